// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file schur_solve.h
/// @brief A solve with the serial MUMPS factor that holds a Schur complement on the contact
/// DOFs, split into its two halves (MUMPS's ICNTL(26)).
///
/// A full solve x = K⁻¹ b with such a factor is: MUMPS's condensation (forward elimination,
/// giving the reduced right-hand side b̃_c = b_c − K_ci K_ii⁻¹ b_i), a dense solve with the
/// Schur complement K*_cc, and MUMPS's expansion (backward substitution from the contact
/// values). A contact increment needs u_p,c = F* b̃_c and, after the contact solve, the full
/// u = K⁻¹ (p + Bᵀ λ), whose right-hand side differs from p only on the contact DOFs: one
/// condensation of p and one expansion from u_c = u_p,c + F* r_c give it, so an increment
/// costs one back-substitution instead of two (the interior's forward elimination does not
/// see the contact DOFs' entries).
///
/// PETSc has no interface to the two halves; they are run on MUMPS's own structure inside
/// PETSc's factor, which is checked against PETSc's public queries and the Schur DOFs before
/// use (as ordering.h does), so that a PETSc laying it out otherwise is a MumpsLayoutError at
/// construction and the caller keeps plain solves.

#include <petscmat.h>
#include <span>
#include <vector>

namespace flexcontact
{
/// @brief The serial MUMPS Schur factor F of K with condense/expand; owns one reference to F.
class SchurSolve
{
public:
  /// @param F factored MUMPS Cholesky of K (one process) with a Schur complement on `dofs`
  /// @param dofs the Schur (contact) DOFs in the order given to MatFactorSetSchurIS
  /// @throws MumpsLayoutError if F's MUMPS structure is not as expected (F unchanged)
  SchurSolve(Mat F, std::span<const PetscInt> dofs);
  ~SchurSolve();
  SchurSolve(const SchurSolve&) = delete;
  SchurSolve& operator=(const SchurSolve&) = delete;

  /// @brief The factor (borrowed; null after destroy()).
  Mat mat() const { return F_; }
  /// @brief Number of contact DOFs n_c.
  int size() const { return static_cast<int>(n_c_); }

  /// @brief x = K⁻¹ b by PETSc (its own condensation, Schur solve and expansion).
  void solve(Vec b, Vec x);

  /// @brief MUMPS's condensation of b: returns b̃_c (order of `dofs`); MUMPS keeps the
  /// interior's forward elimination for the next expand().
  std::vector<double> condense(Vec b);

  /// @brief MUMPS's expansion: x = the solution of K x = b (b of the last condense) whose
  /// contact values are u_c. Once per condense.
  /// @throws std::logic_error without a condense() since the last solve or expand
  void expand(std::span<const double> u_c, Vec x);

  /// @brief Drop the reference to F (later calls throw).
  void destroy();

private:
  /// @brief One MUMPS solve phase (job 3) with ICNTL(26) = `phase` on rhs_ and redrhs_.
  void run_phase(int phase);

  Mat F_ = nullptr;
  PetscInt N_ = 0;
  PetscInt n_c_ = 0;
  std::vector<PetscInt> dofs_; ///< the Schur DOFs, as MUMPS's list must hold them
  std::vector<double> rhs_;    ///< MUMPS's RHS: b in, x out; kept between the two halves
  std::vector<double> redrhs_; ///< REDRHS: b̃_c out of condense, u_c into expand
  bool condensed_ = false;
};
} // namespace flexcontact
