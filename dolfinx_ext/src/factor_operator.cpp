// Copyright flexcontact developers. MIT licence.

/// @file factor_operator.cpp
/// @brief F* applied through the factor of K: scatter r_c into K's layout, MatSolve, gather
/// the contact values on every rank.

#include "factor_operator.h"
#include "petsc_error.h"

#include <petscis.h>
#include <stdexcept>
#include <string>

using namespace flexcontact;

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
