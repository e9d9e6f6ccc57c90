"""The contact patch test geometry (Taylor & Papadopoulos): two stacked bodies, one footprint.

Geometry (m), vertical axis last (y in 2D, z in 3D), symmetry planes through the origin:

* lower body (tag BASE, master): [0, w] × [0, w] × [−H1, 0] (2D: [0, w] × [−H1, 0]); its
  top is the master contact surface (tag MASTER), its bottom tag FIXED;
* upper body (tag UPPER, slave): [0, w] × [0, w] × [0, H2] (2D: [0, w] × [0, H2]) on top of
  it, touching without gap; its bottom is the slave surface (tag SLAVE), its top tag LOADED;
* the faces x = 0 of both bodies carry tag SYMMETRY_X, in 3D the faces y = 0 tag SYMMETRY_Y;
  the faces x = w (and y = w) are not tagged (free).

Both bodies are meshed unstructured, with element sizes growing linearly from the interface
size h_i = min(h_lower, h_upper) at the interface to h_lower at the lower body's bottom and
h_upper at the upper body's top, so away from the interface the two meshes differ. The
interface meshes are identical copies, node for node: in 2D both interface segments are
transfinite with the same node count and the same (non-uniform, geometric) spacing, so the
tributary lengths differ from node to node; in 3D the upper body's bottom face is meshed as
a periodic copy of the lower body's top face.
"""

import math

from . import _check, _gmsh
from .tags import BASE, FIXED, LOADED, MASTER, NAMES, SLAVE, SYMMETRY_X, SYMMETRY_Y, UPPER
from flexcontact.errors import InputError, SolveError

PROGRESSION_2D = 1.15  # ratio of neighbouring interface segments in 2D (any value matches)
NONMATCHING_RATIO = 1.5  # upper/lower interface segment counts (2D) or sizes (3D), non-matching
CELLS = {2: ("triangle",), 3: ("tetrahedron", "hexahedron")}


