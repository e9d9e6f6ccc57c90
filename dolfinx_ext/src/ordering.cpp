// Copyright flexcontact developers. MIT licence.

#include "ordering.h"
#include "collective.h"
#include "mumps_layout.h"
#include "petsc_error.h"

#include <metis.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <mpi.h>
#include <stdexcept>
#include <utility>

using namespace flexcontact;

namespace
{
constexpr std::array<std::pair<const char*, int>, 6> kOrderings{
    {{"metis", 1}, {"mumps", 7}, {"amd", 0}, {"amf", 2}, {"pord", 4}, {"qamd", 6}}};

/// @brief The compressed nodal graph of K (rows grouped by the block size bs, no self
/// loops): METIS's xadj and adjncy.
void nodal_graph(Mat K, PetscInt bs, std::vector<idx_t>& xadj, std::vector<idx_t>& adj)
{
  PetscErrorScope err;
  PetscInt nrows = 0;
  const PetscInt *ia = nullptr, *ja = nullptr;
  PetscBool done = PETSC_FALSE;
  err.check(MatGetRowIJ(K, 0, PETSC_FALSE, PETSC_FALSE, &nrows, &ia, &ja, &done), "MatGetRowIJ");
  if (!done)
    throw std::runtime_error("METIS ordering: PETSc cannot give the sparsity pattern of K");
  const PetscInt n = nrows / bs;
  xadj.assign(n + 1, 0);
  adj.clear();
  adj.reserve(static_cast<std::size_t>(ia[nrows]) / (bs * bs) + n);
  std::vector<PetscInt> mark(n, -1);
  for (PetscInt v = 0; v < n; ++v)
  {
    xadj[v] = static_cast<idx_t>(adj.size());
    for (PetscInt r = v * bs; r < (v + 1) * bs; ++r)
      for (PetscInt k = ia[r]; k < ia[r + 1]; ++k)
      {
        const PetscInt w = ja[k] / bs;
        if (w != v and mark[w] != v)
        {
          mark[w] = v;
          adj.push_back(static_cast<idx_t>(w));
        }
      }
  }
  xadj[n] = static_cast<idx_t>(adj.size());
  err.check(MatRestoreRowIJ(K, 0, PETSC_FALSE, PETSC_FALSE, &nrows, &ia, &ja, &done),
            "MatRestoreRowIJ");
}
/// @brief Pivot position (1-based, MUMPS's PERM_IN) of each of the N rows from METIS nested
/// dissection of the nodal graph (xadj, adj; bs rows per node) without the nodes of the
/// `last` rows, which come at the end in their given order.
std::vector<int> pivot_order(std::vector<idx_t>& xadj, std::vector<idx_t>& adj, PetscInt bs,
                             PetscInt N, std::span<const PetscInt> last)
{
  idx_t n = static_cast<idx_t>(N / bs);
  std::vector<idx_t> iperm(n);
  std::array<idx_t, METIS_NOPTIONS> options;
  METIS_SetDefaultOptions(options.data());
  // The `last` nodes (the Schur complement's) are ordered by removing them from the graph
  // and dissecting the rest, not by moving them out of a dissection of the whole graph: the
  // dissection then never spends a separator on nodes that are eliminated last anyway. On
  // the bench's Hertz meshes (MUMPS's analysis): 3D 130k, 91.2M entries and 1.49e11 flops
  // against 93.1M and 1.57e11; 2D 800k, 71.5M and 2.81e10 against 71.8M and 2.83e10.
  std::vector<char> gone(n, 0);
  for (PetscInt r : last)
    gone[r / bs] = 1;
  std::vector<idx_t> keep_id(n, -1), kept;
  for (idx_t v = 0; v < n; ++v)
    if (!gone[v])
    {
      keep_id[v] = static_cast<idx_t>(kept.size());
      kept.push_back(v);
    }
  idx_t nk = static_cast<idx_t>(kept.size());
  std::vector<idx_t> kx(nk + 1, 0), ka;
  ka.reserve(adj.size());
  for (idx_t k = 0; k < nk; ++k)
  {
    for (idx_t j = xadj[kept[k]]; j < xadj[kept[k] + 1]; ++j)
      if (keep_id[adj[j]] >= 0)
        ka.push_back(keep_id[adj[j]]);
    kx[k + 1] = static_cast<idx_t>(ka.size());
  }
  std::vector<idx_t> kperm(nk), kiperm(nk);
  int rc = METIS_OK;
  if (nk > 0)
    rc = METIS_NodeND(&nk, kx.data(), ka.data(), nullptr, options.data(), kperm.data(),
                      kiperm.data());
  // Kept nodes in METIS's order, then the removed ones (whose rows outside `last`, if any,
  // come just before the `last` rows).
  for (idx_t k = 0; k < nk; ++k)
    iperm[kept[k]] = kiperm[k];
  for (idx_t v = 0, next = nk; v < n; ++v)
    if (gone[v])
      iperm[v] = next++;
  if (rc != METIS_OK)
    throw std::runtime_error("METIS_NodeND failed (return code " + std::to_string(rc)
                             + ") on the nodal graph of K (" + std::to_string(n) + " nodes)");

  // Pivot position of each row: its node's place in METIS's order, the node's rows kept
  // together; then the `last` rows moved to the end and the others closed up.
  std::vector<PetscInt> order(N); // order[position] = row
  for (idx_t v = 0; v < n; ++v)
    for (PetscInt c = 0; c < bs; ++c)
      order[static_cast<std::size_t>(iperm[v]) * bs + c] = static_cast<PetscInt>(v) * bs + c;
  std::vector<char> is_last(N, 0);
  for (PetscInt r : last)
    is_last[r] = 1;
  std::vector<int> perm_in(N);
  int pos = 0;
  for (PetscInt r : order)
    if (!is_last[r])
      perm_in[r] = ++pos;
  for (PetscInt r : last)
    perm_in[r] = ++pos;
  return perm_in;
}

/// @brief The edges (v, w), v ≠ w, of the nodal graph from the locally owned rows of K
/// (global node numbers, bs rows per node), flattened; either direction may be missing
/// (an SBAIJ K stores the upper triangle only).
std::vector<std::int64_t> local_node_edges(Mat K, PetscInt bs, PetscInt rstart, PetscInt rend)
{
  PetscErrorScope err;
  std::vector<std::int64_t> edges;
  std::vector<std::int64_t> nbrs;
  err.check(MatGetRowUpperTriangular(K), "MatGetRowUpperTriangular");
  for (PetscInt v = rstart / bs; v < rend / bs; ++v)
  {
    nbrs.clear();
    for (PetscInt r = v * bs; r < (v + 1) * bs; ++r)
    {
      PetscInt ncols = 0;
      const PetscInt* cols = nullptr;
      err.check(MatGetRow(K, r, &ncols, &cols, nullptr), "MatGetRow");
      for (PetscInt k = 0; k < ncols; ++k)
        if (cols[k] / bs != v)
          nbrs.push_back(cols[k] / bs);
      err.check(MatRestoreRow(K, r, &ncols, &cols, nullptr), "MatRestoreRow");
    }
    std::sort(nbrs.begin(), nbrs.end());
    nbrs.erase(std::unique(nbrs.begin(), nbrs.end()), nbrs.end());
    for (std::int64_t w : nbrs)
    {
      edges.push_back(v);
      edges.push_back(w);
    }
  }
  err.check(MatRestoreRowUpperTriangular(K), "MatRestoreRowUpperTriangular");
  return edges;
}

/// @brief METIS's symmetric graph (both directions, no repeats) of n nodes from edges
/// (v, w) given in either or both directions.
void graph_from_edges(std::int64_t n, const std::vector<std::int64_t>& edges,
                      std::vector<idx_t>& xadj, std::vector<idx_t>& adj)
{
  std::vector<std::vector<idx_t>> nbrs(n);
  for (std::size_t k = 0; k < edges.size(); k += 2)
  {
    nbrs[edges[k]].push_back(static_cast<idx_t>(edges[k + 1]));
    nbrs[edges[k + 1]].push_back(static_cast<idx_t>(edges[k]));
  }
  xadj.assign(n + 1, 0);
  adj.clear();
  for (std::int64_t v = 0; v < n; ++v)
  {
    std::vector<idx_t>& l = nbrs[v];
    std::sort(l.begin(), l.end());
    l.erase(std::unique(l.begin(), l.end()), l.end());
    adj.insert(adj.end(), l.begin(), l.end());
    xadj[v + 1] = static_cast<idx_t>(adj.size());
    std::vector<idx_t>().swap(l);
  }
}
} // namespace

