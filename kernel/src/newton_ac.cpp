// Copyright flexcontact developers. MIT licence.

/// @file newton_ac.cpp
/// @brief Semi-smooth Newton on the Alart–Curnier formulation with a line search.

#include "flexcontact/residual.hpp"
#include "flexcontact/solvers.hpp"

#include "ac_pair.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>


namespace flexcontact
{
namespace
{
/// @brief ρ of every pair from its diagonal block, as Siconos' NSN_AC scales it: 1/‖W_kk‖₂
/// for the normal and the tangential components alike (fallback where the block vanishes).
void spectral_rho(const ProblemView& p, const Vector& fallback, Vector& rn, Vector& rt)
{
  const int d = p.dim;
  rn.resize(p.pairs());
  rt.resize(p.pairs());
  for (int k = 0; k < p.pairs(); ++k)
  {
    Matrix B = 0.5 * (p.W.block(k * d, k * d, d, d) + p.W.block(k * d, k * d, d, d).transpose());
    const double w = Eigen::SelfAdjointEigenSolver<Matrix>(B, Eigen::EigenvaluesOnly)
                         .eigenvalues()
                         .cwiseAbs()
                         .maxCoeff();
    rn[k] = (std::isfinite(w) && w > 1e-12 / fallback[k]) ? 1.0 / w : fallback[k];
    rt[k] = rn[k];
  }
}
/// @brief Φ(λ) for all pairs from λ and u = Wλ + q; optionally the blocks ∂P/∂z (d×d each).
void ac_all(const ProblemView& p, const Vector& rho, const Vector& rho_t, const Vector& lam,
            const Vector& u, Vector& phi, std::vector<double>* dP)
{
  const int d = p.dim;
  for (int k = 0; k < p.pairs(); ++k)
    detail::ac_pair(lam.data() + k * d, u.data() + k * d, p.mu[k], rho[k], rho_t[k], d,
                    phi.data() + k * d, dP ? dP->data() + k * d * d : nullptr);
}

/// @brief Solve A x = b, pivoted LU first. A singular A (semi-definite W, fully constrained
/// pairs) gets the minimum-norm least-squares step instead: it moves nothing along the null
/// space, where an LU or a small regularisation would send λ off to huge values that the
/// relative residual then mistakes for convergence. Beyond a size where a rank-revealing
/// factorisation is too slow, a Tikhonov-regularised LU is the fallback. Returns false if
/// no finite solution was found.
bool linear_solve(const Matrix& A, const Vector& b, Vector& x)
{
  const double bn = b.norm();
  {
    Eigen::PartialPivLU<Matrix> lu(A);
    x = lu.solve(b);
    if (x.allFinite() && (A * x - b).norm() <= 1e-8 * std::max(bn, 1e-300))
      return true;
  }
  if (A.rows() <= 1500)
  {
    Eigen::CompleteOrthogonalDecomposition<Matrix> cod(A);
    cod.setThreshold(1e-12);
    x = cod.compute(A).solve(b);
    return x.allFinite();
  }
  const double scale = std::max(A.cwiseAbs().rowwise().sum().maxCoeff(), 1e-300);
  Matrix R = A;
  R.diagonal().array() += 1e-8 * scale;
  x = Eigen::PartialPivLU<Matrix>(R).solve(b);
  return x.allFinite();
}

/// @brief Φ and the blocks ∂P/∂z at (λ, u); returns the merit ½‖Φ‖².
double merit(const ProblemView& p, const Vector& rho, const Vector& rho_t, const Vector& lam,
             const Vector& u, Vector& phi, std::vector<double>& dP)
{
  ac_all(p, rho, rho_t, lam, u, phi, &dP);
  return 0.5 * phi.squaredNorm();
}

/// @brief The pairs whose block ∂P/∂z is not zero; the others (open) decouple from the
/// Newton system.
void closed_pairs(const std::vector<double>& dP, int m, int d, std::vector<int>& closed)
{
  closed.clear();
  for (int k = 0; k < m; ++k)
  {
    const double* D = dP.data() + k * d * d;
    bool nz = false;
    for (int i = 0; i < d * d; ++i)
      nz = nz || D[i] != 0.0;
    if (nz)
      closed.push_back(k);
  }
}

/// @brief Newton direction dl from the generalised Jacobian, J Δ = −Φ with
/// J = I − D (I − ρW) = (I − D) + D ρ W, D = blockdiag(∂P/∂z). Pairs with D_k = 0 (open)
/// have identity rows: Δ_k = −Φ_k; only the closed block is factorised, which keeps the
/// dense LU to the size of the contact zone. Returns false if that block has no solution.
bool newton_direction(const ProblemView& p, const Vector& rho, const Vector& rho_t,
                      const Vector& phi, const std::vector<double>& dP,
                      const std::vector<int>& closed, Vector& dl)
{
  const int d = p.dim;
  dl = -phi;
  const int nc = static_cast<int>(closed.size());
  if (nc == 0)
    return true;
  // Rows of the closed pairs: (I−D)_kk Δ_k + D_k ρ_k Σ_j W_kj Δ_j = −Φ_k, with Δ_open known.
  // Since Δ = −Φ on open pairs, W_kj Δ_j for open j moves to the right-hand side; the
  // full product WΔ₀ (Δ₀ zero on closed pairs) gives it at once.
  Vector d0 = dl;
  for (int k : closed)
    d0.segment(k * d, d).setZero();
  const Vector Wd0 = p.W * d0;
  Matrix A(nc * d, nc * d);
  Vector b(nc * d);
  for (int a = 0; a < nc; ++a)
  {
    const int k = closed[a];
    Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>
        D(dP.data() + k * d * d, d, d);
    Matrix Dr = D;
    Dr.col(0) *= rho[k];
    Dr.rightCols(d - 1) *= rho_t[k];
    for (int c = 0; c < nc; ++c)
      A.block(a * d, c * d, d, d).noalias() = Dr * p.W.block(k * d, closed[c] * d, d, d);
    A.block(a * d, a * d, d, d) += Matrix::Identity(d, d) - D;
    b.segment(a * d, d) = -phi.segment(k * d, d) - Dr * Wd0.segment(k * d, d);
  }
  Vector x;
  if (!linear_solve(A, b, x))
    return false;
  for (int a = 0; a < nc; ++a)
    dl.segment(closed[a] * d, d) = x.segment(a * d, d);
  return true;
}

/// @brief Non-monotone reference of the line search: the largest merit of the last few
/// accepted iterates lets the iteration pass the shallow ridges the kinks of Φ create
/// (Grippo–Lampariello–Lucidi).
class MeritHistory
{
public:
  explicit MeritHistory(double f) : f_{f} {}

