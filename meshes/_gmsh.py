"""The one place that talks to both gmsh and DOLFINx's gmsh reader.

A builder calls :func:`generate` with a function that, on rank 0 only, adds geometry,
physical groups and the mesh to the current gmsh model. The mesh is then distributed to
every rank of ``comm``. Errors raised while building are re-raised on every rank, so a bad
parameter cannot leave the other ranks waiting in a broadcast.
"""

import gmsh
from flexcontact import compat
from flexcontact.mpi import raise_on_every_rank

_owned = False  # True while gmsh was initialised by this module (so we finalise it)


def _is_initialized() -> bool:
    """Whether gmsh is initialised. gmsh 4.8 cannot tell (its API answers even before
    ``initialize``), so there only this module's own sessions are known: a session the
    caller opened is then finalised too, after the mesh was read."""
    probe = getattr(gmsh, "isInitialized", None)  # gmsh >= 4.11
    return bool(probe()) if probe is not None else _owned


def start(name: str):
    """Initialise gmsh (unless the caller already did) and add an empty model ``name``."""
    global _owned
    if not _is_initialized():
        gmsh.initialize(readConfigFiles=False)
        _owned = True
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.option.setNumber("General.Verbosity", 2)
    # Coincident points of the two bodies must stay distinct entities: node–node contact
    # needs separate nodes on each side of the interface.
    gmsh.option.setNumber("Geometry.AutoCoherence", 0)
    gmsh.model.add(name)


def stop():
    """Remove the current model; finalise gmsh if this module initialised it."""
    global _owned
    if _is_initialized() or _owned:
        gmsh.model.remove()
        if _owned:
            gmsh.finalize()
            _owned = False


def to_dolfinx(comm, gdim: int):
    """Distribute the current gmsh model (living on rank 0) as a DOLFINx mesh.

    Returns ``(mesh, cell_tags, facet_tags)``. Must be called on every rank of ``comm``;
    finalises gmsh on rank 0 afterwards. Only elements in physical groups are kept.
    """
    try:
        msh, cell_tags, facet_tags = compat.gmsh_model_to_mesh(gmsh.model, comm, 0, gdim)
    finally:
        if comm.rank == 0:
            stop()
    return msh, cell_tags, facet_tags


def generate(comm, name: str, build_model, gdim: int):
    """Run ``build_model()`` on rank 0 inside a fresh gmsh model, then :func:`to_dolfinx`.

    ``build_model`` returns a picklable dict of geometry parameters, which is broadcast and
    returned as the fourth item: ``(mesh, cell_tags, facet_tags, info)``.
    """
    info, error = None, None
    if comm.rank == 0:
        try:
            start(name)
            info = build_model()
        except Exception as exc:  # re-raised on every rank below
            error = exc
            stop()
    raise_on_every_rank(comm, error)
    info = comm.bcast(info, root=0)
    msh, cell_tags, facet_tags = to_dolfinx(comm, gdim)
    return msh, cell_tags, facet_tags, info


def mesh_uniform(dim: int, h: float) -> None:
    """Mesh the current model's ``dim``-entities with elements of size ``h`` everywhere,
    then restore gmsh's default size bounds for the next model of a session the caller
    opened."""
    gmsh.option.setNumber("Mesh.MeshSizeMin", h)
    gmsh.option.setNumber("Mesh.MeshSizeMax", h)
    try:
        gmsh.model.mesh.generate(dim)
    finally:
        gmsh.option.setNumber("Mesh.MeshSizeMin", 0.0)
        gmsh.option.setNumber("Mesh.MeshSizeMax", 1e22)


def mesh_with_balls(dim: int, h: float, balls=(), layer=None) -> None:
    """Mesh the current model's ``dim``-entities with elements of size ``h``, capped inside
    each ball ``(size, x, y, z, radius)`` as in :func:`size_field` (``layer`` too); no ball:
    as :func:`mesh_uniform`."""
    if not balls:
        return mesh_uniform(dim, h)
    _background([_layered(_ball(*b, h), b[0], h, layer) for b in balls])
    gmsh.option.setNumber("Mesh.MeshSizeMax", h)
    try:
        gmsh.model.mesh.generate(dim)
    finally:  # gmsh's defaults again, for the next model of a session the caller opened
        gmsh.option.setNumber("Mesh.MeshSizeMax", 1e22)
        for key, default in (("MeshSizeFromPoints", 1), ("MeshSizeFromCurvature", 0),
                             ("MeshSizeExtendFromBoundary", 1)):
            gmsh.option.setNumber(f"Mesh.{key}", default)


