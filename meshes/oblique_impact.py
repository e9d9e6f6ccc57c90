"""A solid disc above an elastic block (plane strain), for oblique impact.

Geometry (m), y up:

* block (tag BASE, master): [−W/2, W/2] × [−D, 0]; its bottom (FIXED) is clamped and the
  part |x − x_c| ≤ w_m of its top is the master candidate surface (MASTER), x_c = w_m − w/2
  shifted towards +x, where the disc slides;
* disc (tag UPPER, slave): centre (0, R + gap), radius R; the arc of its boundary within
  the angle ±α of the lowest point is the slave candidate surface (SLAVE), R sin α = w.

The meshes do not match (node–surface pairing). Element size h in the contact region
(within w of the lowest point on both bodies), growing to h_far away from it.
"""

import math

from . import _check, _gmsh
from .tags import BASE, FIXED, MASTER, NAMES, SLAVE, UPPER
from flexcontact.errors import InputError


def build(comm, R=0.05, h_contact=1e-3, h_far=None, zone=None, slide=None, gap=0.0,
          block_width=None, block_depth=None, refine=0):
    """Build the mesh on ``comm``; returns ``(mesh, cell_tags, facet_tags, info)``.

    Args:
        R: disc radius (m).
        h_contact: element size in the contact region (m).
        h_far: element size far from it (m); default R/4.
        zone: half-width w of the disc's slave arc (m); default R/3.
        slide: how far the master surface extends past the zone towards +x (m), for the
            sliding of the contact; default R/3.
        gap: initial gap between the disc's lowest point and the block (m), ≥ 0.
        block_width, block_depth: W × D (m); default 6R × 2R.
        refine: each level halves h_contact and h_far.
    """
    R = _check.positive("R", R)
    refine = _check.refine_level(refine)
    h = _check.positive("h_contact", h_contact) / 2 ** refine
    hf = max(_check.positive("h_far", R / 4 if h_far is None else h_far) / 2 ** refine, h)
    w = _check.positive("zone", R / 3 if zone is None else zone)
    s = _check.positive("slide", R / 3 if slide is None else slide)
    W = _check.positive("block_width", 6 * R if block_width is None else block_width)
    D = _check.positive("block_depth", 2 * R if block_depth is None else block_depth)
    _check.less("zone", w, "R", R)
    _check.less("zone + slide", w + s, "block_width / 2", W / 2)
    if not (math.isfinite(gap) and gap >= 0):
        raise InputError(f"gap={gap!r}: must be a finite number >= 0 m")
    alpha = math.asin(w / R)
    info = dict(R=R, h_contact=h, h_far=hf, zone=w, slide=s, gap=float(gap), block_width=W,
                block_depth=D, centre=(0.0, R + gap))

    def model():
        import gmsh
        geo = gmsh.model.geo
        bl, br = geo.addPoint(-W / 2, -D, 0), geo.addPoint(W / 2, -D, 0)
        tr, tl = geo.addPoint(W / 2, 0, 0), geo.addPoint(-W / 2, 0, 0)
        ml, mr = geo.addPoint(-w, 0, 0), geo.addPoint(w + s, 0, 0)
        bottom, right = geo.addLine(bl, br), geo.addLine(br, tr)
        top_r, master, top_l = geo.addLine(tr, mr), geo.addLine(mr, ml), geo.addLine(ml, tl)
        left = geo.addLine(tl, bl)
        block = geo.addPlaneSurface([geo.addCurveLoop([bottom, right, top_r, master, top_l,
                                                       left])])
        cy = R + gap
        c = geo.addPoint(0, cy, 0)
        p_l = geo.addPoint(-R * math.sin(alpha), cy - R * math.cos(alpha), 0)
        p_r = geo.addPoint(R * math.sin(alpha), cy - R * math.cos(alpha), 0)
        p_t = geo.addPoint(0, cy + R, 0)
        slave = geo.addCircleArc(p_l, c, p_r)
        a_r, a_l = geo.addCircleArc(p_r, c, p_t), geo.addCircleArc(p_t, c, p_l)
        disc = geo.addPlaneSurface([geo.addCurveLoop([slave, a_r, a_l])])
        geo.synchronize()
        _gmsh.physical(2, [block], BASE, NAMES[BASE])
        _gmsh.physical(2, [disc], UPPER, NAMES[UPPER])
        _gmsh.physical(1, [bottom], FIXED, NAMES[FIXED])
        _gmsh.physical(1, [master], MASTER, NAMES[MASTER])
        _gmsh.physical(1, [slave], SLAVE, NAMES[SLAVE])
        _gmsh.size_field([master, slave], 1, h, hf, 0.2 * w, 0.2 * w + 4 * (hf - h),
                         points_per_curve=int(4 * (2 * w + s) / h))
        gmsh.model.mesh.generate(2)
        return info

    return _gmsh.generate(comm, "oblique_impact", model, gdim=2)
