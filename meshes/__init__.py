"""gmsh geometries for flexcontact's demos and tests, returned as DOLFINx meshes.

Every builder has the signature ``build(comm, ...) -> (mesh, cell_tags, facet_tags, info)``
(``info``: dict of geometry parameters in m) and follows one tagging convention:

======  ===============  =====================================================
tag     name             meaning
======  ===============  =====================================================
1       ``base``         cells of the lower body (the MASTER body)
2       ``upper``        cells of the upper body (the SLAVE body)
10      ``fixed``        facets: bottom of the lower body (clamped)
11      ``loaded``       facets: top of the upper body (loaded)
12      ``symmetry_x``   facets on the plane x = 0 (3D quarter models, both bodies)
13      ``symmetry_y``   facets on the plane y = 0 (3D quarter models, both bodies)
20      ``master``       facets: master contact surface (top of the lower body,
                         candidate contact zone)
21      ``slave``        facets: slave contact surface (bottom of the upper body,
                         candidate contact zone)
======  ===============  =====================================================

The two bodies never share nodes, and on the candidate contact zone their nodes match: each
slave node lies exactly opposite one master node (same x in 2D, same (x, y) in 3D for the
flat master surface z = 0 / y = 0), separated only by the initial gap along the master
normal. That is what node–node contact needs.
"""

from ._gmsh import to_dolfinx
from .tools import surface_coordinates

from .tags import (BASE, FIXED, LOADED, MASTER, NAMES, SLAVE, SYMMETRY_X, SYMMETRY_Y,  # noqa: F401
                   UPPER)
from . import (bar_impact, block_on_base, hertz2d, hertz3d, oblique_impact, patch,  # noqa: E402,F401
               two_cylinders)

__all__ = ["BASE", "UPPER", "FIXED", "LOADED", "SYMMETRY_X", "SYMMETRY_Y", "MASTER", "SLAVE",
           "NAMES", "to_dolfinx", "surface_coordinates", "bar_impact", "block_on_base", "hertz2d", "hertz3d",
           "oblique_impact", "patch", "two_cylinders"]