bool flexcontact::is_ordering(const std::string& name)
{
  return name == "auto" or std::any_of(kOrderings.begin(), kOrderings.end(),
                     [&name](const auto& o) { return name == o.first; });
}

std::string flexcontact::resolve_ordering(const std::string& name, Mat K, bool schur)
{
  if (name != "auto")
    return name;
  PetscInt bs = 1, N = 0;
  PetscErrorScope err;
  err.check(MatGetBlockSize(K, &bs), "MatGetBlockSize");
  err.check(MatGetSize(K, &N, nullptr), "MatGetSize");
  // Below this size METIS and the redone analysis cost more than the flops they save over
  // MUMPS's AMD (2D Hertz, CPU time: 50k DOFs 0.26 s against 0.14 s; 200k 2.2 s against 2.7 s).
  constexpr PetscInt schur_metis_min_dofs = 100000;
  return (bs == 3 or (schur and N >= schur_metis_min_dofs)) ? "metis" : "mumps";
}

int flexcontact::mumps_icntl7(const std::string& name)
{
  for (const auto& [n, v] : kOrderings)
    if (name == n)
      return v;
  throw std::invalid_argument("unknown ordering '" + name
                              + "' (expected 'auto', 'metis', 'mumps', 'amd', 'amf', 'pord' or 'qamd')");
}

