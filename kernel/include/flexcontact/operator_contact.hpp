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

/// @brief Y = A X for the columns of X at once (for F*: one multi-right-hand-side
/// back-substitution, much cheaper per column than as many single solves).
using BlockOperator = std::function<Matrix(const Matrix&)>;

/// @brief Columns of W for some pairs, kept across increments: W[:, pair k] is the m·d × d
/// block `slot[k]` of `columns`.
struct PairColumns
{
  Matrix columns;         ///< m·d × (d · cached pairs)
  std::vector<int> slot;  ///< per pair: its block in `columns`, or -1
  std::vector<int> order; ///< the cached pairs, in block order
};

/// @brief Makes W's columns of `pairs` available in the PairColumns it was given; false if
/// they would pass the memory allowed (nothing fetched then).
using FetchColumns = std::function<bool(const std::vector<int>& pairs)>;

/// @brief Checks that every rank running the same iteration reached the same value, and
/// throws on every rank if not (collective); empty in serial.
using SameOnAllRanks = std::function<void(long value)>;

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
/// non-convergence. `cap`: the pairs' normal force caps of a crushable interface (empty:
/// none; problem.hpp), K then the truncated cone.
SolveReport solve_operator(int dim, const LinearOperator& W, const OperatorScales& scales,
                           const Eigen::Ref<const Vector>& q, const Eigen::Ref<const Vector>& mu,
                           const Eigen::Ref<const Vector>& lambda0, const SolverOptions& opt,
                           const Vector& cap = Vector());

/// @brief The local problem on a working set of pairs, W never formed beyond the set's
/// columns: start from the pairs that penetrate under q (q_n < 0) or carried a force in λ0;
/// solve the problem restricted to the set with the dense solver chain (solvers.hpp: solve,
/// on W_AA, from λ0 and states0); from W[:, A] λ_A + q find the pairs outside the set that
/// penetrate, add them and repeat. When none does, λ (zero outside the set) solves the whole
/// problem: outside the set λ = 0 with u_n ≥ 0 is exactly the De Saxcé map's fixed point, so
/// the whole natural-map residual (any ρ outside the set) is at most the restricted one,
/// which is reported. Each round fetches only the new pairs' columns (one block product).
/// Returns converged=false (its last λ, and a line in `attempts`) if the set passes the
/// memory `fetch` allows, the chain fails, or 50 rounds pass; never throws on that. After
/// each round `same` (if given) checks that every rank took the same branch with the same
/// set: the chain has a wall-clock budget, and ranks must not part ways in collective solves.
/// `cap` as for solve_operator: the restricted problems keep their pairs' caps.
SolveReport solve_working_set(int dim, const PairColumns& columns, const FetchColumns& fetch,
                              const Eigen::Ref<const Vector>& q,
                              const Eigen::Ref<const Vector>& mu,
                              const Eigen::Ref<const Vector>& lambda0,
                              const std::vector<PairState>& states0, const SolverOptions& opt,
                              const SameOnAllRanks& same = {}, const Vector& cap = Vector());

/// @brief Pairs, B, x0 and the incremental driver of CondensedContact, with F* an operator.
///
/// The same increment as CondensedContact::step (slip measured from the last increment's
/// tangential gap, λ and states carried over as warm start, r_c = Bᵀ λ zero on constrained
/// DOFs). With a block operator (use_working_set) it is solved by solve_working_set on the
/// columns of W of the pairs that come into contact, computed by blocks of right-hand sides
/// and kept across increments (until the pairs change) within a memory cap; otherwise, or
/// when that fails, by solve_operator from its best λ. F* is never formed; W only in the
/// columns of the working set.
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
  /// and states of slave nodes that keep a pair carried over. `cap`: the new pairs' caps of
  /// a crushable interface (empty: none); the crush depth is the slave node's.
  void set_pairs(std::vector<ContactPair> pairs, Vector mu, Vector cap = Vector());

  /// @brief Caps of the pairs' normal forces (docs/crushing.md; as CondensedContact's).
  /// @throws std::invalid_argument on a wrong size or a cap ≤ 0 or NaN
  void set_crushing(Vector cap);

  /// @brief δ of every contact node [m].
  const Vector& node_crush_depth() const { return crush_node_; }

  /// @brief W x = B F*(Bᵀ x), constrained contact DOFs neither loaded nor moving.
  Vector apply_W(const Vector& x) const;

  /// @brief Solve increments on a working set of W's columns (solve_working_set), computed
  /// through `block` (F* on many columns at once) and held within `max_bytes` (8 bytes per
  /// entry of the m·d × d·pairs columns); max_bytes ≤ 0 turns it off.
  void use_working_set(BlockOperator block, double max_bytes, SameOnAllRanks same = {});

  /// @brief W[:, pairs] (m·d × d·|pairs|) through one block product (constrained DOFs as in
  /// apply_W).
  Matrix W_columns(const std::vector<int>& pairs) const;

  const Eigen::SparseMatrix<double>& B() const { return B_; } ///< m·d × n_c
  const Vector& x0() const { return x0_; }
  const Vector& mu() const { return mu_; }
  const std::vector<ContactPair>& contact_pairs() const { return pairs_; }
  /// @brief The step and ρ estimates of solve_operator, computed when it first runs for the
  /// current pairs (zero until then).
  const OperatorScales& scales() const { return scales_; }
  /// @brief F* products since construction (each one back-substitution for the caller).
  long applications() const { return applications_; }
  /// @brief Columns F* was applied to in block products, and the block products, since
  /// construction.
  long block_columns() const { return block_columns_; }
  long block_products() const { return block_products_; }
  /// @brief Pairs whose columns of W are held now.
  int cached_pairs() const { return static_cast<int>(columns_.order.size()); }
  int dim() const { return dim_; }
  int pairs() const { return static_cast<int>(pairs_.size()); }
  int contact_dofs() const { return static_cast<int>(X_.rows()) * dim_; }

private:
  Vector flex(Vector r) const;
  bool fetch_columns(const std::vector<int>& pairs);
  SolveReport solve_local(const Vector& q);
  /// @brief δ of pair k's slave node.
  double crush_of(int k) const;

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
  Vector cap_;                     ///< per pair, empty: no crushing
  Vector crush_node_;              ///< δ per contact node
  mutable long applications_ = 0;
  BlockOperator block_;
  double max_bytes_ = 0.0;
  SameOnAllRanks same_;
  PairColumns columns_;
  mutable long block_columns_ = 0, block_products_ = 0;
};
} // namespace flexcontact