def build(comm, dim=3, width=0.1, lower_height=0.04, upper_height=0.06, h_lower=0.02,
          h_upper=0.03, refine=0, matching=True, cell=None):
    """Build the patch-test mesh on ``comm``; returns ``(mesh, cell_tags, facet_tags, info)``.

    Args:
        dim: 2 (plane, x–y) or 3.
        width: w, side of the common footprint (m).
        lower_height: H1, height of the lower body (m).
        upper_height: H2, height of the upper body (m).
        h_lower, h_upper: element sizes (m) at the lower body's bottom and the upper body's
            top; the interface gets min(h_lower, h_upper).
        refine: each level halves both sizes.
        cell: None (triangles in 2D, tetrahedra in 3D); in 3D "tetrahedron" (unstructured,
            above) or "hexahedron": both bodies structured (transfinite, recombined), their
            interface faces in rectangles graded geometrically along x and y (ratio
            PROGRESSION_2D); non-matching: the upper face has NONMATCHING_RATIO times as
            many segments per edge, graded the other way; vertical layers of the mean of
            the interface and outer sizes.
        matching: True: the interface meshes are identical copies, node for node (above);
            False: non-matching interface meshes — in 2D the upper body's interface gets
            NONMATCHING_RATIO times as many segments, graded the other way (no interior node
            of one side faces a node of the other), in 3D the upper body's interface face is
            structured (transfinite) with NONMATCHING_RATIO times as many segments per edge
            as the lower face's unstructured mesh of size h_i.

    ``info``: dim, width, lower_height, upper_height, h_lower, h_upper, h_interface (the
    interface size asked of gmsh; in 2D the mean segment length), area (the interface
    measure: w² in 3D, w in 2D) and n_contact_nodes (per surface).
    """
    if dim not in (2, 3) or isinstance(dim, bool):
        raise InputError(f"dim={dim!r}: must be 2 or 3")
    if not isinstance(matching, bool):
        raise InputError(f"matching={matching!r}: must be True or False")
    cell = CELLS[dim][0] if cell is None else cell
    if cell not in CELLS[dim]:
        raise InputError(f"cell={cell!r}: in {dim}D must be one of {', '.join(CELLS[dim])}")
    w = _check.positive("width", width)
    H1 = _check.positive("lower_height", lower_height)
    H2 = _check.positive("upper_height", upper_height)
    refine = _check.refine_level(refine)
    hl = _check.positive("h_lower", h_lower) / 2 ** refine
    hu = _check.positive("h_upper", h_upper) / 2 ** refine
    hi = min(hl, hu)
    info = dict(dim=dim, width=w, lower_height=H1, upper_height=H2, h_lower=hl, h_upper=hu,
                h_interface=hi, area=w * w if dim == 3 else w, cell=cell)
    # Element size (m) as a function of height: h_i at the interface, growing linearly to
    # h_lower at z = −H1 and to h_upper at z = H2. (|z| − z)/2 is −z below the interface and
    # 0 above, (|z| + z)/2 the reverse; gmsh's MathEval has no conditionals.
    v = "z" if dim == 3 else "y"
    size = (f"{hi!r} + {(hl - hi) / H1!r} * (Fabs({v}) - {v}) / 2"
            f" + {(hu - hi) / H2!r} * (Fabs({v}) + {v}) / 2")

    def size_field():
        import gmsh
        field = gmsh.model.mesh.field
        f = field.add("MathEval")
        field.setString(f, "F", size)
        field.setAsBackgroundMesh(f)
        gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
        gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
        gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)

    def model_2d():
        import gmsh
        geo = gmsh.model.geo
        n = max(2, math.ceil(w / hi - 1e-9))  # interface segments
        info["h_interface"] = w / n
        # Lower body, counter-clockwise; its top runs left -> right, as the upper body's
        # bottom does, so the two transfinite curves get identical node abscissae.
        p = [geo.addPoint(x, y, 0) for x, y in [(0, -H1), (w, -H1), (w, 0), (0, 0)]]
        bottom, right = geo.addLine(p[0], p[1]), geo.addLine(p[1], p[2])
        top, left = geo.addLine(p[3], p[2]), geo.addLine(p[3], p[0])
        s_lower = geo.addPlaneSurface([geo.addCurveLoop([bottom, right, -top, left])])
        q = [geo.addPoint(x, y, 0) for x, y in [(0, 0), (w, 0), (w, H2), (0, H2)]]
        u_bot, u_right = geo.addLine(q[0], q[1]), geo.addLine(q[1], q[2])
        u_top, u_left = geo.addLine(q[2], q[3]), geo.addLine(q[3], q[0])
        s_upper = geo.addPlaneSurface([geo.addCurveLoop([u_bot, u_right, u_top, u_left])])
        if matching:
            for c in (top, u_bot):
                geo.mesh.setTransfiniteCurve(c, n + 1, "Progression", PROGRESSION_2D)
        else:
            n_up = max(n + 1, round(NONMATCHING_RATIO * n))
            geo.mesh.setTransfiniteCurve(top, n + 1, "Progression", PROGRESSION_2D)
            geo.mesh.setTransfiniteCurve(u_bot, n_up + 1, "Progression", 1 / PROGRESSION_2D)
            info["n_contact_nodes_upper"] = n_up + 1
        geo.synchronize()

        _gmsh.physical(2, [s_lower], BASE, NAMES[BASE])
        _gmsh.physical(2, [s_upper], UPPER, NAMES[UPPER])
        _gmsh.physical(1, [bottom], FIXED, NAMES[FIXED])
        _gmsh.physical(1, [u_top], LOADED, NAMES[LOADED])
        _gmsh.physical(1, [top], MASTER, NAMES[MASTER])
        _gmsh.physical(1, [u_bot], SLAVE, NAMES[SLAVE])
        _gmsh.physical(1, [left, u_left], SYMMETRY_X, NAMES[SYMMETRY_X])
        size_field()
        gmsh.model.mesh.generate(2)
        info["n_contact_nodes"] = n + 1
        return info

    def model_3d():
        import gmsh
        occ = gmsh.model.occ
        # Two separate boxes, never fragmented: coincident faces stay distinct, so the
        # bodies keep separate nodes on the interface.
        lower = occ.addBox(0, 0, -H1, w, w, H1)
        upper = occ.addBox(0, 0, 0, w, w, H2)
        occ.synchronize()
        lower_vol = _gmsh.volumes_in(0, 0, -H1, w, w, 0)
        upper_vol = _gmsh.volumes_in(0, 0, 0, w, w, H2)
        if lower_vol != [lower] or upper_vol != [upper]:
            raise SolveError(f"gmsh returned unexpected volumes {lower_vol}, {upper_vol}")
        both = lower_vol + upper_vol
        master = _gmsh.faces_in(0, 0, 0, w, w, 0, lower_vol)
        slave = _gmsh.faces_in(0, 0, 0, w, w, 0, upper_vol)
        bottom = _gmsh.faces_in(0, 0, -H1, w, w, -H1, lower_vol)
        top = _gmsh.faces_in(0, 0, H2, w, w, H2, upper_vol)
        sym_x = _gmsh.faces_in(0, 0, -H1, 0, w, H2, both)
        sym_y = _gmsh.faces_in(0, 0, -H1, w, 0, H2, both)
        if matching:
            identity = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]
            gmsh.model.mesh.setPeriodic(2, slave, master, identity)
        else:
            # The slave face structured (transfinite, NONMATCHING_RATIO times finer along
            # each edge), the master face unstructured: no node of one faces one of the other
            # except at the corners.
            n_up = max(2, round(NONMATCHING_RATIO * math.ceil(w / hi - 1e-9)))
            for f in slave:
                for _, c in gmsh.model.getBoundary([(2, f)], oriented=False):
                    gmsh.model.mesh.setTransfiniteCurve(abs(c), n_up + 1)
                gmsh.model.mesh.setTransfiniteSurface(f)

        _gmsh.physical(3, lower_vol, BASE, NAMES[BASE])
        _gmsh.physical(3, upper_vol, UPPER, NAMES[UPPER])
        _gmsh.physical(2, bottom, FIXED, NAMES[FIXED])
        _gmsh.physical(2, top, LOADED, NAMES[LOADED])
        _gmsh.physical(2, master, MASTER, NAMES[MASTER])
        _gmsh.physical(2, slave, SLAVE, NAMES[SLAVE])
        _gmsh.physical(2, sym_x, SYMMETRY_X, NAMES[SYMMETRY_X])
        _gmsh.physical(2, sym_y, SYMMETRY_Y, NAMES[SYMMETRY_Y])
        size_field()
        gmsh.model.mesh.generate(3)
        info["n_contact_nodes"] = len(set().union(*(
            gmsh.model.mesh.getNodes(2, f, includeBoundary=True)[0] for f in master)))
        return info

    def model_hex():
        return _hexahedra(w, H1, H2, hl, hu, hi, matching, info)

    model = model_2d if dim == 2 else (model_hex if cell == "hexahedron" else model_3d)
    return _gmsh.generate(comm, f"patch_{dim}d", model, gdim=dim)


