"""Known fields written by flexcontact.ResultWriter, and a plain-Python reader of the file.

Run as a script (serially or under mpirun) it writes the 2D case into the folder given as its
argument, so that the tests can compare the files written on one and on two ranks.
"""
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

TIMES = (0.5, 1.0, 1.5)


def fields_2d(msh, t):
    """x²·t (P1 scalar), (x², x·y)·t (P1 vector), x + 2y (DG0, at the cell midpoints)."""
    from flexcontact import compat
    import dolfinx.fem
    s = dolfinx.fem.Function(compat.scalar_space(msh), name="x2")
    s.interpolate(lambda x: t * x[0] ** 2)
    u = dolfinx.fem.Function(compat.vector_space(msh), name="displacement")
    u.interpolate(lambda x: np.vstack([t * x[0] ** 2, t * x[0] * x[1]]))
    c = dolfinx.fem.Function(compat.scalar_space(msh, "DG", 0), name="cellx")
    c.interpolate(lambda x: x[0] + 2 * x[1])
    return [s, u, c]


def left_right_tags(msh):
    """Cell tags: 1 for cells whose midpoint has x < 0.5, 2 for the others."""
    import dolfinx.mesh
    tdim = msh.topology.dim
    left = dolfinx.mesh.locate_entities(msh, tdim, lambda x: x[0] <= 0.5 + 1e-12)
    n = msh.topology.index_map(tdim).size_local + msh.topology.index_map(tdim).num_ghosts
    values = np.full(n, 2, dtype=np.int32)
    # locate_entities wants all vertices inside: cells straddling x = 0.5 do not exist here.
    values[left] = 1
    return dolfinx.mesh.meshtags(msh, tdim, np.arange(n, dtype=np.int32), values)


def write_2d(folder, comm, n=6):
    import dolfinx.mesh
    import flexcontact as fc
    msh = dolfinx.mesh.create_unit_square(comm, n, n)
    with fc.ResultWriter(folder, "case", msh, tags=(left_right_tags(msh),)) as w:
        for t in TIMES:
            w.write(fields_2d(msh, t), t)
    return Path(folder) / "case.xdmf"


def _array(item: ET.Element, folder: Path) -> np.ndarray:
    """The array a Binary DataItem points at, read with NumPy."""
    assert item.get("Format") == "Binary" and item.get("Endian") == "Little"
    kind = {"Float": "f", "Int": "i"}[item.get("NumberType")]
    dtype = np.dtype(f"<{kind}{item.get('Precision')}")
    shape = tuple(int(d) for d in item.get("Dimensions").split())
    return np.fromfile(folder / item.text.strip(), dtype=dtype, count=int(np.prod(shape)),
                       offset=int(item.get("Seek"))).reshape(shape)


def read(path):
    """[{"t", "x", "cells", "topology_type", "seeks", "attributes": {name: (center, type,
    precision, array)}}] for each Grid of the temporal collection."""
    path = Path(path)
    root = ET.parse(path).getroot()
    collections = root.findall("./Domain/Grid")
    assert len(collections) == 1 and collections[0].get("CollectionType") == "Temporal"
    steps = []
    for grid in collections[0].findall("Grid"):
        geo = grid.find("Geometry/DataItem")
        topo = grid.find("Topology/DataItem")
        attributes = {}
        for a in grid.findall("Attribute"):
            item = a.find("DataItem")
            attributes[a.get("Name")] = (a.get("Center"), a.get("AttributeType"),
                                         item.get("Precision"), _array(item, path.parent))
        steps.append({"t": float(grid.find("Time").get("Value")),
                      "x": _array(geo, path.parent), "cells": _array(topo, path.parent),
                      "topology_type": grid.find("Topology").get("TopologyType"),
                      "seeks": (geo.get("Seek"), topo.get("Seek")),
                      "attributes": attributes})
    return steps


if __name__ == "__main__":
    from mpi4py import MPI
    write_2d(sys.argv[1], MPI.COMM_WORLD)
