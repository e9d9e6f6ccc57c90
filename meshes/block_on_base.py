"""A rectangular block resting on a wider base (2D and 3D), matching interface nodes.

Geometry (m), vertical axis last (y in 2D, z in 3D), the base centred under the block:

* base (tag BASE, master): width × depth, top at 0; its top under the block is the master
  contact surface (tag MASTER), its bottom is clamped (tag FIXED);
* block (tag UPPER, slave): width × height, bottom at ``gap`` (default 0: the block sits
  exactly on the base); bottom = slave surface (tag SLAVE), top loaded (tag LOADED).

The interface meshes are identical copies, node for node: in 2D both interface segments are
transfinite with the same node count; in 3D the block's bottom face is meshed as a periodic
(translated) copy of the base's patch under it.
"""

import math

from . import _check, _gmsh
from .tags import BASE, FIXED, LOADED, MASTER, NAMES, SLAVE, UPPER
from flexcontact.errors import InputError


def _sizes(h, h_far, refine):
    refine = _check.refine_level(refine)
    h = _check.positive("h", h) / 2 ** refine
    hf = _check.positive("h_far", h_far) / 2 ** refine
    return h, max(hf, h)


def build(comm, block=(0.1, 0.05), base=(0.3, 0.1), h=0.005, h_far=0.01, refine=0, gap=0.0,
          patch=None, patch_spacing=None):
    """2D mesh on ``comm``; returns ``(mesh, cell_tags, facet_tags, info)``.

    Args:
        block: (width, height) of the block in m.
        base: (width, depth) of the base in m; the base must be at least as wide.
        h: element size on the interface (m); h_far: element size far from it (m).
        refine: each level halves h and h_far.
        gap: initial vertical gap between block and base (m, ≥ 0).
        patch: (x0, x1), the extent of the base's master patch (m); default the block's
            width under it. A longer patch is the candidate zone of a block that slides.
        patch_spacing: the patch's node spacing relative to h, for non-matching meshes;
            default None: the block's spacing (matching nodes when the patch is the
            block's width).

    ``info``: block, base (tuples), block_width, block_height, base_width, base_depth, h (the
    actual interface spacing), h_far, gap, n_contact_nodes (per surface).
    """
    bw, bh = (_check.positive(f"block[{i}]", v) for i, v in enumerate(block))
    Bw, Bd = (_check.positive(f"base[{i}]", v) for i, v in enumerate(base))
    if bw > Bw:
        raise InputError(f"block width {bw!r} exceeds base width {Bw!r}")
    gap = _nonneg_gap(gap)
    h, hf = _sizes(h, h_far, refine)
    n = max(1, math.ceil(bw / h - 1e-9))  # interface segments
    x0, x1 = (-bw / 2, bw / 2) if patch is None else (float(patch[0]), float(patch[1]))
    if not -Bw / 2 < x0 < x1 < Bw / 2 and patch is not None:
        raise InputError(f"patch={patch!r}: need -base_width/2 < x0 < x1 < base_width/2 "
                         f"(base width {Bw!r})")
    hp = h * (1.0 if patch_spacing is None else
              _check.positive("patch_spacing", patch_spacing, "ratio"))
    n_patch = n if patch is None and patch_spacing is None else \
        max(1, math.ceil((x1 - x0) / hp - 1e-9))
    info = dict(block=(bw, bh), base=(Bw, Bd), block_width=bw, block_height=bh, base_width=Bw,
                base_depth=Bd, h=bw / n, h_far=hf, gap=gap, n_contact_nodes=n + 1,
                patch=(x0, x1), h_patch=(x1 - x0) / n_patch)

    def model():
        import gmsh
        geo = gmsh.model.geo
        # Base (master), counter-clockwise; the patch under the block is its own curve.
        p = [geo.addPoint(x, y, 0) for x, y in
             [(-Bw / 2, -Bd), (Bw / 2, -Bd), (Bw / 2, 0), (x1, 0), (x0, 0), (-Bw / 2, 0)]]
        bottom, right = geo.addLine(p[0], p[1]), geo.addLine(p[1], p[2])
        top_r, patch = geo.addLine(p[2], p[3]), geo.addLine(p[4], p[3])  # patch: left -> right
        top_l, left = geo.addLine(p[4], p[5]), geo.addLine(p[5], p[0])
        loop = geo.addCurveLoop([bottom, right, top_r, -patch, top_l, left])
        s_base = geo.addPlaneSurface([loop])
        # Block (slave); its bottom has the same orientation, so identical node abscissae.
        q = [geo.addPoint(x, y, 0) for x, y in
             [(-bw / 2, gap), (bw / 2, gap), (bw / 2, gap + bh), (-bw / 2, gap + bh)]]
        b_bot, b_right = geo.addLine(q[0], q[1]), geo.addLine(q[1], q[2])
        b_top, b_left = geo.addLine(q[2], q[3]), geo.addLine(q[3], q[0])
        s_block = geo.addPlaneSurface([geo.addCurveLoop([b_bot, b_right, b_top, b_left])])
        geo.mesh.setTransfiniteCurve(patch, n_patch + 1)
        geo.mesh.setTransfiniteCurve(b_bot, n + 1)
        geo.synchronize()

        _gmsh.physical(2, [s_base], BASE, NAMES[BASE])
        _gmsh.physical(2, [s_block], UPPER, NAMES[UPPER])
        _gmsh.physical(1, [bottom], FIXED, NAMES[FIXED])
        _gmsh.physical(1, [b_top], LOADED, NAMES[LOADED])
        _gmsh.physical(1, [patch], MASTER, NAMES[MASTER])
        _gmsh.physical(1, [b_bot], SLAVE, NAMES[SLAVE])
        _gmsh.size_field([patch, b_bot], 1, h, hf, 0.1 * bw, 0.1 * bw + 4 * (hf - h))
        gmsh.model.mesh.generate(2)
        return info

    return _gmsh.generate(comm, "block_on_base", model, gdim=2)