def _graded_curves(volume, counts, ratio):
    """Transfinite curves of a box: segments counts[axis] along each axis, spacing growing
    by ``ratio`` per segment towards +x, +y (vertical edges uniform)."""
    import gmsh
    curves = {abs(t) for _, t in gmsh.model.getBoundary(
        gmsh.model.getBoundary([(3, volume)], combined=False, oriented=False),
        combined=False, oriented=False)}
    for c in sorted(curves):
        ends = [p for _, p in gmsh.model.getBoundary([(1, c)], oriented=False)]
        a, b = (gmsh.model.getValue(0, p, []) for p in ends)
        axis = int(abs(b - a).argmax())
        coef = 1.0 if axis == 2 else (ratio if b[axis] > a[axis] else 1.0 / ratio)
        gmsh.model.mesh.setTransfiniteCurve(c, counts[axis] + 1, "Progression", coef)


def _hexahedra(w, H1, H2, hl, hu, hi, matching, info):
    """The two bodies in hexahedra (transfinite, recombined); see ``build``'s ``cell``."""
    import gmsh
    occ = gmsh.model.occ
    lower = occ.addBox(0, 0, -H1, w, w, H1)
    upper = occ.addBox(0, 0, 0, w, w, H2)
    occ.synchronize()
    n = max(2, math.ceil(w / hi - 1e-9))
    n_up = n if matching else max(n + 1, round(NONMATCHING_RATIO * n))
    layers = [max(1, math.ceil(H / (0.5 * (hi + h)) - 1e-9)) for H, h in ((H1, hl), (H2, hu))]
    _graded_curves(lower, (n, n, layers[0]), PROGRESSION_2D)
    _graded_curves(upper, (n_up, n_up, layers[1]),
                   PROGRESSION_2D if matching else 1.0 / PROGRESSION_2D)
    for v in (lower, upper):
        for _, f in gmsh.model.getBoundary([(3, v)], combined=False, oriented=False):
            gmsh.model.mesh.setTransfiniteSurface(abs(f))
            gmsh.model.mesh.setRecombine(2, abs(f))
        gmsh.model.mesh.setTransfiniteVolume(v)
    both = [lower, upper]
    _gmsh.physical(3, [lower], BASE, NAMES[BASE])
    _gmsh.physical(3, [upper], UPPER, NAMES[UPPER])
    _gmsh.physical(2, _gmsh.faces_in(0, 0, -H1, w, w, -H1, [lower]), FIXED, NAMES[FIXED])
    _gmsh.physical(2, _gmsh.faces_in(0, 0, H2, w, w, H2, [upper]), LOADED, NAMES[LOADED])
    _gmsh.physical(2, _gmsh.faces_in(0, 0, 0, w, w, 0, [lower]), MASTER, NAMES[MASTER])
    _gmsh.physical(2, _gmsh.faces_in(0, 0, 0, w, w, 0, [upper]), SLAVE, NAMES[SLAVE])
    _gmsh.physical(2, _gmsh.faces_in(0, 0, -H1, 0, w, H2, both), SYMMETRY_X, NAMES[SYMMETRY_X])
    _gmsh.physical(2, _gmsh.faces_in(0, 0, -H1, w, 0, H2, both), SYMMETRY_Y, NAMES[SYMMETRY_Y])
    gmsh.model.mesh.generate(3)
    info["h_interface"] = w / n
    info["n_contact_nodes"] = (n + 1) ** 2
    if not matching:
        info["n_contact_nodes_upper"] = (n_up + 1) ** 2
    return info