std::string flexcontact::ordering_name(int infog7)
{
  switch (infog7)
  {
  case 0: return "amd";
  case 1: return "metis";
  case 2: return "amf";
  case 3: return "scotch";
  case 4: return "pord";
  case 5: return "mumps_metis";
  case 6: return "qamd";
  default: return "unknown(" + std::to_string(infog7) + ")";
  }
}

std::vector<int> flexcontact::metis_pivot_order(Mat K, std::span<const PetscInt> last)
{
  PetscErrorScope err;
  PetscInt N = 0, bs = 1;
  err.check(MatGetSize(K, &N, nullptr), "MatGetSize");
  err.check(MatGetBlockSize(K, &bs), "MatGetBlockSize");
  if (bs < 1 or N % bs != 0)
    bs = 1;
  std::vector<idx_t> xadj, adj;
  nodal_graph(K, bs, xadj, adj);
  return pivot_order(xadj, adj, bs, N, last);
}

std::vector<int> flexcontact::metis_pivot_order_gathered(Mat K, std::span<const PetscInt> last)
{
  PetscErrorScope err;
  MPI_Comm comm = PetscObjectComm(reinterpret_cast<PetscObject>(K));
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  PetscInt N = 0, bs = 1, rstart = 0, rend = 0;
  err.check(MatGetSize(K, &N, nullptr), "MatGetSize");
  err.check(MatGetBlockSize(K, &bs), "MatGetBlockSize");
  err.check(MatGetOwnershipRange(K, &rstart, &rend), "MatGetOwnershipRange");
  // Nodes must not straddle ranks: else the graph is taken DOF by DOF.
  int aligned = (bs >= 1 and N % bs == 0 and rstart % bs == 0 and rend % bs == 0) ? 1 : 0;
  MPI_Allreduce(MPI_IN_PLACE, &aligned, 1, MPI_INT, MPI_MIN, comm);
  if (!aligned)
    bs = 1;
  const std::vector<std::int64_t> edges = local_node_edges(K, bs, rstart, rend);
  const std::vector<std::int64_t> all = gather_on_root(comm, edges, MPI_INT64_T);
  if (rank != 0)
    return {};
  std::vector<idx_t> xadj, adj;
  graph_from_edges(static_cast<std::int64_t>(N / bs), all, xadj, adj);
  return pivot_order(xadj, adj, bs, N, last);
}

void flexcontact::reanalyse(Mat F, PetscInt N, int icntl7, std::vector<int> perm_in)
{
  // The values PETSc's analysis of a symmetric matrix on one process must have left in the
  // MUMPS structure it calls (mumps_layout.h).
  DMUMPS_STRUC_C* id = mumps_struct(F);
  PetscInt infog7 = -1;
  PetscErrorScope err;
  err.check(MatMumpsGetInfog(F, 7, &infog7), "MatMumpsGetInfog(7)");
  if (!id or id->job != 1 or id->n != N or id->sym != 2 or id->par != 1
      or id->infog[0] < 0 or id->infog[6] != infog7)
    throw MumpsLayoutError(
        "cannot give MUMPS an ordering through this PETSc (its MUMPS factor is not laid out "
        "as expected); use ordering='mumps'");
  if (icntl7 == 1 and perm_in.size() != static_cast<std::size_t>(N))
    throw std::invalid_argument("PERM_IN has the wrong size");
  // MUMPS reads PERM_IN in the analysis only; PETSc's own pointer (none) is put back after,
  // so that PETSc frees only what it allocated.
  int* const petsc_perm_in = id->perm_in;
  if (icntl7 == 1)
    id->perm_in = perm_in.data();
  id->icntl[6] = icntl7;
  id->job = 1;
  dmumps_c(id);
  id->perm_in = petsc_perm_in;
  if (id->infog[0] < 0)
    throw std::runtime_error("MUMPS failed in the analysis with ordering ICNTL(7)="
                             + std::to_string(icntl7) + ": INFOG(1)="
                             + std::to_string(id->infog[0]) + ", INFOG(2)="
                             + std::to_string(id->infog[1]));
  // MUMPS may replace one of its own orderings (with a Schur complement AMF, PORD, QAMD become
  // AMD, INFOG(7) says), but must follow a given permutation.
  if (icntl7 == 1 and id->infog[6] != 1)
    throw std::runtime_error("MUMPS did not use the requested ordering ICNTL(7)="
                             + std::to_string(icntl7) + " (INFOG(7)="
                             + std::to_string(id->infog[6]) + ")");
}
