"""A concrete gravity dam on its foundation and a floating log upstream (2D and 3D).

``build(comm, scenario)`` meshes a :class:`flexcontact.dam.DamScenario` (which holds and
checks every dimension, see its docstring for the axes and the profile) and returns
``(mesh, cell_tags, facet_tags, info)`` with the named groups of :mod:`.dam_tags`.

* The dam and the foundation are meshed together and share their nodes along the base (a
  bonded, conforming interface, tagged ``dam_base``); the log is a separate body sharing no
  node with them.
* The upstream face has a node (2D) or an edge (3D) at the water line, and the downstream
  face one at the tailwater level, so that the hydrostatic pressure, linear on every facet
  below the water and zero above, is integrated exactly.
* Elements have the size ``scenario.h_impact_m`` on the log and within
  ``scenario.impact_zone_m`` of it (so also on the part of the upstream face the log can
  hit), growing to ``scenario.h_far_m`` away from it; on the log ``scenario.h_log_m`` when
  finer (``mesh_size_log_m``).
"""
from __future__ import annotations

import numpy as np

from . import _gmsh
from .dam_tags import (DAM, DAM_BASE, DAM_CREST, DAM_DOWNSTREAM, DAM_UPSTREAM, FOUNDATION,
                       FOUNDATION_BOTTOM, FOUNDATION_SIDES, LOG, LOG_BACK, LOG_FRONT,
                       LOG_LOWER, LOG_MANTLE, LOG_UPPER, NAMES, RESERVOIR_BED, TAILWATER_BED)
from .dam_geometry import (dam_faces_3d, downstream_points, log_faces_3d, log_solid,
                           profile_points)
from .log_end import LogEnd
from flexcontact.errors import InputError


def build(comm, scenario):
    """Mesh ``scenario`` (a checked DamScenario) on ``comm``: 2D or 3D by ``scenario.dim``.

    ``info``: base_width_m, knee_elevation_m, water_level_m, tailwater_level_m, log_centre,
    log_front_point, log_axis, h_far_m, h_impact_m, h_log_m.
    """
    s = scenario
    info = dict(dim=s.dim, base_width_m=s.base_width_m, knee_elevation_m=s.knee_elevation_m,
                water_level_m=s.water_level_m, tailwater_level_m=s.tailwater_level_m,
                log_centre=s.log_centre.tolist(), log_front_point=s.log_front_point.tolist(),
                log_axis=s.log_axis.tolist(), h_far_m=s.h_far_m, h_impact_m=s.h_impact_m,
                h_log_m=s.h_log_m)
    model = (lambda: _model_2d(s, info)) if s.dim == 2 else (lambda: _model_3d(s, info))
    return _gmsh.generate(comm, f"dam{s.dim}d", model, gdim=s.dim)


def _refine_near_log(s, log_entities, dim, log_body, log_volume=None, front=()):
    """Sizes about the log; ``log_body``: the log's surface (2D) or volume (3D), meshed at
    h_log when the scenario sets it finer than h_impact; ``log_volume`` (3D): the contact
    ball refines the log only; ``front``: the log's front-end curves (2D) or faces (3D),
    behind which the ball's size holds only within ``contact_layer_m`` when the scenario
    sets it."""
    near = s.impact_zone_m
    far = near + 2.0 * (s.h_far_m - s.h_impact_m)  # growth rate 1/2: well-shaped grading
    caps = [(s.h_log_m, dim + 1, [log_body])] if s.h_log_m < s.h_impact_m else []
    _gmsh.size_field(log_entities, dim, s.h_impact_m, s.h_far_m, near, far,
                     points_per_curve=max(20, int(4 * s.log_length_m / s.h_impact_m)),
                     balls=_contact_ball(s),
                     balls_only_in=[log_volume] if log_volume is not None else None,
                     layer=_contact_layer(s, front, dim), caps_in=caps)


def _contact_layer(s, front, dim):
    """The contact ball's layer for _gmsh.size_field: within ``contact_layer_m`` of the
    log's front end (None: the whole ball)."""
    if s.contact_layer_m is None or not len(front):
        return None
    return (list(front), dim, s.contact_layer_m)


def _contact_ball(s) -> tuple:
    """The size cap around the first-contact point (scenario ``mesh_size_contact_m``), where
    a crushing end's patch must be resolved: a ball of radius ``contact_zone_m`` about the
    point halfway between the log's front point and the face, growing beyond it at the rate
    1/2."""
    if s.h_contact_m >= s.h_log_m:
        return ()
    front = np.asarray(s.log_front_point, float)
    centre = front.copy()
    centre[0] = 0.5 * front[0]
    x, y, z = (centre[0], centre[1], 0.0) if s.dim == 2 else tuple(centre)
    return ((float(s.h_contact_m), float(x), float(y), float(z), float(s.contact_zone_m)),)


