// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file factor_operator.h
/// @brief F* r_c = (K⁻¹ r)_c applied through the stored factor of K: one back-substitution
/// per product, F* never formed (kernel/.../operator_contact.hpp).

#include <Eigen/Dense>
#include <petscmat.h>
#include <petscvec.h>
#include <vector>

namespace flexcontact
{
/// @brief The flexibility on the contact DOFs as an operator, replicated on every rank.
///
/// Collective: every rank calls it with the same r_c (replicated) and gets the same F* r_c,
/// so that a deterministic iteration built on it runs identically on all ranks. Contact DOFs
/// beyond the real ones (rigid targets' reference nodes, `n_virtual`) have no PETSc DOF:
/// they get zero flexibility.
class FactorFlexibility
{
public:
  /// @param factor factored K (MatSolve); a reference is kept
  /// @param K the stiffness, for its vector layout
  /// @param dofs global indices of the real contact DOFs, the same list on every rank
  /// @param n_virtual trailing contact DOFs with no PETSc DOF
  FactorFlexibility(Mat factor, Mat K, std::vector<PetscInt> dofs, int n_virtual);
  ~FactorFlexibility();
  FactorFlexibility(const FactorFlexibility&) = delete;
  FactorFlexibility& operator=(const FactorFlexibility&) = delete;

  /// @brief F* r (n_c = dofs + n_virtual values in, the same out). Collective.
  Eigen::VectorXd operator()(const Eigen::VectorXd& r) const;

  /// @brief F* R for the columns of R (n_c × k) by multi-right-hand-side solves (MUMPS
  /// solves many columns for little more than one), in chunks of columns_per_solve().
  /// Collective; throws on every rank if the ranks ask for different k.
  Eigen::MatrixXd block(const Eigen::MatrixXd& R) const;

  /// @brief Throws on every rank if the ranks passed different values (collective).
  void same_on_all_ranks(long value) const;

  /// @brief Columns per MatMatSolve: its dense right-hand side and solution hold N values per
  /// column (N = K's size), kept to about 32 MB together, at most 128 columns.
  int columns_per_solve() const;

  int contact_dofs() const { return static_cast<int>(dofs_.size()) + n_virtual_; }

private:
  Mat factor_ = nullptr;
  Vec b_ = nullptr, x_ = nullptr, seq_ = nullptr;
  VecScatter gather_ = nullptr;
  std::vector<PetscInt> dofs_;
  int n_virtual_ = 0;
  PetscInt lo_ = 0, hi_ = 0, N_ = 0;
  MPI_Comm comm_ = MPI_COMM_NULL;
};
} // namespace flexcontact