def build_3d(comm, block=(0.1, 0.1, 0.05), base=(0.3, 0.3, 0.1), h=0.01, h_far=0.03, refine=0,
             gap=0.0):
    """3D mesh on ``comm``; returns ``(mesh, cell_tags, facet_tags, info)``.

    Args:
        block: (length x, width y, height z) of the block in m.
        base: (length x, width y, depth z) of the base in m; at least as large in x and y.
        h: element size on the interface (m); h_far: element size far from it (m).
        refine: each level halves h and h_far.
        gap: initial vertical gap between block and base (m, ≥ 0).

    ``info``: block, base (tuples), block_height, base_depth, h, h_far, gap,
    n_contact_nodes (per surface).
    """
    bx, by, bh = (_check.positive(f"block[{i}]", v) for i, v in enumerate(block))
    Bx, By, Bd = (_check.positive(f"base[{i}]", v) for i, v in enumerate(base))
    if bx > Bx or by > By:
        raise InputError(f"block footprint {(bx, by)!r} exceeds the base {(Bx, By)!r}")
    gap = _nonneg_gap(gap)
    h, hf = _sizes(h, h_far, refine)
    info = dict(block=(bx, by, bh), base=(Bx, By, Bd), block_height=bh, base_depth=Bd, h=h,
                h_far=hf, gap=gap)

    def model():
        import gmsh
        occ = gmsh.model.occ
        base_box = occ.addBox(-Bx / 2, -By / 2, -Bd, Bx, By, Bd)
        rect = occ.addRectangle(-bx / 2, -by / 2, 0, bx, by)
        # Imprint the footprint on the base's top only; the block is never fragmented with
        # the base, so the two bodies keep separate nodes even when they touch.
        occ.fragment([(3, base_box)], [(2, rect)])
        block_box = occ.addBox(-bx / 2, -by / 2, gap, bx, by, bh)
        occ.synchronize()

        base_vol = _gmsh.volumes_in(-Bx / 2, -By / 2, -Bd, Bx / 2, By / 2, 0)
        block_vol = [block_box]
        patch = _gmsh.faces_in(-bx / 2, -by / 2, 0, bx / 2, by / 2, 0, base_vol)
        bottom = _gmsh.faces_in(-Bx / 2, -By / 2, -Bd, Bx / 2, By / 2, -Bd, base_vol)
        b_bot = _gmsh.faces_in(-bx / 2, -by / 2, gap, bx / 2, by / 2, gap, block_vol)
        b_top = _gmsh.faces_in(-bx / 2, -by / 2, gap + bh, bx / 2, by / 2, gap + bh, block_vol)
        translate = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, gap, 0, 0, 0, 1]
        gmsh.model.mesh.setPeriodic(2, b_bot, patch, translate)

        _gmsh.physical(3, base_vol, BASE, NAMES[BASE])
        _gmsh.physical(3, block_vol, UPPER, NAMES[UPPER])
        _gmsh.physical(2, bottom, FIXED, NAMES[FIXED])
        _gmsh.physical(2, b_top, LOADED, NAMES[LOADED])
        _gmsh.physical(2, patch, MASTER, NAMES[MASTER])
        _gmsh.physical(2, b_bot, SLAVE, NAMES[SLAVE])
        near = 0.05 * min(bx, by)
        _gmsh.size_field(patch + b_bot, 2, h, hf, near, near + 3 * (hf - h))
        gmsh.model.mesh.generate(3)
        info["n_contact_nodes"] = len(set().union(*(
            gmsh.model.mesh.getNodes(2, f, includeBoundary=True)[0] for f in patch)))
        return info

    return _gmsh.generate(comm, "block_on_base_3d", model, gdim=3)


def _nonneg_gap(gap):
    if gap == 0:
        return 0.0
    return _check.positive("gap", gap)
