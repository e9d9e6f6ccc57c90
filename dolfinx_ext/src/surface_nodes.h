// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file surface_nodes.h
/// @brief The nodes of a tagged boundary: coordinates, DOFs, outward normals, tributary areas.

#include "compat.h"
#include <cstdint>
#include <vector>

namespace flexcontact
{
/// @brief Nodes of a tagged surface, gathered on rank 0, sorted by coordinates.
struct SurfaceNodes
{
  int gdim = 0;                     ///< geometric dimension
  int bs = 0;                       ///< DOFs per node (block size of the space)
  std::vector<double> x;            ///< n×gdim coordinates, row major
  std::vector<std::int64_t> dofs;   ///< n×bs global DOF indices, block·bs + component
  std::vector<double> normal;       ///< n×gdim unit outward normals
  std::vector<double> area;         ///< n tributary lengths (2D) / areas (3D)
  std::size_t size() const { return area.size(); }
};

/// @brief Nodes of the facets tagged `value`, with their outward normals and tributary
/// areas.
///
/// The normal of a node is the facet-measure-weighted mean of the outward unit normals of
/// the tagged facets around it (outward: pointing away from the facet's cell), normalised.
/// Its tributary area is Σ (facet measure / vertices per facet) over those facets. Facets
/// are collected on every rank (owned and ghost), sent to rank 0 and merged there by their
/// vertices' global DOF indices, so each facet and each node counts once whatever the
/// partition; nodes are sorted lexicographically by coordinates. Collective.
///
/// @param V P1 (scalar or vector) Lagrange space on the mesh of the tags, not a sub-space
/// @param tags facet tags (dimension tdim − 1)
/// @param value the tag of the surface
/// @return on rank 0 the nodes; on other ranks empty arrays
/// @throws std::invalid_argument if `value` is on no facet of the mesh (the message lists
/// the values present), if the tags are not facet tags of V's mesh, or V is not P1
SurfaceNodes surface_nodes(const compat::FunctionSpace& V, const compat::MeshTags& tags,
                           int value);
} // namespace flexcontact
