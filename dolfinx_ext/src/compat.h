// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file compat.h
/// @brief Every DOLFINx-version-dependent type and call of dolfinx_ext, in one place.
///
/// DOLFINx 0.5 (Debian 12) is the reference; the `DOLFINX_VERSION_MINOR >= 8` branches carry
/// the templated spelling of DOLFINx 0.8/0.9 (Mesh<T>, FunctionSpace<T>, Function<T, U>,
/// the geometry dofmap as a 2-D mdspan, the topology held by shared pointer). Porting the
/// bridge to another DOLFINx release should touch this file only.

#include <cstdint>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>

#include <dolfinx/common/IndexMap.h>
#include <dolfinx/common/version.h>
#include <dolfinx/fem/DofMap.h>
#include <dolfinx/fem/Function.h>
#include <dolfinx/fem/FunctionSpace.h>
#include <dolfinx/la/Vector.h>
#include <dolfinx/mesh/Geometry.h>
#include <dolfinx/mesh/Mesh.h>
#include <dolfinx/mesh/MeshTags.h>
#include <dolfinx/mesh/Topology.h>
#include <dolfinx/mesh/cell_types.h>

#include <pybind11/pybind11.h>

namespace flexcontact::compat
{
#if DOLFINX_VERSION_MINOR >= 8
using Mesh = dolfinx::mesh::Mesh<double>;
using FunctionSpace = dolfinx::fem::FunctionSpace<double>;
using Function = dolfinx::fem::Function<double, double>;
#else
using Mesh = dolfinx::mesh::Mesh;
using FunctionSpace = dolfinx::fem::FunctionSpace;
using Function = dolfinx::fem::Function<double>;
#endif
using MeshTags = dolfinx::mesh::MeshTags<std::int32_t>;
using Topology = dolfinx::mesh::Topology;

/// @brief The mesh topology (read only).
inline const Topology& topology(const Mesh& mesh)
{
#if DOLFINX_VERSION_MINOR >= 8
  return *mesh.topology();
#else
  return mesh.topology();
#endif
}

/// @brief Create the connectivity d0 → d1 (and the entities it needs) if missing.
inline void create_connectivity(const Mesh& mesh, int d0, int d1)
{
#if DOLFINX_VERSION_MINOR >= 8
  mesh.topology_mutable()->create_entities(d0);
  mesh.topology_mutable()->create_connectivity(d0, d1);
#else
  mesh.topology_mutable().create_entities(d0);
  mesh.topology_mutable().create_connectivity(d0, d1);
#endif
}

/// @brief Entities of dimension d1 connected to entity e of dimension d0.
/// @pre the connectivity d0 → d1 exists (create_connectivity)
inline std::span<const std::int32_t> links(const Mesh& mesh, int d0, int d1, std::int32_t e)
{
  auto c = topology(mesh).connectivity(d0, d1);
  if (!c)
    throw std::runtime_error("mesh connectivity " + std::to_string(d0) + " -> "
                             + std::to_string(d1) + " has not been created");
  return c->links(e);
}

/// @brief Geometry node indices of cell c (first the vertices, in reference order).
inline std::span<const std::int32_t> cell_geometry_nodes(const Mesh& mesh, std::int32_t c)
{
#if DOLFINX_VERSION_MINOR >= 8
  auto g = mesh.geometry().dofmap();
  return std::span<const std::int32_t>(g.data_handle() + c * g.extent(1), g.extent(1));
#else
  return mesh.geometry().dofmap().links(c);
#endif
}

/// @brief Geometry coordinates, 3 per node (padded with zeros when gdim < 3).
inline std::span<const double> geometry_x(const Mesh& mesh) { return mesh.geometry().x(); }

/// @brief Reference vertices of each entity of dimension dim of the cell type:
/// result[e] lists the cell-local vertex indices of entity e.
inline std::vector<std::vector<int>> entity_vertices(dolfinx::mesh::CellType type, int dim)
{
  auto adj = dolfinx::mesh::get_entity_vertices(type, dim);
  std::vector<std::vector<int>> out(adj.num_nodes());
  for (std::int32_t e = 0; e < adj.num_nodes(); ++e)
  {
    auto l = adj.links(e);
    out[e].assign(l.begin(), l.end());
  }
  return out;
}

/// @brief The mesh a set of tags lives on (its topology, from DOLFINx 0.8).
inline const Topology& tags_topology(const MeshTags& tags)
{
#if DOLFINX_VERSION_MINOR >= 8
  return *tags.topology();
#else
  return tags.mesh()->topology();
#endif
}

/// @brief The mutable array (owned values followed by ghosts) of a Function's vector.
inline std::span<double> function_array(Function& u) { return u.x()->mutable_array(); }

/// @brief Push owned values of a Function to the ghosts of the other ranks.
inline void scatter_forward(Function& u) { u.x()->scatter_fwd(); }

/// @brief Unwrap a DOLFINx object given from Python: the C++ object itself, or a Python
/// wrapper holding it as `_cpp_object` (dolfinx.fem.Function / FunctionSpace in 0.5, and
/// most wrappers from 0.8 on).
/// @throws pybind11::type_error naming the expected type when neither works
template <class T>
std::shared_ptr<T> unwrap(pybind11::handle obj, const char* expected)
{
  namespace py = pybind11;
  try
  {
    return obj.cast<std::shared_ptr<T>>();
  }
  catch (const py::cast_error&)
  {
  }
  if (py::hasattr(obj, "_cpp_object"))
  {
    try
    {
      return obj.attr("_cpp_object").cast<std::shared_ptr<T>>();
    }
    catch (const py::cast_error&)
    {
    }
  }
  throw py::type_error(std::string("expected ") + expected + ", got "
                       + std::string(py::str(py::type::of(obj).attr("__name__"))));
}
} // namespace flexcontact::compat