def physical(dim: int, entities, tag: int, name: str):
    """Add a named physical group of ``dim``-entities with number ``tag``."""
    gmsh.model.addPhysicalGroup(dim, list(entities), tag)
    gmsh.model.setPhysicalName(dim, tag, name)


def size_field(entities, dim: int, h_near: float, h_far: float, dist_near: float,
               dist_far: float, points_per_curve: int = 20, boxes=(), balls=(),
               balls_only_in=None, layer=None, caps_in=()):
    """Background mesh size (m): h_near within dist_near of the ``dim``-entities (curves or
    surfaces), growing linearly to h_far at dist_far. ``boxes``: extra caps
    ``(size, x0, y0, z0, x1, y1, z1)``; inside such a box the size never exceeds ``size``.
    ``balls``: caps ``(size, x, y, z, radius)``, the size inside the ball of that radius,
    growing beyond it at the rate 1/2 until the rest is smaller; ``balls_only_in``: volume
    tags to which the balls are restricted (with their faces, curves and points: gmsh 4.11
    applies a restriction to the listed entities only). ``layer`` = (entities, entity_dim,
    depth_m): a ball's size holds only within ``depth_m`` of those entities (curves or
    surfaces), and grows beyond at the rate 1/2 too (a crushed patch needs fine elements
    along the end it lies on, not deep behind it). ``caps_in``: caps ``(size, entity_dim,
    tags)``, the size never exceeded in those surfaces (2) or volumes (3) and on their
    closure, as a body meshed finer than the zone about it. Sizes from points and curvature
    are switched off."""
    field = gmsh.model.mesh.field
    fields = [_threshold(entities, dim, h_near, h_far, dist_near, dist_far, points_per_curve)]
    for size, *box in boxes:
        f_box = field.add("Box")
        for key, val in zip(("XMin", "YMin", "ZMin", "XMax", "YMax", "ZMax"), box):
            field.setNumber(f_box, key, val)
        field.setNumber(f_box, "VIn", size)
        field.setNumber(f_box, "VOut", h_far)
        fields.append(f_box)
    for ball in balls:
        # Growing to h_far, the ball leaves the near field in charge beyond it (the Min below).
        f_ball = _layered(_ball(*ball, h_far), ball[0], h_far, layer)
        if balls_only_in:
            f_ball = _restricted(f_ball, balls_only_in)
        fields.append(f_ball)
    for size, entity_dim, tags in caps_in:
        f_size = field.add("MathEval")
        field.setString(f_size, "F", repr(float(size)))
        fields.append(_restricted(f_size, tags, entity_dim))
    _background(fields)


def _threshold(entities, dim: int, size_min: float, size_max: float, dist_min: float,
               dist_max: float, points_per_curve: int) -> int:
    """A Threshold field: ``size_min`` within ``dist_min`` of the ``dim``-entities (curves or
    surfaces), growing linearly to ``size_max`` at ``dist_max``."""
    field = gmsh.model.mesh.field
    f_dist = field.add("Distance")
    field.setNumbers(f_dist, {1: "CurvesList", 2: "FacesList"}[dim], list(entities))  # 4.8 names
    field.setNumber(f_dist, "NumPointsPerCurve", points_per_curve)
    f_thr = field.add("Threshold")
    field.setNumber(f_thr, "InField", f_dist)
    for key, val in (("SizeMin", size_min), ("SizeMax", size_max), ("DistMin", dist_min),
                     ("DistMax", dist_max)):
        field.setNumber(f_thr, key, val)
    return f_thr


