// Copyright flexcontact developers. MIT licence.

#include "contact_blocks.h"
#include "collective.h"
#include "flexibility.h"
#include "petsc_error.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iomanip>
#include <limits>
#include <mpi.h>
#include <numeric>
#include <sstream>
#include <unordered_map>
#include <utility>

using namespace flexcontact;

extern "C"
{
void dpotrf_(const char* uplo, const int* n, double* a, const int* lda, int* info);
void dpocon_(const char* uplo, const int* n, const double* a, const int* lda,
             const double* anorm, double* rcond, double* work, int* iwork, int* info);
}

namespace
{
/// @brief Disjoint sets with path halving; the smaller index becomes the root.
struct UnionFind
{
  std::vector<std::int64_t> parent;
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  std::int64_t find(std::int64_t x)
  {
    while (parent[x] != x)
    {
      parent[x] = parent[parent[x]];
      x = parent[x];
    }
    return x;
  }
  void unite(std::int64_t a, std::int64_t b)
  {
    a = find(a);
    b = find(b);
    if (a != b)
      parent[std::max(a, b)] = std::min(a, b);
  }
};

/// @brief Values of the distributed `v` at the global rows `rows` (given on this rank).
std::vector<double> values_at(PetscErrorScope& err, Vec v, const std::vector<PetscInt>& rows)
{
  IS is = nullptr;
  Vec seq = nullptr;
  VecScatter sc = nullptr;
  const PetscInt n = static_cast<PetscInt>(rows.size());
  err.check(ISCreateGeneral(PETSC_COMM_SELF, n, rows.data(), PETSC_COPY_VALUES, &is),
            "ISCreateGeneral");
  err.check(VecCreateSeq(PETSC_COMM_SELF, n, &seq), "VecCreateSeq");
  err.check(VecScatterCreate(v, is, seq, nullptr, &sc), "VecScatterCreate");
  err.check(VecScatterBegin(sc, v, seq, INSERT_VALUES, SCATTER_FORWARD), "VecScatterBegin");
  err.check(VecScatterEnd(sc, v, seq, INSERT_VALUES, SCATTER_FORWARD), "VecScatterEnd");
  std::vector<double> out(n);
  const PetscScalar* a = nullptr;
  err.check(VecGetArrayRead(seq, &a), "VecGetArrayRead");
  std::copy(a, a + n, out.begin());
  err.check(VecRestoreArrayRead(seq, &a), "VecRestoreArrayRead");
  VecScatterDestroy(&sc);
  VecDestroy(&seq);
  ISDestroy(&is);
  return out;
}

/// @brief Local components of the owned rows [r0, r1) (edges to owned columns only): the
/// union-find, and the (local row, global column) edges to columns owned elsewhere.
UnionFind local_components(PetscErrorScope& err, Mat K, PetscInt r0, PetscInt r1,
                           std::vector<std::pair<PetscInt, PetscInt>>& ghost_edges)
{
  UnionFind uf(static_cast<std::size_t>(r1 - r0));
  for (PetscInt r = r0; r < r1; ++r)
  {
    PetscInt nc = 0;
    const PetscInt* cols = nullptr;
    err.check(MatGetRow(K, r, &nc, &cols, nullptr), "MatGetRow");
    for (PetscInt k = 0; k < nc; ++k)
    {
      if (cols[k] >= r0 and cols[k] < r1)
        uf.unite(r - r0, cols[k] - r0);
      else
        ghost_edges.emplace_back(r - r0, cols[k]);
    }
    err.check(MatRestoreRow(K, r, &nc, &cols, nullptr), "MatRestoreRow");
  }
  return uf;
}

/// @brief Error text of a block that is not positive definite.
std::string singular_block(std::size_t b, std::size_t n_blocks, int n, double rcond)
{
  std::ostringstream s;
  s << "stiffness matrix is singular: the condensed stiffness K*_cc on the " << n
    << " contact DOFs of block " << b << " (of " << n_blocks
    << " bodies) is not positive definite (reciprocal condition number " << std::scientific
    << std::setprecision(2) << rcond
    << "; a body has rigid-body modes that no Dirichlet condition removes)";
  return s.str();
}
} // namespace

