"""Run by pvbatch: open an XDMF file as a new user would, warp it, colour it; print JSON.

    pvbatch tests/paraview_check.py FILE.xdmf VECTOR FIELD [SCREENSHOT.png SCALE]

Prints, for the last time step: the reader's output class, its points and cells, each array
(name, association, VTK class, components), the bounds after Warp By Vector on VECTOR, and
the range of FIELD on the warped dataset. With SCREENSHOT, renders the warped mesh coloured
by FIELD (needs a display: xvfb-run).
"""
import json
import sys

from paraview import servermanager as sm
from paraview.simple import ColorBy, CreateRenderView, Render, SaveScreenshot, Show, \
    WarpByVector, Xdmf3ReaderT

path, vector, field = sys.argv[1:4]
reader = Xdmf3ReaderT(FileName=[path])
reader.UpdatePipelineInformation()
times = list(reader.TimestepValues)
t = times[-1]
reader.UpdatePipeline(t)
data = sm.Fetch(reader)
arrays = []
for assoc, fd in (("POINTS", data.GetPointData()), ("CELLS", data.GetCellData())):
    for i in range(fd.GetNumberOfArrays()):
        a = fd.GetArray(i)
        arrays.append([a.GetName(), assoc, a.GetClassName(), a.GetNumberOfComponents()])
warp = WarpByVector(Input=reader)
warp.Vectors = ["POINTS", vector]
warp.ScaleFactor = float(sys.argv[5]) if len(sys.argv) > 5 else 1.0
warp.UpdatePipeline(t)
warped = sm.Fetch(warp)
assoc = "CELLS" if warped.GetCellData().GetArray(field) else "POINTS"
fd = warped.GetCellData() if assoc == "CELLS" else warped.GetPointData()
print(json.dumps({"class": data.GetClassName(), "times": times,
                  "points": data.GetNumberOfPoints(), "cells": data.GetNumberOfCells(),
                  "point_type": data.GetPoints().GetData().GetClassName(), "arrays": arrays,
                  "warped_bounds": list(warped.GetBounds()),
                  "field_range": list(fd.GetArray(field).GetRange(0))}))
if len(sys.argv) > 4:
    view = CreateRenderView()
    view.ViewSize = [1000, 700]
    view.ViewTime = t
    shown = Show(warp, view)
    ColorBy(shown, (assoc, field))
    shown.RescaleTransferFunctionToDataRange(True)
    shown.SetScalarBarVisibility(view, True)
    view.ResetCamera()
    Render(view)
    SaveScreenshot(sys.argv[4], view)
