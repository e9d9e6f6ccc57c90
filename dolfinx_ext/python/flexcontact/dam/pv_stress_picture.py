"""Run by ParaView's pvbatch (not imported by flexcontact): a picture of the dam's stress.

    pvbatch pv_stress_picture.py FILE.xdmf OUT.png SCALE FIELD [TAGS|all [BOUND]]

Reads the last time of FILE.xdmf, keeps the cells whose ``cell_tag`` is one of TAGS (comma
separated, e.g. the dam and the log) if given, warps them by ``displacement_m`` × SCALE, colours them by the cell field
FIELD (blue-white-red, symmetric about zero so that tension is red, on ±BOUND if given:
beyond it the colours saturate, so that a singular peak does not wash out the rest) and
saves OUT.png (1200 × 800). Needs a display: run it under xvfb-run.
"""
import sys

from paraview.simple import (AppendDatasets, ColorBy, CreateRenderView,
                             GetColorTransferFunction, GetScalarBar, Render, SaveScreenshot, Show,
                             Threshold, WarpByVector, Xdmf3ReaderT)

path, out, scale, field = sys.argv[1], sys.argv[2], float(sys.argv[3]), sys.argv[4]
reader = Xdmf3ReaderT(FileName=[path])
reader.UpdatePipelineInformation()
times = reader.TimestepValues
t = times if isinstance(times, float) else (list(times) or [0.0])[-1]
source = reader
if len(sys.argv) > 5 and sys.argv[5] != "all":
    parts = []
    for tag in map(float, sys.argv[5].split(",")):
        part = Threshold(Input=reader)
        part.Scalars = ["CELLS", "cell_tag"]
        try:  # ParaView ≥ 5.10
            part.LowerThreshold, part.UpperThreshold = tag, tag
        except AttributeError:
            part.ThresholdRange = [tag, tag]
        parts.append(part)
    source = parts[0] if len(parts) == 1 else AppendDatasets(Input=parts)
warp = WarpByVector(Input=source)
warp.Vectors = ["POINTS", "displacement_m"]
warp.ScaleFactor = scale
warp.UpdatePipeline(t)
view = CreateRenderView()
view.ViewSize = [1200, 800]
view.ViewTime = t
view.OrientationAxesVisibility = 0
if hasattr(view, "UseColorPaletteForBackground"):  # ParaView ≥ 5.10
    view.UseColorPaletteForBackground = 0
view.Background = [1.0, 1.0, 1.0]
shown = Show(warp, view)
ColorBy(shown, ("CELLS", field))
lut = GetColorTransferFunction(field)
lut.ApplyPreset("Cool to Warm", True)
lo, hi = warp.CellData[field].GetRange()
bound = float(sys.argv[6]) if len(sys.argv) > 6 else max(abs(lo), abs(hi), 1e-30)
lut.RescaleTransferFunction(-bound, bound)
shown.SetScalarBarVisibility(view, True)
bar = GetScalarBar(lut, view)
bar.Title = (f"{field} (displacement ×{scale:.3g}"
             + (", saturated" if len(sys.argv) > 6 else "") + ")")
bar.ComponentTitle = ""
bar.TitleColor = [0.0, 0.0, 0.0]
bar.LabelColor = [0.0, 0.0, 0.0]
b = warp.GetDataInformation().GetBounds()
if b[5] > b[4]:  # 3D: look at the upstream face (x = 0) from upstream, above and aside
    centre = [0.5 * (b[0] + b[1]), 0.5 * (b[2] + b[3]), 0.5 * (b[4] + b[5])]
    view.CameraFocalPoint = centre
    view.CameraPosition = [centre[0] - 1.0, centre[1] - 0.7, centre[2] + 0.5]
    view.CameraViewUp = [0.0, 0.0, 1.0]
view.ResetCamera()
Render(view)
SaveScreenshot(out, view)
print(f"range {lo} {hi}")
