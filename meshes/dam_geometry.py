"""The dam's profile, and the 3D solids and faces that both mesh builders make: the whole
scene (dam.py) and the bodies apart (dam_apart_3d.py)."""
from __future__ import annotations

import numpy as np

from . import _gmsh
from .dam_tags import (DAM_BASE, DAM_CREST, DAM_DOWNSTREAM, DAM_FLANKS, DAM_UPSTREAM,
                       FOUNDATION_BOTTOM, FOUNDATION_FLANKS, FOUNDATION_SIDES, LOG_BACK,
                       LOG_FRONT, LOG_MANTLE, RESERVOIR_BED, TAILWATER_BED)
from flexcontact.errors import InputError


def downstream_points(s) -> list:
    """The downstream face's corners from the toe up to the crest, with the tailwater point
    when it lies strictly between the toe and the knee or the knee and the crest."""
    _, toe, knee, crest_d, _ = s.dam_outline()
    down = [toe]
    ht = s.tailwater_level_m
    if 0 < ht < s.dam_height_m and not np.isclose(ht, knee[1]):
        down.append((s.downstream_face_x_m(ht), ht))
    down += [knee, crest_d]
    down.sort(key=lambda p: p[1])
    return down


def profile_points(s) -> list:
    """Corners of the dam profile (x, vertical) counter-clockwise from the heel, with the
    tailwater point on the downstream face and the water-line point on the upstream face
    (each only when strictly between the ends of its face)."""
    heel, _, _, _, crest_u = s.dam_outline()
    down = downstream_points(s)
    up = [crest_u]
    if s.water_level_m < s.dam_height_m:
        up.append((0.0, s.water_level_m))
    return [heel] + down + up


def log_solid(occ, centre, axis, length_m, radius_m, end):
    """The 3D log's solid (axis ``axis``, centre ``centre``, front end at +L/2 along the
    axis shaped by ``end``): a cylinder, or its shaped profile revolved about the axis
    (OCC's Boolean fuse of a cylinder and a spherical cap leaves a face it cannot mesh)."""
    a, L, R = np.asarray(axis, float), float(length_m), float(radius_m)
    c = np.asarray(centre, float)
    if end.shape == "flat":
        back = c - 0.5 * L * a
        return occ.addCylinder(*map(float, back), *map(float, L * a), R)
    n = np.cross(a, [0.0, 1.0, 0.0] if abs(a[1]) < 0.9 else [1.0, 0.0, 0.0])
    n /= np.linalg.norm(n)
    h, d = 0.5 * L, end.depth_m(R)

    def point(x, y):
        return occ.addPoint(*map(float, c + x * a + y * n))

    axis_back, rim_back, rim_front = point(-h, 0.0), point(-h, R), point(h - d, R)
    axis_front = point(h, 0.0)
    if end.shape == "chamfered":
        corner = point(h, R - float(end.chamfer_m))
        tip = [occ.addLine(rim_front, corner), occ.addLine(corner, axis_front)]
    else:
        centre_pt = point(end.cap(L, R)[0], 0.0)
        tip = [occ.addCircleArc(rim_front, centre_pt, axis_front)]
        occ.remove([(0, centre_pt)])
    loop = [occ.addLine(axis_back, rim_back), occ.addLine(rim_back, rim_front), *tip,
            occ.addLine(axis_front, axis_back)]
    profile = occ.addPlaneSurface([occ.addCurveLoop(loop)])
    solids = [t for dim, t in occ.revolve([(2, profile)], *map(float, c), *map(float, a),
                                          2.0 * np.pi) if dim == 3]
    occ.remove([(2, profile)])  # the profile is no face of the solid of revolution
    if len(solids) != 1:
        raise InputError(f"log_end_shape={end.shape!r}: gmsh made {len(solids)} solids of "
                         f"the log's profile, not one")
    return solids[0]


def log_faces_3d(log_vol, centre, axis, length_m, radius_m, end) -> dict:
    """The log's faces by tag (back, mantle, front), each by its centroid's axial position:
    the back disc at -L/2, the shaft's mantle at -d/2, every face of the front end beyond
    the shaft's end L/2 - d."""
    import gmsh
    log_faces = [abs(t) for _, t in gmsh.model.getBoundary([(3, log_vol)], oriented=False)]
    L, d = float(length_m), end.depth_m(radius_m)
    axial = {f: float((np.array(gmsh.model.occ.getCenterOfMass(2, f)) - centre) @ axis)
             for f in log_faces}
    out = {LOG_BACK: [min(log_faces, key=axial.get)],
           LOG_FRONT: sorted(f for f in log_faces if axial[f] >= 0.5 * L - d - 1e-9 * L)}
    out[LOG_MANTLE] = sorted(set(log_faces) - set(out[LOG_BACK]) - set(out[LOG_FRONT]))
    return out


def dam_faces_3d(s, dam, found) -> dict:
    """The dam's and the foundation's faces by tag (the downstream face: every dam face
    not otherwise tagged)."""
    import gmsh
    B, W, H = s.base_width_m, s.dam_width_m, s.dam_height_m
    Lu, Ld, D = s.foundation_upstream_m, s.foundation_downstream_m, s.foundation_depth_m
    fin = _gmsh.faces_in
    out = {
        FOUNDATION_BOTTOM: fin(-Lu, 0, -D, B + Ld, W, -D, found),
        FOUNDATION_SIDES: fin(-Lu, 0, -D, -Lu, W, 0, found) + fin(B + Ld, 0, -D, B + Ld, W, 0,
                                                                  found),
        FOUNDATION_FLANKS: fin(-Lu, 0, -D, B + Ld, 0, 0, found) + fin(-Lu, W, -D, B + Ld, W, 0,
                                                                      found),
        RESERVOIR_BED: fin(-Lu, 0, 0, 0, W, 0, found),
        TAILWATER_BED: fin(B, 0, 0, B + Ld, W, 0, found),
        DAM_BASE: fin(0, 0, 0, B, W, 0, dam),
        DAM_UPSTREAM: fin(0, 0, 0, 0, W, H, dam),
        DAM_CREST: fin(0, 0, H, B, W, H, dam),
        DAM_FLANKS: fin(0, 0, 0, B, 0, H, dam) + fin(0, W, 0, B, W, H, dam),
    }
    taken = {f for fs in out.values() for f in fs}
    dam_faces = {abs(t) for _, t in gmsh.model.getBoundary([(3, v) for v in dam],
                                                           oriented=False)}
    out[DAM_DOWNSTREAM] = sorted(dam_faces - taken)
    return out