  /// @brief Forgets the earlier iterates (after a restart).
  void reset(double f) { f_.assign(1, f); }

  void push(double f)
  {
    f_.push_back(f);
    if (static_cast<int>(f_.size()) > memory)
      f_.erase(f_.begin());
  }

  double reference() const { return *std::max_element(f_.begin(), f_.end()); }

private:
  static constexpr int memory = 5;
  std::vector<double> f_;
};

/// @brief The line search's trial iterate: λ + α Δ, u + α WΔ, its Φ, and WΔ.
struct Trial
{
  Vector lam, u, phi, Wdl;
};

/// @brief The merit ½‖Φ‖² at λ + α Δ (filling t); +inf if not finite.
double trial_merit(const ProblemView& p, const Vector& rho, const Vector& rho_t,
                   const Vector& lam, const Vector& u, const Vector& dl, double alpha, Trial& t)
{
  t.lam = lam + alpha * dl;
  t.u = u + alpha * t.Wdl;
  ac_all(p, rho, rho_t, t.lam, t.u, t.phi, nullptr);
  const double ft = 0.5 * t.phi.squaredNorm();
  return std::isfinite(ft) ? ft : std::numeric_limits<double>::infinity();
}

/// @brief Line search on ½‖Φ‖², Armijo with the non-monotone reference of history. If the
/// Newton direction dl gives no decrease, the fixed-point direction −Φ (a projected step)
/// replaces it (not with full_step, where the caller then takes the full Newton step).
/// Returns true with the accepted iterate in t.
bool line_search(const ProblemView& p, const Vector& rho, const Vector& rho_t,
                 const Vector& lam, const Vector& u, const Vector& phi, double f,
                 const MeritHistory& history, bool full_step, Vector& dl, Trial& t)
{
  constexpr double sigma = 1e-4;
  const double fref = full_step ? f : history.reference();
  for (int attempt = 0; attempt < (full_step ? 1 : 2); ++attempt)
  {
    if (attempt == 1)
      dl = -phi;
    t.Wdl.noalias() = p.W * dl;
    double alpha = 1.0;
    for (int ls = 0; ls < 40; ++ls, alpha *= 0.5)
      if (trial_merit(p, rho, rho_t, lam, u, dl, alpha, t) <= fref - 2.0 * sigma * alpha * f)
        return true;
  }
  return false;
}

/// @brief Goldstein–Price search along the Newton direction (the merit's slope there is
/// −2f): α is accepted when the mean slope (f(α) − f)/α lies between 0.99 and 0.01 times
/// the initial one; too steep raises the lower bound, too shallow lowers the upper, and
/// α bisects the bracket. Returns true with the accepted iterate in t.
bool goldstein_price(const ProblemView& p, const Vector& rho, const Vector& rho_t,
                     const Vector& lam, const Vector& u, double f, const Vector& dl, Trial& t)
{
  const double slope0 = -2.0 * f;
  t.Wdl.noalias() = p.W * dl;
  double lo = 0.0, hi = 1e10, alpha = 1.0;
  for (int ls = 0; ls < 100; ++ls)
  {
    const double slope = (trial_merit(p, rho, rho_t, lam, u, dl, alpha, t) - f) / alpha;
    const bool not_too_steep = slope >= 0.99 * slope0;
    if (not_too_steep && slope <= 0.01 * slope0)
      return true;
    (not_too_steep ? hi : lo) = alpha;
    alpha = 0.5 * (lo + hi);
  }
  return false;
}

/// @brief A few Gauss–Seidel sweeps with exact pair solves, stopping early once the
/// residual res meets the tolerance. They move λ to where Newton regains its fast local
/// convergence (they succeed where the kinks of Φ trap Newton).
void gauss_seidel_sweeps(const ProblemView& p, const Vector& rho, double tolerance,
                         Vector& lam, Vector& u, double& res)
{
  for (int s = 0; s < 5 && res > tolerance; ++s)
  {
    detail::nsgs_sweep(p, rho, lam, u);
    u.noalias() = p.W * lam + p.q;
    res = natural_map_residual(p, lam, u, rho);
  }
}

/// @brief Fills the report from the last iterate; why ends the attempt's line.
void finish_report(const ProblemView& p, const Vector& lam, int it, int sweeps_used,
                   std::string why, double tolerance, SolveReport& rep)
{
  rep.iterations = it;
  rep.lambda = lam;
  rep.u = p.W * lam + p.q;
  rep.residual = natural_map_residual(p, rep.lambda);
  rep.converged = rep.residual <= tolerance;
  rep.states = classify_states(p, rep.lambda, rep.u);
  if (sweeps_used > 0)
    why += ", Gauss-Seidel restarts " + std::to_string(sweeps_used);
  rep.attempts.push_back("newton_ac: " + std::string(rep.converged ? "converged" : "not converged")
                         + " in " + std::to_string(it) + " iterations, residual "
                         + std::to_string(rep.residual) + why);
}
} // namespace

SolveReport solve_newton_ac(const ProblemView& p, const Eigen::Ref<const Vector>& lambda0,
                            const SolverOptions& opt)
{
  return detail::newton_ac(p, lambda0, opt, detail::NewtonSettings{});
}

SolveReport detail::newton_ac(const ProblemView& p, const Eigen::Ref<const Vector>& lambda0,
                              const SolverOptions& opt, const NewtonSettings& settings)
{
  detail::check_problem(p, lambda0, "solve_newton_ac");
  const int d = p.dim;
  const int m = p.pairs();
  const int n = m * d;
  const Vector rho_res = pair_rho(p);
  Vector rho = rho_res;
  Vector rho_t = detail::tangential_rho(p, rho);
  if (settings.block_rho)
    spectral_rho(p, rho_res, rho, rho_t);
  const long maxit = static_cast<long>(opt.max_iterations) * std::max(settings.iteration_factor, 1);

  SolveReport rep;
  rep.solver = "newton_ac";
  Vector lam = lambda0.size() ? Vector(lambda0) : Vector::Zero(n);
  Vector u = p.W * lam + p.q;
  Vector phi(n), dl(n);
  Trial trial{Vector(n), Vector(n), Vector(n), Vector(n)};
  std::vector<double> dP(static_cast<std::size_t>(m) * d * d);
  std::vector<int> closed;
  closed.reserve(m);

  double f = merit(p, rho, rho_t, lam, u, phi, dP);
  double res = natural_map_residual(p, lam, u, rho_res);
  int it = 0;
  std::string why;
  int last_gain = 0, sweeps_used = 0, full_steps = 0;
  double gain_ref = res, best = res;
  Vector best_lam = lam;
  // Iterations without halving the residual before Newton is declared stalled.
  constexpr int stall = 8;
  MeritHistory history(f);
  const detail::Deadline deadline(opt.time_budget_s);
  while (res > opt.tolerance && it < maxit)
  {
    if (deadline.passed())
    {
      why = ", time budget spent";
      break;
    }
    ++it;
    closed_pairs(dP, m, d, closed);
    if (!newton_direction(p, rho, rho_t, phi, dP, closed, dl))
    {
      why = ", linear system not solvable";
      break;
    }
    bool accepted = settings.full_step && settings.goldstein_price
                        ? goldstein_price(p, rho, rho_t, lam, u, f, dl, trial)
                        : line_search(p, rho, rho_t, lam, u, phi, f, history,
                                      settings.full_step, dl, trial);
    if (!accepted && settings.full_step)
    {
      // Siconos' rule: no decrease along the Newton direction, take the full step anyway.
      ++full_steps;
      trial.lam = lam + dl;
      trial.u.noalias() = p.W * trial.lam + p.q;
      accepted = trial.lam.allFinite();
    }
    if (!accepted || (!settings.full_step && it - last_gain >= stall))
    {
      // Stalled: the sweeps move λ to where Newton converges fast again.
      ++sweeps_used;
      gauss_seidel_sweeps(p, rho_res, opt.tolerance, lam, u, res);
      if (!lam.allFinite())
      {
        why = ", non-finite iterate";
        break;
      }
      f = merit(p, rho, rho_t, lam, u, phi, dP);
      history.reset(f);
      last_gain = it;
      gain_ref = std::min(gain_ref, res);
      if (res < best)
      {
        best = res;
        best_lam = lam;
      }
      if (opt.verbose)
        std::fprintf(stderr, "newton_ac it %d: Gauss-Seidel sweeps, residual %.3e\n", it, res);
      continue;
    }
    lam.swap(trial.lam);
    // Recompute u now and then: the running update accumulates rounding on long runs.
    if (it % 20 == 0)
      u.noalias() = p.W * lam + p.q;
    else
      u.swap(trial.u);
    f = merit(p, rho, rho_t, lam, u, phi, dP);
    history.push(f);
    res = natural_map_residual(p, lam, u, rho_res);
    if (res < 0.5 * gain_ref)
    {
      gain_ref = res;
      last_gain = it;
    }
    if (res < best)
    {
      best = res;
      best_lam = lam;
    }
    if (opt.verbose)
      std::fprintf(stderr, "newton_ac it %d: closed %d, merit %.3e, residual %.3e\n", it,
                   static_cast<int>(closed.size()), f, res);
  }
  if (full_steps > 0)
    why += ", full steps " + std::to_string(full_steps);
  // Full steps make the iteration non-monotone: report the best iterate met.
  if (settings.full_step && !(res <= opt.tolerance) && best < res)
    lam = best_lam;

  finish_report(p, lam, it, sweeps_used, why, opt.tolerance, rep);
  return rep;
}
} // namespace flexcontact
