"""Hertz point contact, quarter model: a sphere-ended column on an elastic block.

Geometry (m), z up, symmetry planes x = 0 (tag SYMMETRY_X) and y = 0 (tag SYMMETRY_Y) on
both bodies:

* block (tag BASE, master): [0, Lx] × [0, Ly] × [−D, 0]; its top z = 0 inside r ≤ w is the
  master surface (r = sqrt(x² + y²)); bottom clamped (tag FIXED);
* column (tag UPPER, slave): quarter of a circular column of radius Rc < R whose bottom is
  the sphere z = g(r) = R − sqrt(R² − r²) (radius R, touching the block at the origin) and
  whose flat top z = H is loaded (tag LOADED). The slave surface is its bottom inside r ≤ w.

The body is a sphere-ended column, not a whole sphere: Hertz' formulas (docs/architecture.md §6) hold for
any bodies with that local curvature as long as the contact radius a ≪ Rc (and ≪ R).

Construction: the column is meshed with a flat bottom at height z0, its bottom disc r ≤ w a
periodic (translated) copy of the block's disc, so the surface meshes are identical. After
loading into DOLFINx every column node is moved vertically, z ← g(r)(1 − ζ) + H ζ with
ζ = (z − z0)/H ∈ [0, 1]: the bottom becomes the sphere, the top stays flat at z = H, and
(x, y) never change — each slave node stays exactly above its master node.
"""

import math

import numpy as np

from . import _check, _gmsh
from .tags import BASE, FIXED, LOADED, MASTER, NAMES, SLAVE, SYMMETRY_X, SYMMETRY_Y, UPPER
from flexcontact.errors import InputError


def gap(x, y, R):
    """Initial normal gap g = R − sqrt(R² − x² − y²) in m between sphere and block."""
    r2 = np.asarray(x, dtype=float) ** 2 + np.asarray(y, dtype=float) ** 2
    return R - np.sqrt(R * R - r2)


