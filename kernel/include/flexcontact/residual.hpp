// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file residual.hpp
/// @brief Coulomb cone projection and the natural-map residual that certifies an answer.

#include "flexcontact/problem.hpp"

namespace flexcontact
{
/// @brief Project one pair's force (λ_n, λ_t…) onto the Coulomb cone |λ_t| ≤ μ λ_n, in place.
/// @param r pointer to d values, normal first
void project_on_cone(double* r, int dim, double mu);

/// @brief Project one pair's force onto the Coulomb cone truncated at r_n ≤ cap, in place:
/// the cone's projection if its normal part is within the cap, otherwise the point of the
/// cap's disc (r_n = cap, |r_t| ≤ μ·cap) nearest to r (docs/crushing.md). cap = +∞ is
/// project_on_cone, bitwise.
void project_on_truncated_cone(double* r, int dim, double mu, double cap);

/// @brief ρ_k of every pair as used by natural_map_residual: 1/W_nn of the pair's normal row,
/// or 1/max_i W_ii when that entry is zero, negative, non-finite or below 1e-12·max_i W_ii
/// (constrained DOFs), or 1 when W has no positive diagonal at all.
/// @throws std::invalid_argument if dim is not 2/3 or the sizes of p disagree
Vector pair_rho(const ProblemView& p);

/// @brief Relative natural-map residual of λ for the problem, 0 for an exact solution.
///
/// Per pair, with the De Saxcé modified velocity û = (u_n + μ|u_t|, u_t) and ρ_k = 1/W_kk of
/// the pair's normal row (so that ρ u is a force):  e_k = λ_k − P_K(λ_k − ρ_k û_k), K the
/// Coulomb cone truncated at the pair's cap where it has one (problem.hpp).
/// Returned: ‖e‖ / max(‖λ‖, ‖ρ q‖, tiny). It vanishes exactly on the solutions of the
/// Signorini–Coulomb problem, whatever solver produced λ.
double natural_map_residual(const ProblemView& p, const Eigen::Ref<const Vector>& lambda);

/// @brief The same residual from a known u = W λ + q and ρ = pair_rho(p): inside an
/// iteration that keeps u up to date this avoids the O(n²) product. Certify final answers
/// with the two-argument form.
double natural_map_residual(const ProblemView& p, const Eigen::Ref<const Vector>& lambda,
                            const Eigen::Ref<const Vector>& u, const Eigen::Ref<const Vector>& rho);

/// @brief State of each pair read from (λ, u): open, stick, slip or crush, with a relative
/// tolerance.
///
/// Open if λ_n ≤ tol·max|λ_i|; otherwise crush if the pair has a cap c_k and
/// λ_n ≥ (1 − tol)·c_k; otherwise slip if |u_t| > tol·max(max|u_i|, max|q_i|), else stick.
std::vector<PairState> classify_states(const ProblemView& p,
                                       const Eigen::Ref<const Vector>& lambda,
                                       const Eigen::Ref<const Vector>& u, double tol = 1e-8);
} // namespace flexcontact
