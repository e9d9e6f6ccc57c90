"""A contact interface whose master surface lies on the slave's own body is refused by name.

The mesh's connected components (mesh_bodies.body_labels) tell the bodies apart: on the
Hertz mesh the block and the cylinder are two components, whatever the partition. A
boundary tag of the cylinder given as the master of the cylinder's own contact surface is
an error naming both tags; with ``self_contact=True`` it is a SelfContactWarning instead.
"""
import json
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI

sys.path.insert(0, str(Path(__file__).resolve().parent))
from conftest import on_two_ranks  # noqa: E402

import flexcontact as fc  # noqa: E402
from flexcontact import compat  # noqa: E402
from flexcontact.mesh_bodies import body_labels  # noqa: E402
from flexcontact.meshes import hertz2d, tags  # noqa: E402
from flexcontact.pairing import SelfContactWarning, pair_interfaces  # noqa: E402
from flexcontact.surface import surface_nodes  # noqa: E402


@pytest.fixture(scope="module")
def mesh():
    return hertz2d.build(MPI.COMM_WORLD, refine=0)


def _labels(msh, facets) -> dict:
    """The body labels of the nodes of four tagged surfaces (rank 0; None elsewhere)."""
    V = compat.vector_space(msh)
    out, blocks, spans = {}, [], {}
    for name, tag in (("slave", tags.SLAVE), ("loaded", tags.LOADED),
                      ("master", tags.MASTER), ("fixed", tags.FIXED)):
        s = surface_nodes(V, facets, tag)
        b = np.asarray(s["dofs"])[:, 0] // 2
        spans[name] = (len(blocks), b.size)
        blocks.extend(b.tolist())
    labels = body_labels(V, np.asarray(blocks, np.int64) if MPI.COMM_WORLD.rank == 0 else None)
    if MPI.COMM_WORLD.rank != 0:
        return None
    for name, (a, n) in spans.items():
        out[name] = sorted(set(labels[a:a + n].tolist()))
    return out


def test_the_two_bodies_are_two_components(mesh):
    msh, cells, facets, _ = mesh
    lab = _labels(msh, facets)
    if MPI.COMM_WORLD.rank == 0:
        assert lab["slave"] == lab["loaded"] and len(lab["slave"]) == 1   # the cylinder
        assert lab["master"] == lab["fixed"] and len(lab["master"]) == 1  # the block
        assert lab["slave"] != lab["master"]


def _pair(msh, facets, **interface):
    """Pair one interface of the Hertz mesh as a problem's constructor does."""
    itf = fc.ContactInterface(facets, mu=0.0, **interface)
    return pair_interfaces(compat.vector_space(msh), [itf], MPI.COMM_WORLD)


def test_a_master_on_the_slaves_own_body_is_named(mesh):
    msh, cells, facets, _ = mesh
    with pytest.raises(fc.InputError, match=rf"master surface \(facet tag {tags.LOADED}\) "
                       rf"lies on the same body as the slave surface \(facet tag "
                       rf"{tags.SLAVE}\).*self_contact=True"):
        _pair(msh, facets, slave=tags.SLAVE, master=tags.LOADED)


def test_self_contact_when_meant_is_a_warning(mesh):
    msh, cells, facets, _ = mesh
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        _pair(msh, facets, slave=tags.SLAVE, master=tags.LOADED, pairing="node_to_surface",
              self_contact=True)
    if MPI.COMM_WORLD.rank == 0:
        assert any(issubclass(w.category, SelfContactWarning) for w in caught), caught


def test_two_ranks_give_the_same_bodies(tmp_path):
    on_two_ranks(__file__, tmp_path, timeout=300)
    par = json.loads((tmp_path / "labels.json").read_text())
    assert par["ranks"] == 2
    assert par["slave"] == par["loaded"] and par["master"] == par["fixed"]
    assert par["slave"] != par["master"] and len(par["slave"]) == len(par["master"]) == 1
    assert par["error"] and f"facet tag {tags.LOADED}" in par["error"]


if __name__ == "__main__":
    msh, cells, facets, _ = hertz2d.build(MPI.COMM_WORLD, refine=0)
    out = _labels(msh, facets)
    error = None
    try:
        _pair(msh, facets, slave=tags.SLAVE, master=tags.LOADED)
    except fc.InputError as e:
        error = str(e)
    if MPI.COMM_WORLD.rank == 0:
        out.update(ranks=MPI.COMM_WORLD.size, error=error)
        Path(sys.argv[1], "labels.json").write_text(json.dumps(out))