def _ball(size, x, y, z, radius, v_out) -> int:
    """A Ball field: ``size`` inside the ball, growing to ``v_out`` at the rate 1/2 (over
    2(v_out − size)) beyond it, as well-shaped grading needs: a blend over a fixed thickness
    grows at a rate set by v_out (up to 8 from a crushed patch's 12.5 mm to a far field's
    3 m)."""
    field = gmsh.model.mesh.field
    f = field.add("Ball")
    for key, val in (("XCenter", x), ("YCenter", y), ("ZCenter", z), ("Radius", radius),
                     ("Thickness", 2.0 * (v_out - size)), ("VIn", size), ("VOut", v_out)):
        field.setNumber(f, key, val)
    return f


def _layered(f_ball: int, size: float, h: float, layer) -> int:
    """The larger of ``f_ball`` and a size that is ``size`` within ``depth_m`` of the
    layer's entities and grows to ``h`` over 2(h − size) beyond; ``layer`` None: ``f_ball``
    itself."""
    if layer is None:
        return f_ball
    entities, entity_dim, depth = layer
    field = gmsh.model.mesh.field
    # Distances are to sample points: 100 per curve put them 8 mm apart on a 0.8 m end.
    f_thr = _threshold(entities, entity_dim, size, h, depth, depth + 2.0 * (h - size), 100)
    f_max = field.add("Max")
    field.setNumbers(f_max, "FieldsList", [f_ball, f_thr])
    return f_max


def _background(fields: list) -> None:
    """The smallest of ``fields`` as the background size, and no size from points,
    curvature or the boundary."""
    field = gmsh.model.mesh.field
    if len(fields) > 1:
        f_min = field.add("Min")
        field.setNumbers(f_min, "FieldsList", fields)
        fields = [f_min]
    field.setAsBackgroundMesh(fields[0])
    for key in ("MeshSizeFromPoints", "MeshSizeFromCurvature", "MeshSizeExtendFromBoundary"):
        gmsh.option.setNumber(f"Mesh.{key}", 0)


def _restricted(f_in: int, entities, dim: int = 3) -> int:
    """A Restrict field applying ``f_in`` in the ``dim``-entities (volumes or surfaces) and
    on their closure."""
    field = gmsh.model.mesh.field
    closure = {dim: [(dim, t) for t in entities]}
    for d in range(dim, 1, -1):
        closure[d - 1] = gmsh.model.getBoundary(closure[d], combined=False, oriented=False)
    closure[0] = gmsh.model.getBoundary(closure[dim], combined=False, oriented=False,
                                        recursive=True)
    f = field.add("Restrict")
    field.setNumber(f, "InField", f_in)
    for d, key in ((3, "VolumesList"), (2, "SurfacesList"), (1, "CurvesList"),
                   (0, "PointsList")):
        if d in closure:
            field.setNumbers(f, key, sorted({abs(t) for _, t in closure[d]}))
    return f


# ---- finding OpenCASCADE entities by position (builders call these inside their model) --
def entities_in(dim, box, owners):
    """Tags of ``dim``-entities inside the bounding box (with a tiny tolerance) that bound
    one of the ``owners`` volumes (so coincident faces of the other body are excluded)."""
    eps = _box_tolerance(box)
    lo, hi = [v - eps for v in box[:3]], [v + eps for v in box[3:]]
    found = [t for _, t in gmsh.model.getEntitiesInBoundingBox(*lo, *hi, dim)]
    own = set()
    for v in owners:
        own.update(abs(t) for _, t in gmsh.model.getBoundary([(3, v)], oriented=False))
    return sorted(t for t in found if t in own)


def _box_tolerance(box):
    """Search margin (m): OpenCASCADE enlarges bounding boxes by its tolerance (~1e-7 m)."""
    return 1e-6 * max(1.0, max(abs(v) for v in box)) + 1e-6 * max(box[3] - box[0], box[4] - box[1],
                                                                    box[5] - box[2])


def faces_in(x0, y0, z0, x1, y1, z1, owners):
    return entities_in(2, (x0, y0, z0, x1, y1, z1), owners)


def volumes_in(x0, y0, z0, x1, y1, z1):
    eps = _box_tolerance((x0, y0, z0, x1, y1, z1))
    return [t for _, t in gmsh.model.getEntitiesInBoundingBox(x0 - eps, y0 - eps, z0 - eps,
                                                             x1 + eps, y1 + eps, z1 + eps, 3)]
