"""The XDMF file itself (rank 0): one Temporal collection, one Grid per time step.

Each step's Grid is the whole mesh with every field as an Attribute, in double precision, so
that ParaView shows one dataset: Warp By Vector on the displacement, then colour by any field.
The geometry and topology are written once; every step's Grid points at the same bytes.

Heavy data go to one raw little-endian binary file (``Format="Binary"`` with a byte ``Seek``)
rather than HDF5: the file is only ever appended to, so a run that stops mid-step leaves every
byte the XML already points at as it was (an HDF5 file interrupted while open can lose what it
held before), it is written with NumPy alone (no second HDF5 library beside the MPI one
DOLFINx links), and ParaView's XDMF readers, meshio and VisIt read it.

The XML is rewritten after every step into a temporary file that then replaces the old one
(an atomic rename), so the ``.xdmf`` on disk is always complete and names only data written.
"""
from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from .xdmf_gather import Field


def _attribute_type(values: np.ndarray) -> str:
    return "Scalar" if values.shape[1] == 1 else "Vector"


class XdmfSeries:
    """Append-only writer of ``<name>.xdmf`` + ``<name>.bin`` (call on one rank only).

    ``x`` (nodes, 3) and ``cells`` (cells, vertices per cell) are the mesh in file order;
    ``static`` lists (name, integer per cell) attributes repeated at every step (cell tags).
    """

    def __init__(self, path: Path, topology_type: str, x: np.ndarray, cells: np.ndarray,
                 static: list[tuple[str, np.ndarray]] = ()):
        self.path = Path(path)
        self.bin_path = self.path.with_suffix(".bin")
        self.topology_type = topology_type
        self.n_cells, self.nodes_per_cell = cells.shape
        self._bin = open(self.bin_path, "wb")
        self._geometry = self._append(np.asarray(x, dtype="<f8"))
        self._topology = self._append(np.asarray(cells, dtype="<i8"))
        self._static = [(name, "Cell", "Scalar", self._append(np.asarray(v, dtype="<i4")))
                        for name, v in static]
        self._bin.flush()
        self._grids: list[bytes] = []   # each step's Grid, serialized once
        self._write_xml()

    def _append(self, a: np.ndarray) -> dict:
        """Write an array at the end of the binary file; the DataItem attributes that find it."""
        a = np.ascontiguousarray(a)
        offset = self._bin.tell()
        self._bin.write(a.tobytes())
        return {"Dimensions": " ".join(str(n) for n in a.shape),
                "NumberType": "Float" if a.dtype.kind == "f" else "Int",
                "Precision": str(a.dtype.itemsize), "Format": "Binary", "Endian": "Little",
                "Seek": str(offset)}

    def add_step(self, t: float, fields: list[Field]) -> None:
        """Append the fields of one time step and rewrite the XML to include it."""
        attributes = [(f.name, f.center, _attribute_type(f.values),
                       self._append(np.asarray(f.values, dtype="<f8"))) for f in fields]
        self._bin.flush()
        self._grids.append(self._grid(t, attributes))
        self._write_xml()

    def close(self) -> None:
        if not self._bin.closed:
            self._bin.close()

    def _data_item(self, parent, item: dict) -> None:
        ET.SubElement(parent, "DataItem", item).text = self.bin_path.name

    def _grid(self, t: float, attributes) -> bytes:
        grid = ET.Element("Grid", Name="mesh", GridType="Uniform")
        ET.SubElement(grid, "Time", Value=repr(float(t)))
        topo = ET.SubElement(grid, "Topology", TopologyType=self.topology_type,
                             NumberOfElements=str(self.n_cells),
                             NodesPerElement=str(self.nodes_per_cell))
        self._data_item(topo, self._topology)
        self._data_item(ET.SubElement(grid, "Geometry", GeometryType="XYZ"), self._geometry)
        for name, center, kind, item in self._static + attributes:
            attr = ET.SubElement(grid, "Attribute", Name=name, AttributeType=kind, Center=center)
            self._data_item(attr, item)
        ET.indent(grid, space="  ", level=3)
        return b"      " + ET.tostring(grid) + b"\n"

    def _write_xml(self) -> None:
        # Each step's Grid is serialized once, so a long run rewrites bytes, not trees.
        head = (b'<?xml version="1.0"?>\n<Xdmf Version="3.0">\n  <Domain>\n'
                b'    <Grid Name="TimeSeries" GridType="Collection" CollectionType="Temporal">\n')
        tail = b"    </Grid>\n  </Domain>\n</Xdmf>\n"
        tmp = self.path.with_name(self.path.name + ".tmp")
        with open(tmp, "wb") as f:
            f.write(head + b"".join(self._grids) + tail)
        os.replace(tmp, self.path)
