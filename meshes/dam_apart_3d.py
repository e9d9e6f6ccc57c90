"""The 3D bodies apart (dam/reuse.py): the dam block and its foundation without the log,
and the round log alone in its own frame.

The dam block is the 2D profile swept along y over the block's width, as in
:func:`.dam.build`, with an edge across the upstream face at every water level of a sweep's
range (the reservoir load is then integrated exactly at those levels) and at both ends of
the strip z0..z1 that logs can hit. The *patch* that is condensed (the strip between y0 and
y1) is imprinted on the upstream face, so that its facets are exactly those inside it, and
elements have the size ``h_impact_m`` within ``impact_zone_m`` of it, growing to
``h_far_m``.
"""
from __future__ import annotations

import numpy as np

from . import _gmsh
from .dam_geometry import dam_faces_3d, downstream_points, log_faces_3d, log_solid
from .dam_tags import DAM, FOUNDATION, LOG, LOG_FRONT, NAMES
from flexcontact.errors import InputError


def build_dam_only_3d(comm, s, strip_m, patch_y_m, water_levels_m=()):
    """The dam block of scenario ``s`` (dim 3) with its foundation, refined on the patch
    ``strip_m`` × ``patch_y_m`` (None: the block's whole width) of the upstream face.
    Returns (mesh, cell_tags, facet_tags, info) with info["strip_m"], info["patch_y_m"]."""
    z0, z1 = (float(z) for z in strip_m)
    if not 0.0 < z0 < z1 < s.dam_height_m:
        raise InputError(f"strip_m={(z0, z1)}: need 0 < z0 < z1 < dam_height_m="
                         f"{s.dam_height_m}")
    W = s.dam_width_m
    y0, y1 = (0.0, W) if patch_y_m is None else (float(y) for y in patch_y_m)
    if not 0.0 <= y0 < y1 <= W:
        raise InputError(f"patch_y_m={(y0, y1)}: need 0 <= y0 < y1 <= dam_width_m={W}")
    levels = sorted({float(z) for z in (*water_levels_m, s.water_level_m, z0, z1)
                     if 0.0 < z < s.dam_height_m}, reverse=True)
    info = dict(dim=3, base_width_m=s.base_width_m, knee_elevation_m=s.knee_elevation_m,
                strip_m=(z0, z1), patch_y_m=(y0, y1), face_nodes_m=levels,
                h_far_m=s.h_far_m, h_impact_m=s.h_impact_m)
    return _gmsh.generate(comm, "dam3d_only",
                          lambda: _model(s, info, levels, (z0, z1), (y0, y1)), gdim=3)


def _model(s, info, face_levels, strip, patch_y):
    import gmsh
    occ = gmsh.model.occ
    B, W, H = s.base_width_m, s.dam_width_m, s.dam_height_m
    Lu, Ld, D = s.foundation_upstream_m, s.foundation_downstream_m, s.foundation_depth_m
    heel, _, _, _, crest_u = s.dam_outline()
    pts = [heel] + downstream_points(s) + [crest_u] + [(0.0, z) for z in face_levels]
    p = [occ.addPoint(x, 0, z) for x, z in pts]
    loop = occ.addCurveLoop([occ.addLine(p[i], p[(i + 1) % len(p)]) for i in range(len(p))])
    profile = occ.addPlaneSurface([loop])
    dam_vol = [t for d, t in occ.extrude([(2, profile)], 0, W, 0) if d == 3]
    found_box = occ.addBox(-Lu, 0, -D, B + Lu + Ld, W, D)
    (z0, z1), (y0, y1) = strip, patch_y
    tools = [(3, found_box)]
    if y0 > 0.0 or y1 < W:  # the patch's ends across the face, imprinted on it
        q = [occ.addPoint(0, y, z) for y, z in ((y0, z0), (y1, z0), (y1, z1), (y0, z1))]
        rect = occ.addPlaneSurface([occ.addCurveLoop(
            [occ.addLine(q[i], q[(i + 1) % 4]) for i in range(4)])])
        tools.append((2, rect))
    occ.fragment([(3, v) for v in dam_vol], tools)
    occ.synchronize()

    dam = _gmsh.volumes_in(0, 0, 0, B, W, H)
    found = _gmsh.volumes_in(-Lu, 0, -D, B + Ld, W, 0)
    _gmsh.physical(3, dam, DAM, NAMES[DAM])
    _gmsh.physical(3, found, FOUNDATION, NAMES[FOUNDATION])
    for tag, fs in dam_faces_3d(s, dam, found).items():
        _gmsh.physical(2, fs, tag, NAMES[tag])
    patch = _gmsh.faces_in(0, y0, z0, 0, y1, z1, dam)
    near = s.impact_zone_m
    extent = max(y1 - y0, z1 - z0)
    _gmsh.size_field(patch, 2, s.h_impact_m, s.h_far_m, near,
                     near + 2.0 * (s.h_far_m - s.h_impact_m),
                     points_per_curve=max(20, int(4 * extent / s.h_impact_m)))
    gmsh.model.mesh.generate(3)
    return info


def build_log_3d(comm, L: float, D: float, h: float, end, balls=(), layer=None):
    """The round log (length ``L``, diameter ``D``, front end ``end``, checked) in its own
    frame, elements of size ``h`` (capped in ``balls``, _gmsh.mesh_with_balls; only within
    ``layer`` m of the front end when given)."""
    info = dict(dim=3, length_m=L, diameter_m=D, h_m=h, end_shape=end.shape)
    return _gmsh.generate(comm, "log3d",
                          lambda: _model_log(L, D, h, end, info, balls, layer), gdim=3)


def _model_log(L, D, h, end, info, balls=(), layer=None):
    import gmsh
    occ = gmsh.model.occ
    centre, axis = np.zeros(3), np.array([1.0, 0.0, 0.0])
    vol = log_solid(occ, centre, axis, L, 0.5 * D, end)
    occ.synchronize()
    _gmsh.physical(3, [vol], LOG, NAMES[LOG])
    faces = log_faces_3d(vol, centre, axis, L, 0.5 * D, end)
    for tag, fs in faces.items():
        _gmsh.physical(2, fs, tag, NAMES[tag])
    _gmsh.mesh_with_balls(3, h, balls,
                          None if layer is None else (faces[LOG_FRONT], 2, layer))
    return info

