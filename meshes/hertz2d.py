"""Hertz line contact (plane strain): a half-cylinder on an elastic block.

Geometry (m), y up:

* block (tag BASE, master): [−W/2, W/2] × [−D, 0]; its top y = 0 is the master surface;
* half-cylinder (tag UPPER, slave): the lower half of the disc of radius R centred at
  (0, R); flat top at y = R (loaded), lowest point (0, 0) touches the block. The initial
  gap at abscissa x is g(x) = R − sqrt(R² − x²).

Candidate contact zone |x| ≤ w (w = zone_factor · a_expected): both interface curves are
chains of straight one-element segments through the same abscissae x_i (spacing ≈ h), the
block's points at (x_i, 0), the cylinder's at (x_i, g(x_i)): every slave node lies exactly
above its master node. Outside the zone the cylinder is a circular arc and the block top a
straight line; sizes grow from h to h_far away from the zone.

For Hertz' formulas (docs/architecture.md §6) the half-width a must be ≪ R and the block large compared
with a; the default W = 8R, D = 4R.
"""

import math

import numpy as np

from . import _check, _gmsh
from .tags import BASE, FIXED, LOADED, MASTER, NAMES, SLAVE, UPPER
from flexcontact.errors import InputError


def gap(x, R):
    """Initial normal gap g(x) = R − sqrt(R² − x²) in m between cylinder and block."""
    x = np.asarray(x, dtype=float)
    return R - np.sqrt(R * R - x * x)


def build(comm, R=0.05, a_expected=None, h_contact=None, h_far=None, refine=0,
          zone_factor=2.5, block_width=None, block_depth=None, block_spacing=None,
          with_cylinder=True, fine_depth=None):
    """Build the mesh on ``comm``; returns ``(mesh, cell_tags, facet_tags, info)``.

    Args:
        R: cylinder radius (m).
        a_expected: expected contact half-width a (m), sets the zone; default R/10.
        h_contact: element size in the candidate zone (m); default a_expected/10.
        h_far: element size far from the zone (m); default R/4.
        refine: each level halves h_contact and h_far (≈ 4× the cells).
        zone_factor: candidate zone half-width w = zone_factor · a_expected (≥ 1).
        block_width, block_depth: block size W × D (m); default 8R × 4R.
        block_spacing: the block's zone spacing relative to the cylinder's, for
            non-matching meshes (e.g. 0.7); default None: the same abscissae (matching
            nodes, each slave node above its master node).
        with_cylinder: False builds the block alone (for a rigid circle as the target; no
            UPPER, LOADED or SLAVE tags).
        fine_depth: depth (m) of the layer meshed at h_contact along the zone, the size
            growing beyond it; default w/4. A few h_contact keep a wide, finely spaced zone
            (many contact DOFs) from filling the bodies with elements.

    ``info`` holds R, a_expected, w, h_contact (the actual zone spacing), h_far,
    block_width, block_depth and n_contact_nodes (per surface).
    """
    R, a, w = _check.hertz_zone(R, a_expected, zone_factor)
    _check.less("zone half-width w = zone_factor * a_expected", w, "R", R)
    refine = _check.refine_level(refine)
    h = _check.positive("h_contact", a / 10 if h_contact is None else h_contact) / 2 ** refine
    hf = _check.positive("h_far", R / 4 if h_far is None else h_far) / 2 ** refine
    W = _check.positive("block_width", 8 * R if block_width is None else block_width)
    D = _check.positive("block_depth", 4 * R if block_depth is None else block_depth)
    _check.less("2R", 2 * R, "block_width", W)
    if h > w:
        raise InputError(
            f"h_contact={h!r} (after refine={refine}) exceeds the zone half-width w={w!r}")
    hf = max(hf, h)
    near = 0.25 * w if fine_depth is None else _check.positive("fine_depth", fine_depth)

    n = math.ceil(w / h - 1e-9)          # segments per side of x = 0
    xs = [w * i / n for i in range(-n, n + 1)]  # symmetric; x = 0 is a node of both bodies
    if block_spacing is None:
        xb = xs
    else:
        nb = math.ceil(w / (_check.positive("block_spacing", block_spacing, "ratio") * h) - 1e-9)
        xb = [w * i / nb for i in range(-nb, nb + 1)]
    info = dict(R=R, a_expected=a, w=w, h_contact=w / n, h_far=hf, block_width=W,
                block_depth=D, n_contact_nodes=2 * n + 1, h_block=w * 2 / (len(xb) - 1),
                n_block_nodes=len(xb))

    def model():
        import gmsh
        geo = gmsh.model.geo
        # Block (master): counter-clockwise boundary.
        bl, br = geo.addPoint(-W / 2, -D, 0), geo.addPoint(W / 2, -D, 0)
        tr, tl = geo.addPoint(W / 2, 0, 0), geo.addPoint(-W / 2, 0, 0)
        pm = [geo.addPoint(x, 0, 0) for x in xb]
        seg_m = [geo.addLine(pm[i], pm[i + 1]) for i in range(len(xb) - 1)]  # left -> right
        bottom, right = geo.addLine(bl, br), geo.addLine(br, tr)
        top_r, top_l, left = geo.addLine(tr, pm[-1]), geo.addLine(pm[0], tl), geo.addLine(tl, bl)
        loop_m = geo.addCurveLoop([bottom, right, top_r] + [-s for s in reversed(seg_m)]
                                  + [top_l, left])
        block = geo.addPlaneSurface([loop_m])
        for s in seg_m:
            geo.mesh.setTransfiniteCurve(s, 2)  # one element per segment: nodes = points

        def block_groups():
            _gmsh.physical(2, [block], BASE, NAMES[BASE])
            _gmsh.physical(1, [bottom], FIXED, NAMES[FIXED])
            _gmsh.physical(1, seg_m, MASTER, NAMES[MASTER])

        if not with_cylinder:
            geo.synchronize()
            block_groups()
            _gmsh.size_field(seg_m, 1, h, hf, near, near + 3 * (hf - h), points_per_curve=4)
            gmsh.model.mesh.generate(2)
            return info
        # Cylinder (slave): nodes of the zone exactly above the block's.
        c = geo.addPoint(0, R, 0)
        ps = [geo.addPoint(x, float(gap(x, R)), 0) for x in xs]
        seg_s = [geo.addLine(ps[i], ps[i + 1]) for i in range(2 * n)]
        ar, al = geo.addPoint(R, R, 0), geo.addPoint(-R, R, 0)
        arc_r, top = geo.addCircleArc(ps[-1], c, ar), geo.addLine(ar, al)
        arc_l = geo.addCircleArc(al, c, ps[0])
        cyl = geo.addPlaneSurface([geo.addCurveLoop(seg_s + [arc_r, top, arc_l])])
        for s in seg_s:
            geo.mesh.setTransfiniteCurve(s, 2)
        geo.synchronize()

        block_groups()
        _gmsh.physical(2, [cyl], UPPER, NAMES[UPPER])
        _gmsh.physical(1, [top], LOADED, NAMES[LOADED])
        _gmsh.physical(1, seg_s, SLAVE, NAMES[SLAVE])

        _gmsh.size_field(seg_m + seg_s, 1, h, hf, near, near + 3 * (hf - h), points_per_curve=4)
        gmsh.model.mesh.generate(2)
        return info

    return _gmsh.generate(comm, "hertz2d", model, gdim=2)