std::vector<int> flexcontact::contact_blocks(Mat K, const std::vector<PetscInt>& dofs)
{
  PetscErrorScope err;
  MPI_Comm comm = PetscObjectComm(reinterpret_cast<PetscObject>(K));
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  PetscInt r0 = 0, r1 = 0;
  err.check(MatGetOwnershipRange(K, &r0, &r1), "MatGetOwnershipRange");
  std::vector<std::pair<PetscInt, PetscInt>> ghost_edges;
  UnionFind uf = local_components(err, K, r0, r1, ghost_edges);

  // Number the local components globally: rank offset + local index of the root.
  const PetscInt n = r1 - r0;
  std::vector<std::int64_t> local_id(n, -1);
  std::int64_t n_local = 0, offset = 0, n_total = 0;
  for (PetscInt i = 0; i < n; ++i)
    if (uf.find(i) == i)
      local_id[i] = n_local++;
  MPI_Exscan(&n_local, &offset, 1, MPI_INT64_T, MPI_SUM, comm);
  if (rank == 0)
    offset = 0;
  MPI_Allreduce(&n_local, &n_total, 1, MPI_INT64_T, MPI_SUM, comm);
  auto comp = [&](PetscInt i) { return offset + local_id[uf.find(i)]; };

  Vec label = nullptr;
  err.check(MatCreateVecs(K, nullptr, &label), "MatCreateVecs");
  PetscScalar* a = nullptr;
  err.check(VecGetArray(label, &a), "VecGetArray");
  for (PetscInt i = 0; i < n; ++i)
    a[i] = static_cast<double>(comp(i)); // exact below 2⁵³ components
  err.check(VecRestoreArray(label, &a), "VecRestoreArray");

  // Edges between components through columns owned elsewhere, gathered on rank 0.
  std::vector<PetscInt> ghosts;
  for (const auto& e : ghost_edges)
    ghosts.push_back(e.second);
  std::sort(ghosts.begin(), ghosts.end());
  ghosts.erase(std::unique(ghosts.begin(), ghosts.end()), ghosts.end());
  const std::vector<double> ghost_comp = values_at(err, label, ghosts);
  std::vector<std::int64_t> send;
  for (const auto& [i, c] : ghost_edges)
  {
    const auto g = std::lower_bound(ghosts.begin(), ghosts.end(), c) - ghosts.begin();
    send.push_back(comp(i));
    send.push_back(static_cast<std::int64_t>(ghost_comp[g]));
  }
  const std::vector<std::int64_t> edges = gather_on_root(comm, send, MPI_INT64_T);

  const std::vector<double> dof_comp
      = values_at(err, label, rank == 0 ? dofs : std::vector<PetscInt>());
  VecDestroy(&label);
  if (rank != 0)
    return {};
  UnionFind global(static_cast<std::size_t>(n_total));
  for (std::size_t k = 0; k < edges.size(); k += 2)
    global.unite(edges[k], edges[k + 1]);
  std::unordered_map<std::int64_t, int> block_of_root;
  std::vector<int> labels(dofs.size());
  for (std::size_t k = 0; k < dofs.size(); ++k)
  {
    const std::int64_t root = global.find(static_cast<std::int64_t>(dof_comp[k]));
    labels[k] = block_of_root.try_emplace(root, static_cast<int>(block_of_root.size()))
                    .first->second;
  }
  return labels;
}

std::vector<std::vector<int>> flexcontact::block_members(const std::vector<int>& labels)
{
  const int n_blocks = labels.empty() ? 0 : *std::max_element(labels.begin(), labels.end()) + 1;
  std::vector<std::vector<int>> blocks(n_blocks);
  for (std::size_t k = 0; k < labels.size(); ++k)
    blocks[labels[k]].push_back(static_cast<int>(k));
  return blocks;
}

BlockFlexibility flexcontact::blockwise_cholesky(const double* s, std::size_t lda,
                                                const std::vector<std::vector<int>>& blocks)
{
  std::size_t n = 0;
  for (const auto& b : blocks)
    n += b.size();
  std::vector<Eigen::MatrixXd> factors;
  for (std::size_t b = 0; b < blocks.size(); ++b)
  {
    const std::vector<int>& idx = blocks[b];
    const int nb = static_cast<int>(idx.size());
    Eigen::MatrixXd A(nb, nb); // the block, symmetrised (its lower triangle is used)
    for (int j = 0; j < nb; ++j)
      for (int i = j; i < nb; ++i)
        A(i, j) = 0.5 * (s[idx[i] + idx[j] * lda] + s[idx[j] + idx[i] * lda]);
    std::vector<double> colsum(nb, 0.0); // 1-norm of the symmetric block, for dpocon
    for (int j = 0; j < nb; ++j)
      for (int i = j; i < nb; ++i)
      {
        colsum[j] += std::abs(A(i, j));
        if (i != j)
          colsum[i] += std::abs(A(i, j));
      }
    const double anorm = nb ? *std::max_element(colsum.begin(), colsum.end()) : 0.0;
    int info = 0;
    double rcond = 0.0;
    dpotrf_("L", &nb, A.data(), &nb, &info);
    if (info == 0)
    {
      std::vector<double> work(3 * static_cast<std::size_t>(nb));
      std::vector<int> iwork(nb);
      dpocon_("L", &nb, A.data(), &nb, &anorm, &rcond, work.data(), iwork.data(), &info);
    }
    if (info != 0 or !(rcond > 1e3 * std::numeric_limits<double>::epsilon()))
      throw SingularStiffnessError(singular_block(b, blocks.size(), nb, info == 0 ? rcond : 0.0));
    A.triangularView<Eigen::StrictlyUpper>().setZero();
    factors.push_back(std::move(A));
  }
  return BlockFlexibility(static_cast<Eigen::Index>(n), blocks, std::move(factors));
}
