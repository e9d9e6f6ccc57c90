// Copyright flexcontact developers. MIT licence.

/// @file factor_operator.cpp
/// @brief F* applied through the factor of K: scatter r_c into K's layout, MatSolve, gather
/// the contact values on every rank.

#include "factor_operator.h"
#include "petsc_error.h"

#include <petscis.h>
#include <algorithm>
#include <stdexcept>
#include <string>

using namespace flexcontact;

namespace
{
/// @brief A Mat destroyed with its scope (also when a PETSc call throws).
struct ScopedMat
{
  Mat m = nullptr;
  ScopedMat() = default;
  ScopedMat(const ScopedMat&) = delete;
  ScopedMat& operator=(const ScopedMat&) = delete;
  ~ScopedMat()
  {
    if (m)
      MatDestroy(&m);
  }
};
} // namespace

FactorFlexibility::FactorFlexibility(Mat factor, Mat K, std::vector<PetscInt> dofs,
                                     int n_virtual)
    : dofs_(std::move(dofs)), n_virtual_(n_virtual)
{
  if (!factor or !K)
    throw std::invalid_argument("FactorFlexibility: the factor or K is a null Mat");
  if (n_virtual < 0)
    throw std::invalid_argument("FactorFlexibility: n_virtual is " + std::to_string(n_virtual));
  PetscErrorScope err;
  PetscInt N = 0;
  err.check(MatGetSize(K, &N, nullptr), "MatGetSize");
  N_ = N;
  comm_ = PetscObjectComm(reinterpret_cast<PetscObject>(K));
  for (PetscInt d : dofs_)
    if (d < 0 or d >= N)
      throw std::invalid_argument("FactorFlexibility: contact DOF " + std::to_string(d)
                                  + " out of range [0, " + std::to_string(N) + ")");
  err.check(PetscObjectReference(reinterpret_cast<PetscObject>(factor)), "PetscObjectReference");
  factor_ = factor;
  err.check(MatCreateVecs(K, &x_, &b_), "MatCreateVecs");
  err.check(VecGetOwnershipRange(b_, &lo_, &hi_), "VecGetOwnershipRange");
  const PetscInt n = static_cast<PetscInt>(dofs_.size());
  err.check(VecCreateSeq(PETSC_COMM_SELF, n, &seq_), "VecCreateSeq");
  // Every rank gathers all contact values: the iteration runs replicated.
  IS from = nullptr, to = nullptr;
  err.check(ISCreateGeneral(PETSC_COMM_SELF, n, dofs_.data(), PETSC_COPY_VALUES, &from),
            "ISCreateGeneral");
  err.check(ISCreateStride(PETSC_COMM_SELF, n, 0, 1, &to), "ISCreateStride");
  const PetscErrorCode ierr = VecScatterCreate(x_, from, seq_, to, &gather_);
  ISDestroy(&from);
  ISDestroy(&to);
  err.check(ierr, "VecScatterCreate");
}

FactorFlexibility::~FactorFlexibility()
{
  VecScatterDestroy(&gather_);
  VecDestroy(&seq_);
  VecDestroy(&b_);
  VecDestroy(&x_);
  MatDestroy(&factor_);
}

Eigen::VectorXd FactorFlexibility::operator()(const Eigen::VectorXd& r) const
{
  if (r.size() != contact_dofs())
    throw std::invalid_argument("FactorFlexibility: r has " + std::to_string(r.size())
                                + " entries, expected " + std::to_string(contact_dofs()));
  PetscErrorScope err;
  PetscScalar* b = nullptr;
  err.check(VecGetArray(b_, &b), "VecGetArray");
  std::fill(b, b + (hi_ - lo_), 0.0);
  for (std::size_t i = 0; i < dofs_.size(); ++i)
    if (dofs_[i] >= lo_ and dofs_[i] < hi_)
      b[dofs_[i] - lo_] += r[static_cast<Eigen::Index>(i)];
  err.check(VecRestoreArray(b_, &b), "VecRestoreArray");
  err.check(MatSolve(factor_, b_, x_), "MatSolve");
  err.check(VecScatterBegin(gather_, x_, seq_, INSERT_VALUES, SCATTER_FORWARD),
            "VecScatterBegin");
  err.check(VecScatterEnd(gather_, x_, seq_, INSERT_VALUES, SCATTER_FORWARD), "VecScatterEnd");
  Eigen::VectorXd out = Eigen::VectorXd::Zero(r.size());
  const PetscScalar* s = nullptr;
  err.check(VecGetArrayRead(seq_, &s), "VecGetArrayRead");
  for (std::size_t i = 0; i < dofs_.size(); ++i)
    out[static_cast<Eigen::Index>(i)] = s[i];
  err.check(VecRestoreArrayRead(seq_, &s), "VecRestoreArrayRead");
  return out;
}