def _model_2d(s, info):
    import gmsh
    geo = gmsh.model.geo
    pts = profile_points(s)
    p = [geo.addPoint(x, y, 0) for x, y in pts]
    heel, toe = p[0], p[1]
    n_down = len(pts) - 2 - (1 if s.water_level_m < s.dam_height_m else 0)  # toe..crest_d
    lines = [geo.addLine(p[i], p[(i + 1) % len(p)]) for i in range(len(p))]
    base = lines[0]
    downstream = lines[1:n_down]
    crest = lines[n_down]
    upstream = lines[n_down + 1:]
    s_dam = geo.addPlaneSurface([geo.addCurveLoop(lines)])

    s_found, found_groups = _foundation_2d(s, geo, heel, toe, base)
    log_curves, s_log = _log_2d(s, geo)
    geo.synchronize()

    _gmsh.physical(2, [s_dam], DAM, NAMES[DAM])
    _gmsh.physical(2, [s_found], FOUNDATION, NAMES[FOUNDATION])
    _gmsh.physical(2, [s_log], LOG, NAMES[LOG])
    groups = {**found_groups, DAM_BASE: [base], DAM_UPSTREAM: upstream, DAM_CREST: [crest],
              DAM_DOWNSTREAM: downstream, **log_curves}
    for tag, curves in groups.items():
        _gmsh.physical(1, curves, tag, NAMES[tag])
    _refine_near_log(s, [c for cs in log_curves.values() for c in cs], 1, s_log,
                     front=log_curves[LOG_FRONT])
    gmsh.model.mesh.generate(2)
    return info


def _foundation_2d(s, geo, heel, toe, base):
    """The foundation block under the dam (sharing the base line): its surface and its
    facet groups."""
    B, Lu, Ld, D = s.base_width_m, s.foundation_upstream_m, s.foundation_downstream_m, \
        s.foundation_depth_m
    f = [geo.addPoint(x, y, 0) for x, y in [(-Lu, -D), (B + Ld, -D), (B + Ld, 0), (-Lu, 0)]]
    bottom, right = geo.addLine(f[0], f[1]), geo.addLine(f[1], f[2])
    tail_bed, res_bed = geo.addLine(f[2], toe), geo.addLine(heel, f[3])
    left = geo.addLine(f[3], f[0])
    s_found = geo.addPlaneSurface([geo.addCurveLoop([bottom, right, tail_bed, -base, res_bed,
                                                     left])])
    return s_found, {FOUNDATION_BOTTOM: [bottom], FOUNDATION_SIDES: [left, right],
                     RESERVOIR_BED: [res_bed], TAILWATER_BED: [tail_bed]}


def _log_2d(s, geo):
    """The log's outline: the shaft's lower and upper edges, its back end and the front end
    shaped by ``s.log_end``."""
    a = s.log_axis
    n = np.array([-a[1], a[0]])
    c = s.log_centre
    return log_outline_2d(geo, s.log_length_m, s.log_radius_m, s.log_end,
                          lambda x, y: c + x * a + y * n)


def log_outline_2d(geo, length_m, radius_m, end, to_world):
    """Add the 2D log's curves and surface to gmsh's ``geo`` kernel, with the log-frame
    point (x along the axis, y across it) placed at ``to_world(x, y)``. Returns
    ({tag: curves}, surface). The front end (tag ``log_front``) is every curve beyond the
    shaft: a segment (flat), three segments (chamfered), or two arcs meeting on the axis
    (rounded; two, because a gmsh arc must be shorter than half a circle)."""
    h, R = 0.5 * length_m, radius_m
    d = end.depth_m(R)

    def point(x, y):
        X = to_world(x, y)
        return geo.addPoint(float(X[0]), float(X[1]), 0)

    # Points and curves in the order back-lower, front end, back-upper: a flat log's
    # entities are numbered as they always were, so its mesh is unchanged.
    back_low = point(-h, -R)
    if end.shape == "flat":
        front_low, front_up = point(h, -R), point(h, R)
        ends = [(front_low, front_up)]
    elif end.shape == "chamfered":
        cc = float(end.chamfer_m)
        front_low, q1, q2 = point(h - cc, -R), point(h, -R + cc), point(h, R - cc)
        front_up = point(h - cc, R)
        ends = [(front_low, q1), (q1, q2), (q2, front_up)]
    else:
        x_c = end.cap(length_m, R)[0]
        front_low, centre, pole = point(h - d, -R), point(x_c, 0.0), point(h, 0.0)
        front_up = point(h - d, R)
    back_up = point(-h, R)
    lower = geo.addLine(back_low, front_low)
    if end.shape == "rounded":
        front = [geo.addCircleArc(front_low, centre, pole),
                 geo.addCircleArc(pole, centre, front_up)]
    else:
        front = [geo.addLine(p, q) for p, q in ends]
    upper, back = geo.addLine(front_up, back_up), geo.addLine(back_up, back_low)
    surface = geo.addPlaneSurface([geo.addCurveLoop([lower, *front, upper, back])])
    return ({LOG_LOWER: [lower], LOG_FRONT: front, LOG_UPPER: [upper], LOG_BACK: [back]},
            surface)


