// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file operator_contact.hpp
/// @brief The condensed contact problem without a dense W (docs/architecture.md §1): W is
/// only applied, W x = B F*(Bᵀ x), F* through a caller-given operator (a back-substitution
/// with the stored factor of K), and the local problem is solved by an iteration that only
/// needs W·x. Memory is O(m·d + n_c) instead of O(n_c² + (m·d)²).

#include "flexcontact/condensed.hpp"
#include "flexcontact/increment.hpp"
#include "flexcontact/pairs.hpp"
#include "flexcontact/problem.hpp"

#include <Eigen/Sparse>
#include <functional>
#include <vector>

namespace flexcontact
{
/// @brief y = A x for a symmetric positive semi-definite A.
using LinearOperator = std::function<Vector(const Vector&)>;

/// @brief Scales of a matrix-free local problem: a step from ‖W‖ and the natural-map ρ.
struct OperatorScales
{
  double lipschitz = 0.0;   ///< upper estimate of λ_max(W) (power iteration, +5 %)
  double mean_normal = 0.0; ///< estimate of the mean normal diagonal entry W_nn,k
  int applications = 0;     ///< W·x products spent on the estimates
};

/// @brief ‖W‖ by 30 power iterations from a fixed start, and the mean normal diagonal entry
/// by Hutchinson's estimator restricted to the normal rows (8 Rademacher probes from a fixed
/// seed): deterministic, so that every rank of a parallel run gets the same numbers.
OperatorScales operator_scales(const LinearOperator& W, int dim, int pairs);

/// @brief Accelerated projected fixed point on the De Saxcé cone map (APGD with gradient
/// restarts): λ ← P_K(y − (u(y) + μ|u_t(y)| e_n)/L), y the Nesterov extrapolation, restarted
/// when a step turns back. One W·x per iteration (u is kept up to date by linearity).
/// Converged when the natural-map residual (residual.hpp) with the uniform ρ = 1/mean W_nn
/// is below opt.tolerance; at most 100 × opt.max_iterations iterations. Returns the best
/// iterate's report (converged=false if none met the tolerance); never throws on
/// non-convergence.
SolveReport solve_operator(int dim, const LinearOperator& W, const OperatorScales& scales,
                           const Eigen::Ref<const Vector>& q, const Eigen::Ref<const Vector>& mu,
                           const Eigen::Ref<const Vector>& lambda0, const SolverOptions& opt);

/// @brief Pairs, B, x0 and the incremental driver of CondensedContact, with F* an operator.
///
/// The same increment as CondensedContact::step (slip measured from the last increment's
/// tangential gap, λ and states carried over as warm start, r_c = Bᵀ λ zero on constrained
/// DOFs), solved by solve_operator. No W, no F* is ever formed.
class OperatorContact
{
public:
  /// @param flexibility r_c ↦ F* r_c on the n_c contact DOFs (n_c = X.rows()·dim)
  /// @throws std::invalid_argument as CondensedContact's constructor
  OperatorContact(int dim, LinearOperator flexibility, Matrix X, std::vector<ContactPair> pairs,
                  Vector mu, std::vector<bool> constrained = {}, SolverOptions options = {});

  /// @brief One increment from the contact-DOF values of u_p = K⁻¹ p (total load).
  /// @throws std::invalid_argument if up_c has the wrong size or is not finite
  /// @throws ConvergenceError if the iteration does not converge (history unchanged)
  CondensedStep step(const Eigen::Ref<const Vector>& up_c);

  /// @brief New pairs (re-pairing): B, x0 and the scales rebuilt; slip measured from the new
  /// pairs' gap at the last contact displacement u_c = u_p,c + F* r_c (one F* product); λ
  /// and states of slave nodes that keep a pair carried over.
  void set_pairs(std::vector<ContactPair> pairs, Vector mu);

  /// @brief W x = B F*(Bᵀ x), constrained contact DOFs neither loaded nor moving.
  Vector apply_W(const Vector& x) const;

  const Eigen::SparseMatrix<double>& B() const { return B_; } ///< m·d × n_c
  const Vector& x0() const { return x0_; }
  const Vector& mu() const { return mu_; }
  const std::vector<ContactPair>& contact_pairs() const { return pairs_; }
  const OperatorScales& scales() const { return scales_; }
  /// @brief F* products since construction (each one back-substitution for the caller).
  long applications() const { return applications_; }
  int dim() const { return dim_; }
  int pairs() const { return static_cast<int>(pairs_.size()); }
  int contact_dofs() const { return static_cast<int>(X_.rows()) * dim_; }

private:
  Vector flex(Vector r) const;

  int dim_;
  LinearOperator F_;
  Matrix X_;
  std::vector<ContactPair> pairs_;
  Vector mu_;
  std::vector<bool> constrained_;
  SolverOptions options_;
  Eigen::SparseMatrix<double> B_;
  Vector x0_;
  OperatorScales scales_;
  Vector x_, lambda_;              ///< total gap and λ of the last increment
  std::vector<PairState> states_;
  Vector up_c_, reaction_;         ///< of the last increment, for u_c at re-pairing
  mutable long applications_ = 0;
};
} // namespace flexcontact