void FactorFlexibility::same_on_all_ranks(long value) const
{
  long lo = 0, hi = 0;
  MPI_Allreduce(&value, &lo, 1, MPI_LONG, MPI_MIN, comm_);
  MPI_Allreduce(&value, &hi, 1, MPI_LONG, MPI_MAX, comm_);
  if (lo != hi)
    throw std::runtime_error("FactorFlexibility: the ranks' working sets diverged ("
                             + std::to_string(lo) + " against " + std::to_string(hi)
                             + "): the replicated contact solve is no longer the same");
}

int FactorFlexibility::columns_per_solve() const
{
  // Small against the dense path's n_c² so as not to move the memory crossover; past a few
  // dozen columns a block solve gains little more per column.
  const double bytes = 32e6, per_column = 2.0 * 8.0 * static_cast<double>(std::max<PetscInt>(N_, 1));
  return static_cast<int>(std::clamp(bytes / per_column, 1.0, 128.0));
}

Eigen::MatrixXd FactorFlexibility::block(const Eigen::MatrixXd& R) const
{
  if (R.rows() != contact_dofs())
    throw std::invalid_argument("FactorFlexibility: R has " + std::to_string(R.rows())
                                + " rows, expected " + std::to_string(contact_dofs()));
  // A rank that asked for other columns would wait in another MatMatSolve: fail everywhere.
  long long k_all = R.cols(), lo = 0, hi = 0;
  MPI_Allreduce(&k_all, &lo, 1, MPI_LONG_LONG, MPI_MIN, comm_);
  MPI_Allreduce(&k_all, &hi, 1, MPI_LONG_LONG, MPI_MAX, comm_);
  if (lo != hi)
    throw std::runtime_error("FactorFlexibility: the ranks asked for " + std::to_string(lo)
                             + " to " + std::to_string(hi) + " columns: the replicated "
                             "iteration diverged between ranks");
  const Eigen::Index n = static_cast<Eigen::Index>(dofs_.size());
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(R.rows(), R.cols());
  PetscErrorScope err;
  const Eigen::Index chunk = columns_per_solve();
  for (Eigen::Index c0 = 0; c0 < R.cols(); c0 += chunk)
  {
    const PetscInt k = static_cast<PetscInt>(std::min(chunk, R.cols() - c0));
    ScopedMat Es, Xs;
    err.check(MatCreateDense(comm_, hi_ - lo_, PETSC_DECIDE, N_, k, nullptr, &Es.m),
              "MatCreateDense");
    err.check(MatCreateDense(comm_, hi_ - lo_, PETSC_DECIDE, N_, k, nullptr, &Xs.m),
              "MatCreateDense");
    Mat E = Es.m, X = Xs.m;
    PetscInt lda = 0;
    PetscScalar* e = nullptr;
    err.check(MatDenseGetLDA(E, &lda), "MatDenseGetLDA");
    err.check(MatDenseGetArray(E, &e), "MatDenseGetArray");
    for (PetscInt j = 0; j < k; ++j)
      std::fill(e + j * lda, e + j * lda + (hi_ - lo_), 0.0);
    for (Eigen::Index i = 0; i < n; ++i)
      if (dofs_[i] >= lo_ and dofs_[i] < hi_)
        for (PetscInt j = 0; j < k; ++j)
          e[(dofs_[i] - lo_) + j * lda] += R(i, c0 + j);
    err.check(MatDenseRestoreArray(E, &e), "MatDenseRestoreArray");
    for (Mat A : {E, X})
    {
      err.check(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
      err.check(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
    }
    err.check(MatMatSolve(factor_, E, X), "MatMatSolve");
    // Each contact DOF is owned by one rank: summing the owned rows replicates them exactly.
    Eigen::MatrixXd part = Eigen::MatrixXd::Zero(n, k);
    const PetscScalar* x = nullptr;
    err.check(MatDenseGetLDA(X, &lda), "MatDenseGetLDA");
    err.check(MatDenseGetArrayRead(X, &x), "MatDenseGetArrayRead");
    for (Eigen::Index i = 0; i < n; ++i)
      if (dofs_[i] >= lo_ and dofs_[i] < hi_)
        for (PetscInt j = 0; j < k; ++j)
          part(i, j) = x[(dofs_[i] - lo_) + j * lda];
    err.check(MatDenseRestoreArrayRead(X, &x), "MatDenseRestoreArrayRead");
    MPI_Allreduce(MPI_IN_PLACE, part.data(), static_cast<int>(part.size()), MPI_DOUBLE, MPI_SUM,
                  comm_);
    out.block(0, c0, n, k) = part;
  }
  return out;
}
