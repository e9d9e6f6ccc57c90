// Copyright flexcontact developers. MIT licence.

#include "flexibility.h"
#include "collective.h"
#include "contact_blocks.h"
#include "distributed_schur.h"
#include "ordering.h"
#include "petsc_error.h"

#include <algorithm>
#include <iomanip>
#include <sstream>
#include <limits>
#include <numeric>
#include <mpi.h>
#include <petscis.h>
#include <vector>

using namespace flexcontact;

namespace
{
/// @brief Owns one reference to a PETSc Mat.
struct OwnedMat
{
  Mat m = nullptr;
  OwnedMat() = default;
  OwnedMat(const OwnedMat&) = delete;
  OwnedMat& operator=(const OwnedMat&) = delete;
  ~OwnedMat()
  {
    if (m)
      MatDestroy(&m);
  }
  Mat release()
  {
    Mat out = m;
    m = nullptr;
    return out;
  }
};

/// @brief Owns one reference to a PETSc IS.
struct OwnedIS
{
  IS is = nullptr;
  OwnedIS() = default;
  OwnedIS(const OwnedIS&) = delete;
  OwnedIS& operator=(const OwnedIS&) = delete;
  ~OwnedIS()
  {
    if (is)
      ISDestroy(&is);
  }
};

/// @brief Check MUMPS's global status after a phase; INFOG is the same on every rank.
void check_mumps(PetscErrorScope& err, Mat F, const char* phase)
{
  PetscInt infog1 = 0, info2 = 0;
  err.check(MatMumpsGetInfog(F, 1, &infog1), "MatMumpsGetInfog");
  if (infog1 >= 0)
    return;
  err.check(MatMumpsGetInfog(F, 2, &info2), "MatMumpsGetInfog");
  throw_mumps_error(phase, static_cast<int>(infog1), static_cast<int>(info2));
}

/// @brief Number of null pivots MUMPS found (INFOG(28)), and the singular-K error if any.
int check_null_pivots(PetscErrorScope& err, Mat F)
{
  PetscInt n = 0;
  err.check(MatMumpsGetInfog(F, 28, &n), "MatMumpsGetInfog");
  throw_if_null_pivots(static_cast<int>(n));
  return static_cast<int>(n);
}

/// @brief Where MUMPS reports the size and cost of a factor (global INFOG/RINFOG indices):
/// entries (INFOG < 0 counts millions), flops, and memory in MB.
struct FactorSizeFields
{
  int entries, flops, memory_mb;
};
/// After the factorization: INFOG(29), RINFOG(3), INFOG(22).
constexpr FactorSizeFields factorized{29, 3, 22};
/// What the analysis expects of the factorization: INFOG(20), RINFOG(1), INFOG(17).
constexpr FactorSizeFields estimated{20, 1, 17};

/// @brief The ordering MUMPS used (INFOG(7)) and the size and cost of its factor, read
/// from `fields`.
void factor_size(PetscErrorScope& err, Mat F, FactorSizeFields fields, Flexibility& out)
{
  auto infog = [&](int i)
  {
    PetscInt v = 0;
    err.check(MatMumpsGetInfog(F, i, &v), ("MatMumpsGetInfog(" + std::to_string(i) + ")").c_str());
    return v;
  };
  const PetscInt infog7 = infog(7), entries = infog(fields.entries);
  const PetscInt memory_mb = infog(fields.memory_mb);
  PetscReal flops = 0;
  err.check(MatMumpsGetRinfog(F, fields.flops, &flops),
            ("MatMumpsGetRinfog(" + std::to_string(fields.flops) + ")").c_str());
  out.mumps_ordering = ordering_name(static_cast<int>(infog7));
  out.factor_entries = entries >= 0 ? static_cast<std::int64_t>(entries)
                                    : -static_cast<std::int64_t>(entries) * 1000000;
  out.factor_flops = flops;
  out.factor_memory_mb = static_cast<int>(memory_mb);
}

/// @brief MUMPS Cholesky of K with the fill-reducing `ordering` (ordering.h; serial unless
/// "mumps"), optionally with a centralised Schur complement on `schur` (rank 0's indices;
/// empty elsewhere). Returns the factored matrix; sets out.null_pivots, out.ordering and the
/// factor's statistics, and counts in out.factorization_retries the factorizations that ran
/// out of MUMPS workspace and were redone.
Mat factorize(PetscErrorScope& err, Mat K, const std::vector<PetscInt>* schur,
              const std::string& ordering, Flexibility& out, bool analysis_only = false)
{
  int& retries = out.factorization_retries;
  // K is factored as symmetric indefinite (LDLᵀ with pivoting), and in parallel MUMPS's
  // dynamic scheduling depends on the load of the machine: the factorization can outgrow the
  // workspace the analysis estimated (INFOG(1) = -8 or -9), now and then. MUMPS's remedy is a
  // larger ICNTL(14); PETSc refuses to repeat the numerical phase on a factor whose last phase
  // failed, so the whole factorization is redone with a fresh factor.
  retries = 0;
  PetscInt icntl14 = 0; // 0: MUMPS's default
  PetscInt N = 0;
  err.check(MatGetSize(K, &N, nullptr), "MatGetSize");
  int icntl7 = mumps_icntl7(ordering);
  std::vector<int> perm_in;
  double t0 = MPI_Wtime();
  if (icntl7 == 1)
    perm_in = metis_pivot_order(K, schur ? std::span<const PetscInt>(*schur)
                                         : std::span<const PetscInt>());
  out.ordering_s = MPI_Wtime() - t0;
  for (;;)
  {
    OwnedMat F;
    err.check(MatGetFactor(K, MATSOLVERMUMPS, MAT_FACTOR_CHOLESKY, &F.m), "MatGetFactor(mumps)");
    // ICNTL(24) = 1: detect null pivots (reported in INFOG(28)) instead of dividing by ~0.
    err.check(MatMumpsSetIcntl(F.m, 24, 1), "MatMumpsSetIcntl(24)");
    if (icntl14 > 0)
      err.check(MatMumpsSetIcntl(F.m, 14, icntl14), "MatMumpsSetIcntl(14)");
    // PETSc's own analysis is redone below with the requested ordering: let it use the
    // cheapest one (AMD) rather than MUMPS's automatic choice (PORD or AMF, slow in 3D).
    if (icntl7 != 7)
      err.check(MatMumpsSetIcntl(F.m, 7, 0), "MatMumpsSetIcntl(7)");
    if (schur)
    {
      MPI_Comm comm = PetscObjectComm(reinterpret_cast<PetscObject>(K));
      OwnedIS is;
      err.check(ISCreateGeneral(comm, static_cast<PetscInt>(schur->size()), schur->data(),
                                PETSC_COPY_VALUES, &is.is),
                "ISCreateGeneral");
      err.check(MatFactorSetSchurIS(F.m, is.is), "MatFactorSetSchurIS");
    }
    MatFactorInfo info;
    err.check(MatFactorInfoInitialize(&info), "MatFactorInfoInitialize");
    double ta = MPI_Wtime();
    err.check(MatCholeskyFactorSymbolic(F.m, K, nullptr, &info), "MatCholeskyFactorSymbolic");
    out.analysis_s = MPI_Wtime() - ta;
    check_mumps(err, F.m, "analysis");
    PetscInt used7 = -1;
    err.check(MatMumpsGetInfog(F.m, 7, &used7), "MatMumpsGetInfog(7)");
    if (icntl7 != 7 and not(icntl7 == 0 and used7 == 0)) // AMD asked and already used
    {
      // PETSc cannot pass ICNTL(7) = 1 with PERM_IN: redo the analysis with the requested
      // ordering on the same MUMPS instance.
      double t1 = MPI_Wtime();
      try
      {
        reanalyse(F.m, N, icntl7, perm_in);
      }
      catch (const MumpsLayoutError& e)
      {
        // "auto" promises a factorization, not METIS: start again with a fresh factor and
        // MUMPS's own choice (PETSc's analysis above used AMD).
        if (not out.ordering_auto)
          throw;
        out.ordering = "mumps";
        out.ordering_fallback = e.what();
        icntl7 = 7;
        out.ordering_s += MPI_Wtime() - t1;
        continue;
      }
      out.ordering_s += MPI_Wtime() - t1;
    }
    if (analysis_only)
    {
      factor_size(err, F.m, estimated, out);
      return F.release();
    }
    err.check(MatMumpsSetIcntl(F.m, 24, 1), "MatMumpsSetIcntl(24)");
    err.check(MatCholeskyFactorNumeric(F.m, K, &info), "MatCholeskyFactorNumeric");
    PetscInt infog1 = 0; // global: every rank takes the same branch
    err.check(MatMumpsGetInfog(F.m, 1, &infog1), "MatMumpsGetInfog");
    if ((infog1 == -8 or infog1 == -9) and retries < 3)
    {
      err.check(MatMumpsGetIcntl(F.m, 14, &icntl14), "MatMumpsGetIcntl(14)");
      icntl14 = std::max<PetscInt>(2 * icntl14, 50);
      ++retries;
      continue;
    }
    check_mumps(err, F.m, "factorization");
    out.null_pivots = check_null_pivots(err, F.m);
    factor_size(err, F.m, factorized, out);
    return F.release();
  }
}

/// @brief F* = rows c of X, K X = E_c, gathered on rank 0.
Eigen::MatrixXd multi_rhs_solve(PetscErrorScope& err, MPI_Comm comm, int rank, Mat K, Mat F,
                                const std::vector<PetscInt>& dofs)
{
  const int n_c = static_cast<int>(dofs.size());
  PetscInt m_local = 0, N = 0, rstart = 0, rend = 0;
  err.check(MatGetLocalSize(K, &m_local, nullptr), "MatGetLocalSize");
  err.check(MatGetSize(K, &N, nullptr), "MatGetSize");
  err.check(MatGetOwnershipRange(K, &rstart, &rend), "MatGetOwnershipRange");

  OwnedMat E, X;
  err.check(MatCreateDense(comm, m_local, PETSC_DECIDE, N, n_c, nullptr, &E.m), "MatCreateDense");
  err.check(MatCreateDense(comm, m_local, PETSC_DECIDE, N, n_c, nullptr, &X.m), "MatCreateDense");
  for (int j = 0; j < n_c; ++j)
  {
    if (dofs[j] >= rstart and dofs[j] < rend)
      err.check(MatSetValue(E.m, dofs[j], j, 1.0, INSERT_VALUES), "MatSetValue");
  }
  err.check(MatAssemblyBegin(E.m, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
  err.check(MatAssemblyEnd(E.m, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
  err.check(MatAssemblyBegin(X.m, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
  err.check(MatAssemblyEnd(X.m, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
  err.check(MatMatSolve(F, E.m, X.m), "MatMatSolve");

  // Local rows of X that are contact DOFs: (position in dofs, n_c values) each.
  PetscInt lda = 0;
  err.check(MatDenseGetLDA(X.m, &lda), "MatDenseGetLDA");
  const PetscScalar* x = nullptr;
  err.check(MatDenseGetArrayRead(X.m, &x), "MatDenseGetArrayRead");
  std::vector<double> send;
  for (int i = 0; i < n_c; ++i)
  {
    if (dofs[i] >= rstart and dofs[i] < rend)
    {
      send.push_back(i);
      const std::size_t r = dofs[i] - rstart;
      for (int j = 0; j < n_c; ++j)
        send.push_back(x[r + static_cast<std::size_t>(j) * lda]);
    }
  }
  err.check(MatDenseRestoreArrayRead(X.m, &x), "MatDenseRestoreArrayRead");

  const std::vector<double> recv = gather_on_root(comm, send, MPI_DOUBLE);

  Eigen::MatrixXd Fs;
  if (rank == 0)
  {
    Fs.resize(n_c, n_c);
    for (std::size_t p = 0; p < recv.size(); p += n_c + 1)
    {
      const int i = static_cast<int>(recv[p]);
      for (int j = 0; j < n_c; ++j)
        Fs(i, j) = recv[p + 1 + j];
    }
    Fs = 0.5 * (Fs + Fs.transpose()).eval();
  }
  return Fs;
}

/// @brief F* = (K⁻¹)_cc on rank 0 from MUMPS's computation of selected entries of the
/// inverse (ICNTL(30)), made with the plain factor F.
///
/// PETSc's MatMumpsGetInverse takes the requested pattern as the transpose (MATTRANSPOSEVIRTUAL)
/// of an AIJ matrix Bt, because MUMPS wants compressed columns and AIJ stores rows: row j of Bt
/// lists the rows i of column j of K⁻¹ wanted. MUMPS reads it on the host only and requires as
/// many right-hand sides as rows of K, so Bt is N×N. In parallel PETSc reads the diagonal
/// block of rank 0's part of the MPIAIJ, so rank 0 owns all N rows and all N columns of Bt and
/// the other ranks own none. MUMPS overwrites Bt's values with the entries of K⁻¹.
///
/// Only the entries within a block (`labels`, rank 0's block of each contact DOF) are asked
/// for: the others are zero (contact_blocks.h).
Eigen::MatrixXd selected_inverse(PetscErrorScope& err, MPI_Comm comm, int rank, Mat F,
                                 PetscInt N, const std::vector<PetscInt>& dofs,
                                 const std::vector<int>& labels)
{
  const int n_c = static_cast<int>(dofs.size());
  // Rows of an AIJ matrix are set with sorted columns; pos[k] is the place of sorted[k] in dofs.
  std::vector<int> pos(n_c);
  std::iota(pos.begin(), pos.end(), 0);
  std::sort(pos.begin(), pos.end(), [&dofs](int a, int b) { return dofs[a] < dofs[b]; });
  std::vector<PetscInt> sorted(n_c);
  for (int k = 0; k < n_c; ++k)
    sorted[k] = dofs[pos[k]];
  // Per block, its DOFs in sorted order (the columns of its rows of Bt) and their places.
  std::vector<std::vector<PetscInt>> block_cols;
  std::vector<std::vector<int>> block_pos;
  if (rank == 0)
  {
    const int n_blocks = n_c ? *std::max_element(labels.begin(), labels.end()) + 1 : 0;
    block_cols.resize(n_blocks);
    block_pos.resize(n_blocks);
    for (int k = 0; k < n_c; ++k)
    {
      block_cols[labels[pos[k]]].push_back(sorted[k]);
      block_pos[labels[pos[k]]].push_back(pos[k]);
    }
  }

  const PetscInt n_local = rank == 0 ? N : 0;
  OwnedMat Bt;
  err.check(MatCreate(comm, &Bt.m), "MatCreate");
  err.check(MatSetSizes(Bt.m, n_local, n_local, N, N), "MatSetSizes");
  err.check(MatSetType(Bt.m, MATAIJ), "MatSetType(aij)");
  std::vector<PetscInt> nnz(n_local, 0);
  if (rank == 0)
    for (int k = 0; k < n_c; ++k)
      nnz[sorted[k]] = static_cast<PetscInt>(block_cols[labels[pos[k]]].size());
  err.check(MatSeqAIJSetPreallocation(Bt.m, 0, nnz.data()), "MatSeqAIJSetPreallocation");
  err.check(MatMPIAIJSetPreallocation(Bt.m, 0, nnz.data(), 0, nullptr),
            "MatMPIAIJSetPreallocation");
  if (rank == 0)
  {
    // Non-zero placeholders: the pattern is what matters, and AIJ keeps it whatever the value.
    const std::vector<PetscScalar> ones(n_c, 1.0);
    for (int k = 0; k < n_c; ++k)
    {
      const std::vector<PetscInt>& cols = block_cols[labels[pos[k]]];
      err.check(MatSetValues(Bt.m, 1, &sorted[k], static_cast<PetscInt>(cols.size()),
                             cols.data(), ones.data(), INSERT_VALUES),
                "MatSetValues");
    }
  }
  err.check(MatAssemblyBegin(Bt.m, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
  err.check(MatAssemblyEnd(Bt.m, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
  OwnedMat spRHS;
  err.check(MatCreateTranspose(Bt.m, &spRHS.m), "MatCreateTranspose");

  // MatMumpsGetInverse leaves ICNTL(30) = 1 (and ICNTL(20) = 1, ICNTL(21) = 0) in the factor;
  // MatSolve resets only ICNTL(20), so a later MatSolve would compute inverse entries again
  // instead of solving, and in parallel would look for a distributed solution MUMPS no longer
  // produces. Restore what MatSolve relies on.
  PetscInt icntl20 = 0, icntl21 = 0;
  err.check(MatMumpsGetIcntl(F, 20, &icntl20), "MatMumpsGetIcntl(20)");
  err.check(MatMumpsGetIcntl(F, 21, &icntl21), "MatMumpsGetIcntl(21)");
  err.check(MatMumpsGetInverse(F, spRHS.m), "MatMumpsGetInverse");
  check_mumps(err, F, "selected-inverse solve");
  err.check(MatMumpsSetIcntl(F, 30, 0), "MatMumpsSetIcntl(30)");
  err.check(MatMumpsSetIcntl(F, 20, icntl20), "MatMumpsSetIcntl(20)");
  err.check(MatMumpsSetIcntl(F, 21, icntl21), "MatMumpsSetIcntl(21)");

  Eigen::MatrixXd Fs;
  std::string bad;
  if (rank == 0)
  {
    Fs.setZero(n_c, n_c);
    for (int k = 0; k < n_c and bad.empty(); ++k)
    {
      // Row sorted[k] of Bt is column dofs[pos[k]] of K⁻¹.
      PetscInt ncols = 0;
      const PetscInt* cols = nullptr;
      const PetscScalar* vals = nullptr;
      err.check(MatGetRow(Bt.m, sorted[k], &ncols, &cols, &vals), "MatGetRow");
      const std::vector<PetscInt>& want = block_cols[labels[pos[k]]];
      const std::vector<int>& place = block_pos[labels[pos[k]]];
      if (static_cast<std::size_t>(ncols) == want.size()
          and std::equal(cols, cols + ncols, want.begin()))
      {
        for (PetscInt l = 0; l < ncols; ++l)
          Fs(place[l], pos[k]) = vals[l];
      }
      else
      {
        bad = "MatMumpsGetInverse returned a pattern other than the requested one (row "
              + std::to_string(sorted[k]) + ")";
      }
      err.check(MatRestoreRow(Bt.m, sorted[k], &ncols, &cols, &vals), "MatRestoreRow");
    }
    Fs = 0.5 * (Fs + Fs.transpose()).eval();
  }
  throw_collective_if(comm, !bad.empty(), bad,
                      [](const std::string& w) { throw std::runtime_error(w); });
  return Fs;
}
} // namespace

Flexibility flexcontact::flexibility(Mat K, std::span<const std::int64_t> contact_dofs,
                                     const std::string& method, const std::string& ordering,
                                     bool per_body, bool factors)
{
  if (method != "schur" and method != "inverse_entries" and method != "matmatsolve")
    throw std::invalid_argument("unknown flexibility method '" + method
                                + "' (expected 'schur', 'inverse_entries' or 'matmatsolve')");
  if (!is_ordering(ordering))
    throw std::invalid_argument("unknown ordering '" + ordering
                                + "' (expected 'auto', 'metis', 'mumps', 'amd', 'amf', 'pord' or 'qamd')");
  if (!K)
    throw std::invalid_argument("the stiffness matrix is a null Mat");

  PetscErrorScope err;
  MPI_Comm comm = PetscObjectComm(reinterpret_cast<PetscObject>(K));
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);

  PetscInt M = 0, N = 0;
  err.check(MatGetSize(K, &M, &N), "MatGetSize");
  if (M != N)
    throw std::invalid_argument("the stiffness matrix is not square (" + std::to_string(M) + "x"
                                + std::to_string(N) + ")");

  // Contact DOFs: validated on rank 0, then known everywhere.
  std::vector<PetscInt> dofs;
  std::string bad;
  if (rank == 0)
  {
    dofs.assign(contact_dofs.begin(), contact_dofs.end());
    std::vector<PetscInt> sorted = dofs;
    std::sort(sorted.begin(), sorted.end());
    if (!sorted.empty() and (sorted.front() < 0 or sorted.back() >= M))
      bad = "contact DOF out of range [0, " + std::to_string(M) + "): "
            + std::to_string(sorted.front() < 0 ? sorted.front() : sorted.back());
    else if (auto it = std::adjacent_find(sorted.begin(), sorted.end()); it != sorted.end())
      bad = "contact DOF " + std::to_string(*it) + " is listed twice";
  }
  throw_collective_if(comm, !bad.empty(), bad,
                      [](const std::string& w) { throw std::invalid_argument(w); });
  int n_c = static_cast<int>(dofs.size());
  MPI_Bcast(&n_c, 1, MPI_INT, 0, comm);
  dofs.resize(n_c);
  MPI_Bcast(dofs.data(), n_c, MPIU_INT, 0, comm);

  // "schur" drives MUMPS directly (distributed_schur.h) on any number of ranks: PETSc cannot
  // solve with a Schur-enabled MUMPS factor in parallel, and in serial its own analysis would
  // be thrown away for the requested ordering (a second analysis).
  const bool direct = method == "schur" and n_c > 0;
  const std::string used = method;

  Flexibility out;
  out.method = used;
  // A given ordering is set by redoing MUMPS's analysis on rank 0's instance (ordering.h);
  // on several ranks through PETSc MUMPS's automatic choice stays.
  out.ordering = (size > 1 and !direct) ? "mumps"
                                        : resolve_ordering(ordering, K, used == "schur" and n_c > 0);
  out.ordering_auto = ordering == "auto";
  out.n_contact_dofs = n_c;
  err.check(MatSetOption(K, MAT_SYMMETRIC, PETSC_TRUE), "MatSetOption(MAT_SYMMETRIC)");

  double tb = MPI_Wtime();
  const std::vector<int> labels = per_body ? contact_blocks(K, dofs)
                                           : std::vector<int>(rank == 0 ? n_c : 0, 0);
  const std::vector<std::vector<int>> blocks = block_members(labels);
  out.blocks_s = MPI_Wtime() - tb;
  out.n_blocks = static_cast<int>(blocks.size());
  MPI_Bcast(&out.n_blocks, 1, MPI_INT, 0, comm);
  for (const auto& b : blocks)
    out.block_sizes.push_back(static_cast<int>(b.size()));

  if (direct)
  {
    Flexibility d = distributed_flexibility(K, dofs, out.ordering, blocks, factors);
    d.ordering_auto = out.ordering_auto;
    d.n_blocks = out.n_blocks;
    d.block_sizes = std::move(out.block_sizes);
    d.blocks_s = out.blocks_s;
    out = std::move(d);
  }
  else if (n_c == 0)
  {
    double t0 = MPI_Wtime();
    out.factor = factorize(err, K, nullptr, out.ordering, out);
    out.factorization_s = MPI_Wtime() - t0;
    out.factorizations = 1;
    out.F.resize(0, 0);
  }
  else
  {
    double t0 = MPI_Wtime();
    OwnedMat F;
    F.m = factorize(err, K, nullptr, out.ordering, out);
    out.factorization_s = MPI_Wtime() - t0;
    out.factorizations = 1;
    double t1 = MPI_Wtime();
    out.F = used == "inverse_entries" ? selected_inverse(err, comm, rank, F.m, M, dofs, labels)
                                      : multi_rhs_solve(err, comm, rank, K, F.m, dofs);
    out.schur_s = MPI_Wtime() - t1;
    out.factor = F.release();
  }

  double t[4] = {out.factorization_s, out.schur_s, out.inverse_s, out.blocks_s};
  MPI_Allreduce(MPI_IN_PLACE, t, 4, MPI_DOUBLE, MPI_MAX, comm);
  out.factorization_s = t[0];
  out.schur_s = t[1];
  out.inverse_s = t[2];
  out.blocks_s = t[3];
  return out;
}

Flexibility flexcontact::factor_analysis(Mat K, std::span<const std::int64_t> contact_dofs,
                                         const std::string& ordering)
{
  if (!is_ordering(ordering))
    throw std::invalid_argument("unknown ordering '" + ordering
                                + "' (expected 'auto', 'metis', 'mumps', 'amd', 'amf', 'pord' or 'qamd')");
  PetscErrorScope err;
  MPI_Comm comm = PetscObjectComm(reinterpret_cast<PetscObject>(K));
  int size = 1;
  MPI_Comm_size(comm, &size);
  if (size > 1)
    throw std::invalid_argument("factor_analysis runs on one process only");
  PetscInt N = 0;
  err.check(MatGetSize(K, &N, nullptr), "MatGetSize");
  std::vector<PetscInt> dofs(contact_dofs.begin(), contact_dofs.end());
  for (PetscInt d : dofs)
    if (d < 0 or d >= N)
      throw std::invalid_argument("contact DOF out of range [0, " + std::to_string(N)
                                  + "): " + std::to_string(d));
  err.check(MatSetOption(K, MAT_SYMMETRIC, PETSC_TRUE), "MatSetOption(MAT_SYMMETRIC)");
  Flexibility out;
  out.ordering = resolve_ordering(ordering, K, not dofs.empty());
  out.n_contact_dofs = static_cast<int>(dofs.size());
  double t0 = MPI_Wtime();
  OwnedMat F;
  F.m = factorize(err, K, dofs.empty() ? nullptr : &dofs, out.ordering, out, true);
  out.factorization_s = MPI_Wtime() - t0;
  return out;
}

void flexcontact::throw_mumps_error(const char* phase, int infog1, int infog2)
{
  std::string what = std::string("MUMPS failed in the ") + phase + ": INFOG(1)="
                     + std::to_string(infog1) + ", INFOG(2)=" + std::to_string(infog2);
  if (infog1 == -10)
    what += " (numerically singular matrix)";
  else if (infog1 == -9 or infog1 == -8 or infog1 == -13 or infog1 == -19)
    what += " (not enough memory)";
  throw MumpsError(what + "; see the MUMPS users' guide, 'Error diagnostics'", infog1);
}

void flexcontact::throw_if_null_pivots(int n)
{
  if (n > 0)
    throw SingularStiffnessError(
        "stiffness matrix is singular: " + std::to_string(n)
        + " null pivots (a body has rigid-body modes: it is not held by Dirichlet conditions "
          "or by springs)");
}
