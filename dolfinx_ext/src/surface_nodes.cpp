// Copyright flexcontact developers. MIT licence.

#include "surface_nodes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <mpi.h>
#include <numeric>
#include <set>
#include <sstream>
#include <stdexcept>

using namespace flexcontact;

namespace
{
/// @brief Every tag value present on any rank, sorted.
std::vector<std::int32_t> global_tag_values(MPI_Comm comm, const compat::MeshTags& tags)
{
  std::set<std::int32_t> local(tags.values().begin(), tags.values().end());
  std::vector<std::int32_t> mine(local.begin(), local.end());
  int size = 1;
  MPI_Comm_size(comm, &size);
  int n = static_cast<int>(mine.size());
  std::vector<int> counts(size), offsets(size + 1, 0);
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  std::partial_sum(counts.begin(), counts.end(), offsets.begin() + 1);
  std::vector<std::int32_t> all(offsets.back());
  MPI_Allgatherv(mine.data(), n, MPI_INT32_T, all.data(), counts.data(), offsets.data(),
                 MPI_INT32_T, comm);
  std::sort(all.begin(), all.end());
  all.erase(std::unique(all.begin(), all.end()), all.end());
  return all;
}

/// @brief Unit normal (unoriented) and measure of a facet from its vertex coordinates
/// (gdim per vertex): segment in 2D, triangle or planar quadrilateral in 3D.
std::pair<std::array<double, 3>, double> facet_normal(const std::vector<double>& X, int nv,
                                                      int gdim)
{
  std::array<double, 3> n = {0, 0, 0};
  auto p = [&](int v, int k) { return X[v * gdim + k]; };
  if (gdim == 2)
  {
    n = {p(1, 1) - p(0, 1), -(p(1, 0) - p(0, 0)), 0};
  }
  else
  {
    // Triangle: (x1 − x0) × (x2 − x0). Quadrilateral (DOLFINx vertex order 0,1,2,3 with
    // diagonals 0–3 and 1–2): (x3 − x0) × (x2 − x1); both give twice the area.
    std::array<double, 3> a, b;
    for (int k = 0; k < 3; ++k)
    {
      a[k] = nv == 3 ? p(1, k) - p(0, k) : p(3, k) - p(0, k);
      b[k] = nv == 3 ? p(2, k) - p(0, k) : p(2, k) - p(1, k);
    }
    n = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
  }
  double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  double measure = gdim == 2 ? len : 0.5 * len;
  if (len > 0)
    for (auto& c : n)
      c /= len;
  return {n, measure};
}

/// @brief Gather a vector on rank 0.
template <class T>
std::vector<T> gather(MPI_Comm comm, const std::vector<T>& send, MPI_Datatype type)
{
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  int n = static_cast<int>(send.size());
  std::vector<int> counts(size), offsets(size + 1, 0);
  MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, comm);
  std::partial_sum(counts.begin(), counts.end(), offsets.begin() + 1);
  std::vector<T> recv(rank == 0 ? offsets.back() : 0);
  MPI_Gatherv(send.data(), n, type, recv.data(), counts.data(), offsets.data(), type, 0, comm);
  return recv;
}
} // namespace