def _model_3d(s, info):
    import gmsh
    occ = gmsh.model.occ
    B, W, H = s.base_width_m, s.dam_width_m, s.dam_height_m
    Lu, Ld, D = s.foundation_upstream_m, s.foundation_downstream_m, s.foundation_depth_m
    # The profile in the x–z plane, swept along y: the water-line and tailwater points
    # become edges splitting the faces.
    p = [occ.addPoint(x, 0, z) for x, z in profile_points(s)]
    loop = occ.addCurveLoop([occ.addLine(p[i], p[(i + 1) % len(p)]) for i in range(len(p))])
    profile = occ.addPlaneSurface([loop])
    dam_vol = [t for d, t in occ.extrude([(2, profile)], 0, W, 0) if d == 3]
    found_box = occ.addBox(-Lu, 0, -D, B + Lu + Ld, W, D)
    occ.fragment([(3, v) for v in dam_vol], [(3, found_box)])
    log_vol = _log_3d(s, occ)
    occ.synchronize()

    dam = _gmsh.volumes_in(0, 0, 0, B, W, H)
    found = _gmsh.volumes_in(-Lu, 0, -D, B + Ld, W, 0)
    _gmsh.physical(3, dam, DAM, NAMES[DAM])
    _gmsh.physical(3, found, FOUNDATION, NAMES[FOUNDATION])
    _gmsh.physical(3, [log_vol], LOG, NAMES[LOG])
    faces = _faces_3d(s, dam, found, log_vol)
    for tag, fs in faces.items():
        _gmsh.physical(2, fs, tag, NAMES[tag])
    # In 3D the ball resolves the log's crushing end only. On the dam's face gmsh's surface
    # mesher caught it only below h_impact ≈ 0.3 m (at 0.4 m the face kept 0.4 m
    # elements, at 0.3 m it had 200,000 more cells), so the dam's near field jumped with
    # h_impact; it is now h_impact at every mesh, and the mesh study refines it evenly.
    _refine_near_log(s, faces[LOG_MANTLE] + faces[LOG_FRONT] + faces[LOG_BACK], 2, log_vol,
                     log_vol, front=faces[LOG_FRONT])
    gmsh.model.mesh.generate(3)
    return info


def _log_3d(s, occ):
    return log_solid(occ, s.log_centre, s.log_axis, s.log_length_m, s.log_radius_m, s.log_end)


def _faces_3d(s, dam, found, log_vol):
    out = dam_faces_3d(s, dam, found)
    out.update(log_faces_3d(log_vol, s.log_centre, s.log_axis, s.log_length_m,
                            s.log_radius_m, s.log_end))
    return out


# ---- the bodies apart: the dam without the log, the log in its own frame (dam/reuse.py) --
def build_dam_only(comm, scenario, strip_m, water_levels_m=(), patch_y_m=None):
    """The dam and its foundation without the log, refined along a strip of the upstream
    face that logs can hit (in 3D a patch: the strip between ``patch_y_m`` = (y0, y1),
    meshes/dam_apart_3d.py).

    ``strip_m`` = (z0, z1): the elevations (m) bounding the strip, 0 < z0 < z1 < dam height;
    the face has nodes there and at each of ``water_levels_m`` (and the scenario's own water
    level), so the reservoir load is integrated exactly at those levels. Elements have the
    size ``scenario.h_impact_m`` within ``scenario.impact_zone_m`` of the strip, growing to
    ``scenario.h_far_m``. Tags as :func:`build` without the log's; the strip is part of
    ``dam_upstream`` (``info["strip_m"]`` locates it). Returns (mesh, cell_tags,
    facet_tags, info).
    """
    s = scenario
    if s.dim == 3:
        from .dam_apart_3d import build_dam_only_3d
        return build_dam_only_3d(comm, s, strip_m, patch_y_m, water_levels_m)
    z0, z1 = (float(z) for z in strip_m)
    if not 0.0 < z0 < z1 < s.dam_height_m:
        raise InputError(f"strip_m={(z0, z1)}: need 0 < z0 < z1 < dam_height_m="
                         f"{s.dam_height_m}")
    levels = sorted({float(z) for z in (*water_levels_m, s.water_level_m, z0, z1)
                     if 0.0 < z < s.dam_height_m}, reverse=True)
    info = dict(dim=2, base_width_m=s.base_width_m, knee_elevation_m=s.knee_elevation_m,
                strip_m=(z0, z1), face_nodes_m=levels, h_far_m=s.h_far_m,
                h_impact_m=s.h_impact_m)
    return _gmsh.generate(comm, "dam2d_only", lambda: _model_dam_only_2d(s, info, levels),
                          gdim=2)