def build(comm, R=0.05, a_expected=None, h_contact=None, h_far=None, refine=0,
          zone_factor=2.5, column_radius=None, column_height=None, block=None,
          with_block=True):
    """Build the quarter model on ``comm``; returns ``(mesh, cell_tags, facet_tags, info)``.

    Args:
        R: sphere radius (m).
        a_expected: expected contact radius a (m), sets the zone; default R/10.
        h_contact: element size in the candidate zone (m); default a_expected/4.
        h_far: largest element size (m); default 0.4 R.
        refine: each level halves h_contact and h_far (≈ 8× the cells).
        zone_factor: candidate zone radius w = zone_factor · a_expected (≥ 1).
        column_radius: Rc, with w < Rc < R (m); default R/2.
        column_height: H, height of the column's top above the contact point (m); default R.
        block: (Lx, Ly, D) of the quarter block (m); default (4R, 4R, 4R).
        with_block: False builds the column alone (for a rigid plane z = 0 as the target;
            no BASE, FIXED or MASTER tags).

    ``info`` holds R, a_expected, w, h_contact, h_far, column_radius, column_height, block
    and n_contact_nodes (per surface).
    """
    R, a, w = _check.hertz_zone(R, a_expected, zone_factor)
    Rc = _check.positive("column_radius", R / 2 if column_radius is None else column_radius)
    _check.less("column_radius", Rc, "R", R)
    _check.less("zone radius w = zone_factor * a_expected", w, "column_radius", Rc)
    H = _check.positive("column_height", R if column_height is None else column_height)
    gap_edge = R - math.sqrt(R * R - Rc * Rc)
    if H <= 2 * gap_edge:
        raise InputError(f"column_height={H!r} must exceed twice the sphere's rise at r = Rc "
                         f"({2 * gap_edge!r} m) so that the mapped column is not inverted")
    Lx, Ly, D = (_check.positive(f"block[{i}]", v) for i, v in
                 enumerate((4 * R, 4 * R, 4 * R) if block is None else block))
    _check.less("column_radius", Rc, "block length Lx", Lx)
    _check.less("column_radius", Rc, "block width Ly", Ly)
    refine = _check.refine_level(refine)
    h = _check.positive("h_contact", a / 4 if h_contact is None else h_contact) / 2 ** refine
    hf = max(_check.positive("h_far", 0.4 * R if h_far is None else h_far) / 2 ** refine, h)
    if h > w:
        raise InputError(f"h_contact={h!r} (after refine={refine}) exceeds the zone radius w={w!r}")
    z0 = H  # the column is meshed clear of the block, then mapped down
    info = dict(R=R, a_expected=a, w=w, h_contact=h, h_far=hf, column_radius=Rc,
                column_height=H, block=(Lx, Ly, D))

    def model():
        import gmsh
        occ = gmsh.model.occ
        if with_block:
            base_box = occ.addBox(0, 0, -D, Lx, Ly, D)
            occ.fragment([(3, base_box)], [(2, _quarter_disc(occ, w, 0.0))])
        col = occ.addCylinder(0, 0, z0, 0, 0, H, Rc, angle=math.pi / 2)
        occ.fragment([(3, col)], [(2, _quarter_disc(occ, w, z0))])
        occ.synchronize()

        base_vol = _gmsh.volumes_in(0, 0, -D, Lx, Ly, 0) if with_block else []
        col_vol = _gmsh.volumes_in(0, 0, z0, Rc, Rc, z0 + H)
        both = base_vol + col_vol
        patch_m = _gmsh.faces_in(0, 0, 0, w, w, 0, base_vol) if with_block else []
        patch_s = _gmsh.faces_in(0, 0, z0, w, w, z0, col_vol)
        if with_block:
            gmsh.model.mesh.setPeriodic(2, patch_s, patch_m,
                                        [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, z0, 0, 0, 0, 1])
            _gmsh.physical(3, base_vol, BASE, NAMES[BASE])
            _gmsh.physical(2, _gmsh.faces_in(0, 0, -D, Lx, Ly, -D, base_vol), FIXED,
                           NAMES[FIXED])
            _gmsh.physical(2, patch_m, MASTER, NAMES[MASTER])
        _gmsh.physical(3, col_vol, UPPER, NAMES[UPPER])
        _gmsh.physical(2, _gmsh.faces_in(0, 0, z0 + H, Rc, Rc, z0 + H, col_vol), LOADED,
                       NAMES[LOADED])
        _gmsh.physical(2, _gmsh.faces_in(0, 0, -D, 0, max(Ly, Rc), z0 + H, both),
                       SYMMETRY_X, NAMES[SYMMETRY_X])
        _gmsh.physical(2, _gmsh.faces_in(0, 0, -D, max(Lx, Rc), 0, z0 + H, both),
                       SYMMETRY_Y, NAMES[SYMMETRY_Y])
        _gmsh.physical(2, patch_s, SLAVE, NAMES[SLAVE])
        # The column is slender: cap its size so that its rim and loaded top are resolved.
        cap = (max(h, Rc / 4), -Rc, -Rc, z0 - Rc, 2 * Rc, 2 * Rc, z0 + H + Rc)
        _gmsh.size_field(patch_m + patch_s, 2, h, hf, 0.5 * w, 0.5 * w + 2.5 * (hf - h),
                         boxes=[cap])
        gmsh.model.mesh.generate(3)
        info["n_contact_nodes"] = len(set().union(*(
            gmsh.model.mesh.getNodes(2, f, includeBoundary=True)[0] for f in patch_s)))
        return info

    msh, cell_tags, facet_tags, info = _gmsh.generate(comm, "hertz3d", model, gdim=3)
    _shape_column(msh.geometry.x, R, H, z0)
    return msh, cell_tags, facet_tags, info


def _quarter_disc(occ, radius, z):
    """OCC plane surface: the quarter disc r ≤ radius, x, y ≥ 0, at height z."""
    o = occ.addPoint(0, 0, z)
    ax, ay = occ.addPoint(radius, 0, z), occ.addPoint(0, radius, z)
    arc = occ.addCircleArc(ax, o, ay)
    loop = occ.addCurveLoop([occ.addLine(o, ax), arc, occ.addLine(ay, o)])
    return occ.addPlaneSurface([loop])


def _shape_column(x, R, H, z0):
    """Move the column's nodes (z > z0/2; the block lies in z ≤ 0) in place: bottom onto the
    sphere, top kept at z = H. Local on every rank (owned and ghost nodes alike)."""
    up = x[:, 2] > 0.5 * z0
    zeta = (x[up, 2] - z0) / H
    x[up, 2] = gap(x[up, 0], x[up, 1], R) * (1.0 - zeta) + H * zeta
