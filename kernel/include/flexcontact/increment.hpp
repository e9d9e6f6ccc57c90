// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file increment.hpp
/// @brief The incremental driver (seed eqs. 12–18): one local problem per load increment or
/// time step, friction path dependent through the previous tangential gap.

#include "flexcontact/problem.hpp"
#include "flexcontact/problem_file.hpp"
#include <memory>
#include <stdexcept>

namespace flexcontact
{
/// @brief Holds W, μ and the history (gap x, force λ, states) between increments.
///
/// The caller gives for each increment the total q = B u_p + x0 (u_p = K⁻¹ p of the total
/// load). The gap is x = W λ + q; the tangential slip of the increment is x_t − x_t,prev, so
/// the local problem solved is u = W λ + (q − P_t x_prev), with P_t keeping tangential rows.
class IncrementalSolver
{
public:
  /// @throws std::invalid_argument on sizes that disagree, μ < 0 or non-finite, W not finite
  IncrementalSolver(int dim, Matrix W, Vector mu, SolverOptions options = {});

  /// @brief Solve one increment; starts from the last increment's λ and states.
  /// @throws std::invalid_argument if q has the wrong size or is not finite
  /// @throws ConvergenceError if no solver of the chain converges (history left unchanged)
  const SolveReport& step(const Eigen::Ref<const Vector>& q_total);

  /// @brief The bordered increment of bodies held only by contact: the gap is
  /// x = W λ + q + G α and the bodies' equilibrium Gᵀ λ = e holds (e = −Rᵀ p of the total
  /// load). α is the rigid-mode amplitude (total, not incremental).
  /// @throws std::invalid_argument if no border is set or e has the wrong size
  const SolveReport& step(const Eigen::Ref<const Vector>& q_total,
                          const Eigen::Ref<const Vector>& e);

  /// @brief Set the border G = B R_c (m·d × k; k = 0 removes it); α restarts at zero.
  /// @throws std::invalid_argument on a wrong row count or non-finite entries
  void set_border(Matrix G);

  /// @brief Gap before the first increment (default 0): the tangential slip of the first
  /// increment is measured from it, so an initial tangential offset is not taken as slip.
  /// @throws std::invalid_argument on a wrong size or non-finite values
  void set_initial_gap(const Eigen::Ref<const Vector>& x0);

  /// @brief Replace W (same size), e.g. after a change of time step; the history (gap, λ,
  /// states) is kept and warm-starts the next increment.
  /// @throws std::invalid_argument on a wrong size or non-finite entries
  void set_delassus(Matrix W);

  /// @brief The λ and states the next increment starts from (a warm start only: the
  /// solution depends on the gap history, not on them), e.g. carried over to new pairs.
  /// @throws std::invalid_argument on wrong sizes or non-finite λ
  void set_warm_start(Vector lambda, std::vector<PairState> states);

  /// @brief A crushable interface (problem.hpp, docs/crushing.md): the cap c_k > 0 of each
  /// pair's normal force (+∞: none) and its crush depth δ_k ≥ 0 so far [m], the depth by
  /// which the pair's surface has crushed along its normal. The local problem's normal gap
  /// is x_n + δ; a pair that ends an increment at its cap deepens δ to −x_n. Empty vectors
  /// remove the cap (δ is then not used).
  /// @throws std::invalid_argument on wrong sizes, a cap ≤ 0 or NaN, a δ < 0 or not finite
  void set_crushing(Vector cap, Vector crush_depth);

  /// @brief q' of the local problem u = W λ + q' that step(q_total) solves next: q_total
  /// with the last increment's tangential gap removed and the crush depths added to the
  /// normal gaps (sizes as for step()).
  Vector local_q(const Eigen::Ref<const Vector>& q_total) const;

  const Vector& gap() const { return x_; }          ///< total gap x of the last increment
  const Vector& force() const { return lambda_; }   ///< λ of the last increment
  const Vector& alpha() const { return alpha_; }    ///< rigid-mode amplitudes (bordered)
  const Vector& cap() const { return cap_; }        ///< normal force caps (empty: none)
  const Vector& crush_depth() const { return crush_; } ///< δ per pair after the last increment
  /// Σ_k c_k (δ_k − δ_k,prev): the work the crushing forces did in the last increment [J,
  /// J/m in 2D], the energy it dissipated
  double crush_work() const { return crush_work_; }
  const Matrix& border() const { return G_; }       ///< G, m·d × k (k = 0: none)
  const std::vector<PairState>& states() const { return states_; }
  const SolveReport& last() const { return last_; }
  int dim() const { return dim_; }
  int pairs() const { return static_cast<int>(mu_.size()); }
  const Matrix& W() const { return W_; }

private:
  int dim_;
  Matrix W_;
  Vector mu_;
  SolverOptions options_;
  Vector x_, lambda_;
  Matrix G_;
  Vector alpha_;
  Vector cap_, crush_;
  double crush_work_ = 0.0;
  std::vector<PairState> states_;
  SolveReport last_;
};

/// @brief Thrown when no local solver converged; what() names solvers, iterations, residual.
/// `problem`, where the failure was one call of solve(), is what that call was given: the
/// bindings save it as a file a user can send (problem_file.hpp).
class ConvergenceError : public std::runtime_error
{
public:
  ConvergenceError(const std::string& what, SolveReport report,
                   std::shared_ptr<const LocalProblem> problem = nullptr)
      : std::runtime_error(what), report(std::move(report)), problem(std::move(problem))
  {
  }
  SolveReport report;
  std::shared_ptr<const LocalProblem> problem;
};
} // namespace flexcontact