SurfaceNodes flexcontact::surface_nodes(const compat::FunctionSpace& V,
                                        const compat::MeshTags& tags, int value)
{
  auto mesh = V.mesh();
  if (!mesh)
    throw std::invalid_argument("the function space has no mesh");
  MPI_Comm comm = mesh->comm();
  int rank = 0;
  MPI_Comm_rank(comm, &rank);

  const compat::Topology& topology = compat::topology(*mesh);
  const int tdim = topology.dim();
  const int fdim = tdim - 1;
  const int gdim = mesh->geometry().dim();
  if (&compat::tags_topology(tags) != &topology)
    throw std::invalid_argument("the facet tags belong to another mesh than the function space");
  if (tags.dim() != fdim)
    throw std::invalid_argument("the tags are of entity dimension " + std::to_string(tags.dim())
                                + ", facet tags (dimension " + std::to_string(fdim)
                                + ") are needed");
  if (gdim != tdim)
    throw std::invalid_argument("surface_nodes needs a mesh whose geometric dimension equals "
                                "its topological dimension (got gdim="
                                + std::to_string(gdim) + ", tdim=" + std::to_string(tdim) + ")");
  if (!V.component().empty())
    throw std::invalid_argument("surface_nodes needs a whole function space, not a sub-space");

  // The tag must exist somewhere; if not, say which values do.
  std::vector<std::int32_t> present = global_tag_values(comm, tags);
  if (!std::binary_search(present.begin(), present.end(), value))
  {
    std::ostringstream s;
    s << "facet tag value " << value << " does not occur on any facet of the mesh; the facet "
      << "tags hold the values [";
    for (std::size_t i = 0; i < present.size(); ++i)
      s << (i ? ", " : "") << present[i];
    s << "]";
    throw std::invalid_argument(s.str());
  }

  const auto cell_type = topology.cell_type();
  const int nv_cell = dolfinx::mesh::num_cell_vertices(cell_type);
  const auto facet_vertices = compat::entity_vertices(cell_type, fdim);
  const int nv = static_cast<int>(facet_vertices.front().size());
  for (const auto& f : facet_vertices)
    if (static_cast<int>(f.size()) != nv)
      throw std::invalid_argument("cells with facets of different types are not supported");

  auto dofmap = V.dofmap();
  const int bs = dofmap->index_map_bs();
  auto index_map = dofmap->index_map;

  compat::create_connectivity(*mesh, fdim, tdim);
  compat::create_connectivity(*mesh, tdim, fdim);
  std::span<const double> xg = compat::geometry_x(*mesh);

  // Per tagged facet: nv global node indices; nv×gdim coordinates, gdim normal, measure.
  std::vector<std::int64_t> send_nodes;
  std::vector<double> send_data;
  const int ndata = nv * gdim + gdim + 1;
  const auto& indices = tags.indices();
  const auto& values = tags.values();
  std::vector<double> X(nv * gdim);
  for (std::size_t i = 0; i < indices.size(); ++i)
  {
    if (values[i] != value)
      continue;
    const std::int32_t f = indices[i];
    const std::int32_t c = compat::links(*mesh, fdim, tdim, f).front();
    auto cell_facets = compat::links(*mesh, tdim, fdim, c);
    const int lf = static_cast<int>(
        std::distance(cell_facets.begin(), std::find(cell_facets.begin(), cell_facets.end(), f)));
    auto gnodes = compat::cell_geometry_nodes(*mesh, c);
    auto cdofs = dofmap->cell_dofs(c);
    if (static_cast<int>(cdofs.size()) != nv_cell)
      throw std::invalid_argument("surface_nodes needs a P1 space: "
                                  + std::to_string(cdofs.size()) + " nodes per cell, expected "
                                  + std::to_string(nv_cell));

    // Cell centroid and the facet's vertices.
    std::array<double, 3> xc = {0, 0, 0}, xf = {0, 0, 0};
    for (int v = 0; v < nv_cell; ++v)
      for (int k = 0; k < gdim; ++k)
        xc[k] += xg[3 * gnodes[v] + k] / nv_cell;
    for (int j = 0; j < nv; ++j)
    {
      const int v = facet_vertices[lf][j];
      for (int k = 0; k < gdim; ++k)
      {
        X[j * gdim + k] = xg[3 * gnodes[v] + k];
        xf[k] += X[j * gdim + k] / nv;
      }
      std::int64_t g = 0;
      std::int32_t l = cdofs[v];
      index_map->local_to_global(std::span<const std::int32_t>(&l, 1),
                                 std::span<std::int64_t>(&g, 1));
      send_nodes.push_back(g);
    }
    auto [n, measure] = facet_normal(X, nv, gdim);
    double side = 0;
    for (int k = 0; k < gdim; ++k)
      side += n[k] * (xf[k] - xc[k]);
    if (side < 0)
      for (auto& nk : n)
        nk = -nk;
    send_data.insert(send_data.end(), X.begin(), X.end());
    send_data.insert(send_data.end(), n.begin(), n.begin() + gdim);
    send_data.push_back(measure);
  }

  std::vector<std::int64_t> nodes = gather(comm, send_nodes, MPI_INT64_T);
  std::vector<double> data = gather(comm, send_data, MPI_DOUBLE);

  SurfaceNodes out;
  out.gdim = gdim;
  out.bs = bs;
  if (rank != 0)
    return out;

  // Merge: each facet once (key: sorted node indices), then sum per node.
  struct Acc
  {
    std::array<double, 3> x{}, n{};
    double area = 0;
  };
  std::map<std::int64_t, Acc> acc;
  std::set<std::vector<std::int64_t>> seen;
  const std::size_t nfacets = nodes.size() / nv;
  for (std::size_t f = 0; f < nfacets; ++f)
  {
    std::vector<std::int64_t> key(nodes.begin() + f * nv, nodes.begin() + (f + 1) * nv);
    std::sort(key.begin(), key.end());
    if (!seen.insert(key).second)
      continue;
    const double* d = data.data() + f * ndata;
    const double* n = d + nv * gdim;
    const double measure = n[gdim];
    for (int j = 0; j < nv; ++j)
    {
      Acc& a = acc[nodes[f * nv + j]];
      for (int k = 0; k < gdim; ++k)
      {
        a.x[k] = d[j * gdim + k];
        a.n[k] += measure * n[k];
      }
      a.area += measure / nv;
    }
  }

  // Sort nodes lexicographically by coordinates.
  std::vector<std::pair<std::int64_t, const Acc*>> order;
  for (const auto& [g, a] : acc)
    order.emplace_back(g, &a);
  std::sort(order.begin(), order.end(), [gdim](const auto& p, const auto& q) {
    for (int k = 0; k < gdim; ++k)
      if (p.second->x[k] != q.second->x[k])
        return p.second->x[k] < q.second->x[k];
    return p.first < q.first;
  });

  for (const auto& [g, a] : order)
  {
    double len = 0;
    for (int k = 0; k < gdim; ++k)
      len += a->n[k] * a->n[k];
    len = std::sqrt(len);
    for (int k = 0; k < gdim; ++k)
    {
      out.x.push_back(a->x[k]);
      out.normal.push_back(len > 0 ? a->n[k] / len : 0.0);
    }
    for (int c = 0; c < bs; ++c)
      out.dofs.push_back(g * bs + c);
    out.area.push_back(a->area);
  }
  return out;
}