def _model_dam_only_2d(s, info, face_levels):
    import gmsh
    geo = gmsh.model.geo
    heel, _, _, _, crest_u = s.dam_outline()
    down = downstream_points(s)
    pts = [heel] + down + [crest_u] + [(0.0, z) for z in face_levels]
    p = [geo.addPoint(x, y, 0) for x, y in pts]
    lines = [geo.addLine(p[i], p[(i + 1) % len(p)]) for i in range(len(p))]
    k = len(down)
    upstream = lines[k + 1:]
    s_dam = geo.addPlaneSurface([geo.addCurveLoop(lines)])
    s_found, found_groups = _foundation_2d(s, geo, p[0], p[1], lines[0])
    geo.synchronize()
    _gmsh.physical(2, [s_dam], DAM, NAMES[DAM])
    _gmsh.physical(2, [s_found], FOUNDATION, NAMES[FOUNDATION])
    groups = {**found_groups, DAM_BASE: [lines[0]], DAM_UPSTREAM: upstream,
              DAM_CREST: [lines[k]], DAM_DOWNSTREAM: lines[1:k]}
    for tag, curves in groups.items():
        _gmsh.physical(1, curves, tag, NAMES[tag])
    z0, z1 = info["strip_m"]
    strip = [c for i, c in enumerate(lines[k + 1:], start=k + 1)
             if z0 <= 0.5 * (pts[i][1] + pts[(i + 1) % len(pts)][1]) <= z1]
    near = s.impact_zone_m
    _gmsh.size_field(strip, 1, s.h_impact_m, s.h_far_m, near,
                     near + 2.0 * (s.h_far_m - s.h_impact_m),
                     points_per_curve=max(20, int(4 * (z1 - z0) / s.h_impact_m)))
    gmsh.model.mesh.generate(2)
    return info


def build_log(comm, length_m, diameter_m, h_m, end=None, dim=2, ball=None):
    """The log in its own frame: axis along x, centre at the origin, front end (tag
    ``log_front``) at x = +L/2, shaped by ``end`` (a :class:`~.log_end.LogEnd`; None: flat);
    elements of size ``h_m``, and of ``size`` within ``zone`` of the point (a, b) (3D:
    (a, b, 0)) when ``ball`` = (a, b, size, zone) is given: the crushed patch's refinement
    (growing beyond it at the rate 1/2, as the whole mesh's contact ball); with a fifth
    entry ``layer``, only within ``layer`` (m) of the front end, growing behind it at the
    same rate (the scenario's ``contact_layer_m``). In 2D a
    plane-strain slab ``length_m`` × ``diameter_m`` (facets ``log_front``, ``log_back``,
    ``log_upper``, ``log_lower``), in 3D a round log (faces ``log_front``, ``log_back``,
    ``log_mantle``). Cells ``log``. Returns (mesh, cell_tags, facet_tags, info)."""
    from ._check import positive
    L, D, h = (positive(n, v) for n, v in (("length_m", length_m), ("diameter_m", diameter_m),
                                           ("h_m", h_m)))
    end = (LogEnd() if end is None else end).check(D, ("end.shape", "end.chamfer_m",
                                                       "end.radius_m"))
    balls, layer = (), None
    if ball is not None:
        a, b, size, zone = (float(v) for v in ball[:4])
        balls = ((size, a, b, 0.0, zone),)
        layer = float(ball[4]) if len(ball) > 4 else None
    if dim == 3:
        from .dam_apart_3d import build_log_3d
        return build_log_3d(comm, L, D, h, end, balls, layer)
    if dim != 2:
        raise InputError(f"dim={dim!r}: the log is meshed in 2D or 3D")
    info = dict(dim=2, length_m=L, diameter_m=D, h_m=h, end_shape=end.shape)
    return _gmsh.generate(
        comm, "log2d", lambda: _model_log_2d(L, D, h, end, info, balls, layer), gdim=2)


def _model_log_2d(L, D, h, end, info, balls=(), layer=None):
    import gmsh
    geo = gmsh.model.geo
    curves, surface = log_outline_2d(geo, L, 0.5 * D, end, lambda x, y: (x, y))
    geo.synchronize()
    _gmsh.physical(2, [surface], LOG, NAMES[LOG])
    for tag in (LOG_LOWER, LOG_FRONT, LOG_UPPER, LOG_BACK):
        _gmsh.physical(1, curves[tag], tag, NAMES[tag])
    _gmsh.mesh_with_balls(2, h, balls,
                          None if layer is None else (curves[LOG_FRONT], 1, layer))
    return info
