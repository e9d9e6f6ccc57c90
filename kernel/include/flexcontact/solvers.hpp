// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file solvers.hpp
/// @brief The local contact solvers behind one interface, and the dispatcher with fallback.
///
/// Every solver takes the problem, a starting λ (may be empty: zero start) and options, and
/// returns a SolveReport with its residual computed by natural_map_residual(), never by
/// trusting its own stopping test. A solver that does not converge returns converged=false;
/// it does not throw.

#include "flexcontact/problem.hpp"

namespace flexcontact
{
/// @brief Feng–Touzot active-set method (the seed's eqs. 12–18): stick/slip/open rows, 2D slip
/// direction ±t, 3D slip direction from the previous iterate (the seed's explicit method).
/// Switching: a stick pair outside the Coulomb cone goes to slip before a pulled one goes to
/// open (the seed opens it at once, which cycles on strongly coupled pairs); slip → stick
/// when the slip reverses, slip → open on λ_n < 0, open → stick on u_n < 0. 3D directions
/// use the projection weighting μλ_n s + ρ u_t (relaxed when they oscillate).
/// Cycle detection: a revisited state vector stops it with cycled=true. With capped normal
/// forces (problem.hpp) a fourth state, crush: λ_n at the cap, sticking or sliding
/// tangentially; a closed pair passing its cap crushes, a crushing pair whose gap opens
/// unloads (docs/crushing.md).
/// @param states0 starting states per pair (empty: all stick)
SolveReport solve_active_set(const ProblemView& p, const Eigen::Ref<const Vector>& lambda0,
                             const std::vector<PairState>& states0, const SolverOptions& opt);

/// @brief The seed's projection method: De Saxcé–Feng bi-potential fixed point,
/// λ_k ← P_K(λ_k − ρ_k (u_k + μ|u_t,k| n)), as a Gauss–Seidel sweep over pairs.
SolveReport solve_projection(const ProblemView& p, const Eigen::Ref<const Vector>& lambda0,
                             const SolverOptions& opt);

/// @brief Semi-smooth (generalised) Newton on the Alart–Curnier augmented Lagrangian
/// formulation, with a non-monotone line search on the merit ½‖Φ‖² of the Alart–Curnier
/// function Φ and Gauss–Seidel restarts when it stalls; it stops on the natural-map residual.
SolveReport solve_newton_ac(const ProblemView& p, const Eigen::Ref<const Vector>& lambda0,
                            const SolverOptions& opt);

/// @brief Semi-smooth Newton on the bordered problem of bodies held only by contact:
/// u = W λ + q + G α with the Alart–Curnier conditions on (λ, u) and the bodies' equilibrium
/// Gᵀ λ = e (G = B R_c, R the rigid modes; e = −Rᵀ p). The Jacobian is
/// [[(I − D) + D ρ W, D ρ G], [Gᵀ, 0]] on the closed pairs and α; it is solved by a
/// complete orthogonal decomposition, so a direction of α that no closed pair resists
/// (a frictionless block's slide) gets no step, and is reported in `undetermined` with α
/// zero along it. With no closed pair at the start (λ0 zero), the all-stick system
/// [[W, G], [Gᵀ, 0]] [λ; α] = [−q; e] gives the start. The residual is the larger of the
/// natural-map residual at q + G α and ‖Gᵀλ − e‖ / max(‖e‖, ‖|G|ᵀ|λ|‖).
SolveReport solve_newton_bordered(const ProblemView& p, const Eigen::Ref<const Matrix>& G,
                                  const Eigen::Ref<const Vector>& e,
                                  const Eigen::Ref<const Vector>& lambda0,
                                  const Eigen::Ref<const Vector>& alpha0,
                                  const SolverOptions& opt);

/// @brief The chain for a bordered problem: only "newton_ac" handles the equilibrium rows
/// (as solve_newton_bordered); the other solvers of the chain are skipped, each with a line
/// in `attempts`. Tried from (λ0, α0), then from the all-stick start.
SolveReport solve(const ProblemView& p, const Eigen::Ref<const Matrix>& G,
                  const Eigen::Ref<const Vector>& e, const Eigen::Ref<const Vector>& lambda0,
                  const Eigen::Ref<const Vector>& alpha0, const SolverOptions& opt);

/// @brief Names accepted in SolverOptions::chain: "active_set", "projection", "newton_ac".
std::vector<std::string> solver_names();

/// @brief Default order, most robust first.
std::vector<std::string> default_chain();

/// @brief Try the solvers of opt.chain (or default_chain()) in order until one converges.
/// With the default chain and 300 unknowns or more, 50 projection sweeps come first as a
/// warm start (recorded in `attempts`): they settle most pairs' states cheaply, and Newton
/// then needs a step or two. Each solver is tried from the best answer so far and from the
/// caller's start (the active set from the caller's first). Newton from the caller's start
/// gets 10 × max_iterations steps (ill-conditioned problems need hundreds of damped ones);
/// if it fails, Newton runs from zero in four more variants, each 10 × max_iterations
/// steps: Siconos' globalisation (full step where the line search fails) with each pair's
/// ρ = 1/‖W_kk‖₂ and a Goldstein–Price search, the same with Armijo's search, Armijo's
/// with the normal/tangential ρ, and the restarted Newton with the block ρ; they solve
/// different subsets of the hard problems. The whole chain stops trying once the work of
/// opt.work_budget_gflop (0: chain_work_budget_gflop(n), 50 + 200·(n/1000)³ Gflop) is
/// spent, with a line in `attempts`; each attempt also stops at it. Work, not time: the
/// same input gives the bitwise same answer on a quiet and on a loaded machine. The report is the converging solver's, with `attempts`
/// listing every try; if none converges it is the best one's (smallest residual) with
/// converged=false.
SolveReport solve(const ProblemView& p, const Eigen::Ref<const Vector>& lambda0,
                  const std::vector<PairState>& states0, const SolverOptions& opt);
} // namespace flexcontact
