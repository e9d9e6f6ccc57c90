// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file ac_pair.hpp
/// @brief Private to the kernel: the Alart–Curnier function of one pair and the derivative of
/// its projection, shared by the global Newton and the projection solver's local solve.

#include "flexcontact/problem.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace flexcontact::detail
{
/// @brief Alart–Curnier function of one pair, Φ = λ − P(λ − ρ u) in the non-De Saxcé form:
/// normal λ_n − max(0, z_n); tangent λ_t − P_disc(μ max(0, z_n))(z_t), z = λ − ρ u.
/// If dP is non-null it receives ∂P/∂z (d×d, row-major), one element of the generalised
/// Jacobian; the generalised Jacobian of Φ is then I − dP (I − diag(ρ_n, ρ_t…) ∂u/∂λ).
/// Separate normal and tangential ρ keep the map well scaled when the pair's block is
/// strongly anisotropic; any ρ_n, ρ_t > 0 give the same solutions.
///
/// With a cap c on the normal force (problem.hpp) the normal part is clamped to [0, c],
/// λ_n − min(max(0, z_n), c), and the disc's radius is μ times that clamped value; c = +∞
/// is the uncapped function, bitwise.
inline void ac_pair(const double* lam, const double* u, double mu, double rho_n, double rho_t,
                    int d, double* phi, double* dP,
                    double cap = std::numeric_limits<double>::infinity())
{
  double z[3] = {0.0, 0.0, 0.0};
  z[0] = lam[0] - rho_n * u[0];
  for (int i = 1; i < d; ++i)
    z[i] = lam[i] - rho_t * u[i];
  const double xi = z[0] > 0.0 ? (z[0] > cap ? cap : z[0]) : 0.0;
  const double r = mu * xi;
  const bool free_normal = z[0] > 0.0 && !(z[0] > cap); // ∂ξ/∂z_n = 1
  // sqrt, not hypot: 5% of a chain solve under callgrind; z is a force (λ − ρu), far from
  // the overflow range hypot guards against.
  const double zt = d == 2 ? std::abs(z[1]) : std::sqrt(z[1] * z[1] + z[2] * z[2]);
  double P[3];
  P[0] = xi;
  // "Inside" needs r > 0: with r = 0 the disc is a point and the derivative is 0, otherwise
  // an open pair with z_t = 0 would get stick rows.
  const bool inside = r > 0.0 && zt <= r;
  const double s = (zt > 0.0 && !inside) ? r / zt : 0.0;
  for (int i = 1; i < d; ++i)
    P[i] = inside ? z[i] : s * z[i];
  for (int i = 0; i < d; ++i)
    phi[i] = lam[i] - P[i];
  if (!dP)
    return;
  for (int i = 0; i < d * d; ++i)
    dP[i] = 0.0;
  dP[0] = free_normal ? 1.0 : 0.0;
  if (inside)
  {
    for (int i = 1; i < d; ++i)
      dP[i * d + i] = 1.0;
  }
  else if (zt > 0.0)
  {
    // P_t = μ ξ ẑ: ∂/∂z_t = (r/|z_t|)(I − ẑẑᵀ), ∂/∂z_n = μ ẑ where 0 < z_n < cap.
    for (int i = 1; i < d; ++i)
    {
      const double hi = z[i] / zt;
      if (free_normal)
        dP[i * d] = mu * hi;
      for (int j = 1; j < d; ++j)
        dP[i * d + j] = s * ((i == j ? 1.0 : 0.0) - hi * z[j] / zt);
    }
  }
}

/// @brief Tangential ρ of every pair: 1 / (largest eigenvalue of the pair's tangential
/// block of W), or the pair's normal ρ when that block is zero or not positive.
inline Vector tangential_rho(const ProblemView& p, const Vector& rho_n)
{
  const int d = p.dim;
  Vector rt(p.pairs());
  for (int k = 0; k < p.pairs(); ++k)
  {
    const int o = k * d + 1;
    double w;
    if (d == 2)
      w = p.W(o, o);
    else
    {
      const double a = p.W(o, o), b = 0.5 * (p.W(o, o + 1) + p.W(o + 1, o)), c = p.W(o + 1, o + 1);
      w = 0.5 * (a + c) + std::hypot(0.5 * (a - c), b);
    }
    rt[k] = (std::isfinite(w) && w > 1e-12 / rho_n[k]) ? 1.0 / w : rho_n[k];
  }
  return rt;
}

/// @brief One nonsmooth Gauss–Seidel sweep over the pairs, each pair's problem solved exactly
/// with its diagonal block (defined in projection.cpp). Keeps u = W λ + q up to date
/// incrementally. Returns how many pairs fell back to the plain De Saxcé–Feng step because
/// their block was too degenerate for an exact local solve.
int nsgs_sweep(const ProblemView& p, const Vector& rho, Vector& lam, Vector& u);

/// @brief How the chain runs the Alart–Curnier Newton beyond its public defaults.
struct NewtonSettings
{
  /// ρ from each pair's diagonal block, 1/‖W_kk‖₂ for all components (Siconos' NSN_AC
  /// scaling), instead of 1/W_nn normal and 1/λ_max(tangential block).
  bool block_rho = false;
  /// Newton steps allowed: this × SolverOptions::max_iterations.
  int iteration_factor = 1;
  /// Siconos' globalisation instead of Gauss–Seidel restarts: where the line search finds
  /// no decrease, the full Newton step is taken anyway, and a slow iteration is never
  /// restarted. Non-monotone, it crosses the kinks of Φ that trap a monotone search on
  /// ill-conditioned W (condition 1e10), where it needs hundreds of steps.
  bool full_step = false;
  /// With full_step, a Goldstein–Price search (accept α when the merit's mean slope lies
  /// between 0.99 and 0.01 of the initial one, bisecting between the bounds) instead of
  /// Armijo backtracking. Neither solves all the ill-conditioned problems the other does.
  bool goldstein_price = false;
};

/// @brief The Newton of solve_newton_ac() with the given settings (newton_ac.cpp).
SolveReport newton_ac(const ProblemView& p, const Eigen::Ref<const Vector>& lambda0,
                      const SolverOptions& opt, const NewtonSettings& settings);

/// @brief Throws std::invalid_argument naming what is wrong with a problem and its start λ.
inline void check_problem(const ProblemView& p, const Eigen::Ref<const Vector>& lambda0,
                          const char* who)
{
  const std::string w = std::string("flexcontact: ") + who + ": ";
  if (p.dim != 2 && p.dim != 3)
    throw std::invalid_argument(w + "dim must be 2 or 3, got " + std::to_string(p.dim));
  const auto n = p.q.size();
  if (n % p.dim != 0 || p.W.rows() != n || p.W.cols() != n || p.mu.size() != n / p.dim)
    throw std::invalid_argument(w + "sizes disagree (q " + std::to_string(n) + ", W "
                                + std::to_string(p.W.rows()) + "x" + std::to_string(p.W.cols())
                                + ", mu " + std::to_string(p.mu.size()) + ")");
  if (lambda0.size() != 0 && lambda0.size() != n)
    throw std::invalid_argument(w + "lambda0 has size " + std::to_string(lambda0.size())
                                + ", expected 0 or " + std::to_string(n));
  if (!p.W.allFinite())
    throw std::invalid_argument(w + "W is not finite");
  if (!p.q.allFinite())
    throw std::invalid_argument(w + "q is not finite");
  if (!lambda0.allFinite())
    throw std::invalid_argument(w + "lambda0 is not finite");
  for (Eigen::Index k = 0; k < p.mu.size(); ++k)
    if (!(p.mu[k] >= 0.0) || !std::isfinite(p.mu[k]))
      throw std::invalid_argument(w + "mu of pair " + std::to_string(k)
                                  + " is negative or not finite");
  for (int k = 0; p.cap && k < p.pairs(); ++k)
    if (!(p.cap[k] > 0.0))
      throw std::invalid_argument(w + "the normal force cap of pair " + std::to_string(k)
                                  + " is " + std::to_string(p.cap[k])
                                  + "; it must be > 0 (+inf: no cap)");
}
} // namespace flexcontact::detail
