// Copyright flexcontact developers. MIT licence.

/// @file newton_bordered.cpp
/// @brief Semi-smooth Newton on the bordered problem of bodies held only by contact (FETI
/// style): u = W λ + q + G α, Alart–Curnier on (λ, u), equilibrium Gᵀ λ = e.

#include "flexcontact/residual.hpp"
#include "flexcontact/solvers.hpp"

#include "ac_pair.hpp"
#include "message_numbers.hpp"
#include "newton_step.hpp"

#include <Eigen/QR>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

namespace flexcontact
{
namespace
{
/// @brief The problem: the local view, the border and the pairs' ρ. The linear systems
/// are solved for ρ̄ α rather than α (ρ̄ the mean normal ρ): W is of order 1/ρ̄ (1e-11 m/N
/// for steel), G of order 1, and unscaled the complete orthogonal decomposition would take
/// the W block for rank deficiency.
struct Bordered
{
  const ProblemView& p;
  Eigen::Ref<const Matrix> G;
  Eigen::Ref<const Vector> e;
  Vector rho, rho_t;
  double rbar;
};

/// @brief One iterate (λ, α) with q + G α, u, Φ, ψ = Gᵀλ − e, ∂P/∂z and the merit.
struct Iterate
{
  Vector lam, alpha, qe, u, phi, psi;
  std::vector<double> dP;
  double f = 0.0;
};

void evaluate(const Bordered& b, Iterate& s)
{
  const int d = b.p.dim;
  s.qe = b.p.q + b.G * s.alpha;
  s.u = b.p.W * s.lam + s.qe;
  s.phi.resize(s.lam.size());
  s.dP.resize(static_cast<std::size_t>(b.p.pairs()) * d * d);
  for (int k = 0; k < b.p.pairs(); ++k)
    detail::ac_pair(s.lam.data() + k * d, s.u.data() + k * d, b.p.mu[k], b.rho[k],
                    b.rho_t[k], d, s.phi.data() + k * d, s.dP.data() + k * d * d,
                    b.p.cap_of(k));
  s.psi = b.G.transpose() * s.lam - b.e;
  s.f = 0.5 * (s.phi.squaredNorm() + s.psi.squaredNorm());
}

/// @brief The larger of the contact laws' natural-map residual at q + G α and the relative
/// equilibrium residual.
double residual(const Bordered& b, const Iterate& s)
{
  const ProblemView v{b.p.dim, b.p.W, s.qe, b.p.mu, b.p.cap};
  const double contact = natural_map_residual(v, s.lam);
  const Vector held = b.G.cwiseAbs().transpose() * s.lam.cwiseAbs();
  const double scale = std::max({b.e.norm(), held.norm(), 1e-300});
  return std::max(contact, s.psi.norm() / scale);
}

std::vector<int> closed_pairs(const Iterate& s, int m, int d)
{
  std::vector<int> closed;
  detail::closed_pairs(s.dP, m, d, closed);
  return closed;
}

/// @brief D_k ρ of pair k at the iterate s (newton_step.hpp).
Matrix scaled_d(const Bordered& b, const Iterate& s, int k)
{
  return detail::scaled_dp(s.dP, k, b.p.dim, b.rho[k], b.rho_t[k]);
}

/// @brief Minimum-norm solution of A x = b (complete orthogonal decomposition).
bool min_norm_solve(const Matrix& A, const Vector& rhs, Vector& x)
{
  Eigen::CompleteOrthogonalDecomposition<Matrix> cod;
  cod.setThreshold(1e-12);
  cod.compute(A);
  x = cod.solve(rhs);
  return x.allFinite();
}

/// @brief Newton step (Δλ, Δα): open pairs Δλ_k = −Φ_k; closed pairs
/// (I − D)Δλ_k + D ρ (W Δλ + G Δα)_k = −Φ_k; equilibrium Gᵀ Δλ = −ψ.
bool newton_direction(const Bordered& b, const Iterate& s, Vector& dl, Vector& da)
{
  const int d = b.p.dim, k = static_cast<int>(b.G.cols());
  const std::vector<int> closed = closed_pairs(s, b.p.pairs(), d);
  const int nc = static_cast<int>(closed.size());
  dl = -s.phi;
  Vector d0 = dl;
  for (int c : closed)
    d0.segment(c * d, d).setZero();
  const Vector Wd0 = b.p.W * d0;
  Matrix A = Matrix::Zero(nc * d + k, nc * d + k);
  Vector rhs(nc * d + k);
  for (int a = 0; a < nc; ++a)
  {
    const int kk = closed[a];
    const Matrix Dr = scaled_d(b, s, kk);
    for (int c = 0; c < nc; ++c)
      A.block(a * d, c * d, d, d).noalias() = Dr * b.p.W.block(kk * d, closed[c] * d, d, d);
    A.block(a * d, a * d, d, d) += Matrix::Identity(d, d) - detail::dp_block(s.dP, kk, d);
    A.block(a * d, nc * d, d, k).noalias() = Dr * b.G.middleRows(kk * d, d) / b.rbar;
    A.block(nc * d, a * d, k, d) = b.G.middleRows(kk * d, d).transpose();
    rhs.segment(a * d, d) = -s.phi.segment(kk * d, d) - Dr * Wd0.segment(kk * d, d);
  }
  rhs.tail(k) = -s.psi - b.G.transpose() * d0;
  Vector x;
  if (!min_norm_solve(A, rhs, x))
    return false;
  for (int a = 0; a < nc; ++a)
    dl.segment(closed[a] * d, d) = x.segment(a * d, d);
  da = x.tail(k) / b.rbar;
  return true;
}

/// @brief The all-stick start: [[W, G], [Gᵀ, 0]] [λ; α] = [−q; e].
void all_stick_start(const Bordered& b, Iterate& s)
{
  const Eigen::Index n = b.p.q.size(), k = b.G.cols();
  Matrix A = Matrix::Zero(n + k, n + k);
  A.topLeftCorner(n, n) = b.rbar * b.p.W;
  A.topRightCorner(n, k) = b.G;
  A.bottomLeftCorner(k, n) = b.G.transpose();
  Vector rhs(n + k);
  rhs.head(n) = -b.rbar * b.p.q;
  rhs.tail(k) = b.e;
  Vector x;
  if (min_norm_solve(A, rhs, x))
  {
    s.lam = x.head(n);
    s.alpha = x.tail(k) / b.rbar;
  }
}

/// @brief Orthonormal basis of the directions of α that move no closed pair in a direction
/// it resists: the null space of the stacked D_k ρ G_k of the closed pairs.
Matrix undetermined_directions(const Bordered& b, const Iterate& s)
{
  const int d = b.p.dim, k = static_cast<int>(b.G.cols());
  const std::vector<int> closed = closed_pairs(s, b.p.pairs(), d);
  Matrix C = Matrix::Zero(std::max<int>(static_cast<int>(closed.size()) * d, 1), k);
  for (std::size_t a = 0; a < closed.size(); ++a)
    C.middleRows(static_cast<Eigen::Index>(a) * d, d)
        = scaled_d(b, s, closed[a]) * b.G.middleRows(closed[a] * d, d);
  const double scale = b.rho.maxCoeff() * std::max(b.G.cwiseAbs().maxCoeff(), 1e-300);
  Eigen::JacobiSVD<Matrix> svd(C, Eigen::ComputeFullV);
  const Vector& sv = svd.singularValues();
  std::vector<int> null;
  for (int j = 0; j < k; ++j)
    if (j >= sv.size() || sv[j] <= 1e-10 * scale)
      null.push_back(j);
  Matrix N(k, static_cast<int>(null.size()));
  for (std::size_t j = 0; j < null.size(); ++j)
    N.col(static_cast<Eigen::Index>(j)) = svd.matrixV().col(null[j]);
  return N;
}

/// @brief Line search on the merit ½(‖Φ‖² + ‖ψ‖²), Armijo with a non-monotone reference.
bool line_search(const Bordered& b, const Iterate& s, const Vector& dl, const Vector& da,
                 double fref, Iterate& t)
{
  constexpr double sigma = 1e-4;
  double step = 1.0;
  for (int ls = 0; ls < 40; ++ls, step *= 0.5)
  {
    t.lam = s.lam + step * dl;
    t.alpha = s.alpha + step * da;
    evaluate(b, t);
    if (std::isfinite(t.f) && t.f <= fref - 2.0 * sigma * step * s.f)
      return true;
  }
  return false;
}

/// @brief Sets α to zero along the undetermined directions if the answer stays certified.
void minimum_norm_alpha(const Bordered& b, double tolerance, Iterate& s, double& res,
                        Matrix& N)
{
  N = undetermined_directions(b, s);
  if (N.cols() == 0)
    return;
  Iterate t = s;
  t.alpha = s.alpha - N * (N.transpose() * s.alpha);
  evaluate(b, t);
  const double rt = residual(b, t);
  if (rt <= std::max(tolerance, res))
  {
    s = std::move(t);
    res = rt;
  }
}
} // namespace

SolveReport solve_newton_bordered(const ProblemView& p, const Eigen::Ref<const Matrix>& G,
                                  const Eigen::Ref<const Vector>& e,
                                  const Eigen::Ref<const Vector>& lambda0,
                                  const Eigen::Ref<const Vector>& alpha0,
                                  const SolverOptions& opt)
{
  detail::check_problem(p, lambda0, "solve_newton_bordered");
  const std::string who = "flexcontact: solve_newton_bordered: ";
  if (G.rows() != p.q.size() || e.size() != G.cols())
    throw std::invalid_argument(who + "G is " + std::to_string(G.rows()) + "x"
                                + std::to_string(G.cols()) + " and e has "
                                + std::to_string(e.size()) + " entries; expected "
                                + std::to_string(p.q.size()) + " rows and e of G's columns");
  if (alpha0.size() != 0 && alpha0.size() != G.cols())
    throw std::invalid_argument(who + "alpha0 has " + std::to_string(alpha0.size())
                                + " entries, expected 0 or " + std::to_string(G.cols()));
  if (!G.allFinite() || !e.allFinite() || !alpha0.allFinite())
    throw std::invalid_argument(who + "G, e or alpha0 is not finite");
  const Vector rho = pair_rho(p);
  const Bordered b{p, G, e, rho, detail::tangential_rho(p, rho), rho.mean()};
  const Eigen::Index n = p.q.size();

  Iterate s;
  s.lam = lambda0.size() ? Vector(lambda0) : Vector::Zero(n);
  s.alpha = alpha0.size() ? Vector(alpha0) : Vector::Zero(G.cols());
  evaluate(b, s);
  const bool cold = lambda0.size() == 0 || closed_pairs(s, p.pairs(), p.dim).empty();
  if (cold)
  {
    all_stick_start(b, s);
    evaluate(b, s);
  }
  double res = residual(b, s);
  int it = 0;
  std::string why;
  detail::MeritHistory history(s.f);
  Iterate t;
  while (res > opt.tolerance && it < opt.max_iterations)
  {
    ++it;
    Vector dl, da;
    if (!newton_direction(b, s, dl, da))
    {
      why = ", linear system not solvable";
      break;
    }
    if (!line_search(b, s, dl, da, history.reference(), t))
    {
      why = ", line search failed (no static equilibrium near this iterate?)";
      break;
    }
    std::swap(s, t);
    history.push(s.f);
    res = residual(b, s);
    if (opt.verbose)
      std::fprintf(stderr, "newton_bordered it %d: merit %.3e, residual %.3e\n", it, s.f, res);
  }
  SolveReport rep;
  minimum_norm_alpha(b, opt.tolerance, s, res, rep.undetermined);
  rep.solver = "newton_ac";
  rep.iterations = it;
  rep.lambda = s.lam;
  rep.alpha = s.alpha;
  rep.u = s.u;
  rep.residual = res;
  rep.converged = res <= opt.tolerance;
  const ProblemView v{p.dim, p.W, s.qe, p.mu, p.cap};
  rep.states = classify_states(v, rep.lambda, rep.u);
  rep.attempts.push_back("newton_ac (bordered" + std::string(cold ? ", all-stick start" : "")
                         + "): " + (rep.converged ? "converged" : "not converged") + " in "
                         + std::to_string(it) + " iterations, residual " + detail::exp3(res)
                         + why);
  return rep;
}

namespace
{
/// @brief Empty, or why the capped contact forces cannot balance the loads e: along some
/// rigid mode i, (Gᵀλ)_i over the truncated cones (problem.hpp) spans at most
/// [Σ_k min(0, c_k (a_n − μ|a_t|)), Σ_k max(0, c_k (a_n + μ|a_t|))] with a = G's rows of
/// pair k in column i, and e_i lies outside. Modes that an uncapped pair can carry either
/// way are not judged.
std::string no_equilibrium(const ProblemView& p, const Eigen::Ref<const Matrix>& G,
                           const Eigen::Ref<const Vector>& e)
{
  const int d = p.dim;
  for (Eigen::Index i = 0; i < G.cols(); ++i)
  {
    double hi = 0.0, lo = 0.0;
    for (int k = 0; k < p.pairs(); ++k)
    {
      const double an = G(k * d, i);
      const double at = d == 2 ? std::abs(G(k * d + 1, i)) : std::hypot(G(k * d + 1, i),
                                                                        G(k * d + 2, i));
      const double up = an + p.mu[k] * at, down = an - p.mu[k] * at;
      const double c = p.cap_of(k);
      hi += up > 0.0 ? c * up : 0.0;
      lo += down < 0.0 ? c * down : 0.0;
    }
    const double tol = 1e-12 * std::max({std::abs(hi), std::abs(lo), std::abs(e[i])});
    if (std::isfinite(hi) && e[i] > hi + tol)
      return "no equilibrium: along rigid mode " + std::to_string(i) + " the load is "
             + detail::exp3(e[i]) + " but the crushable contact forces can carry at most "
             + detail::exp3(hi) + " (their caps): the surfaces would crush without end";
    if (std::isfinite(lo) && e[i] < lo - tol)
      return "no equilibrium: along rigid mode " + std::to_string(i) + " the load is "
             + detail::exp3(e[i]) + " but the crushable contact forces can carry at least "
             + detail::exp3(lo) + " (their caps): the surfaces would crush without end";
  }
  return "";
}
} // namespace

SolveReport solve(const ProblemView& p, const Eigen::Ref<const Matrix>& G,
                  const Eigen::Ref<const Vector>& e, const Eigen::Ref<const Vector>& lambda0,
                  const Eigen::Ref<const Vector>& alpha0, const SolverOptions& opt)
{
  const std::vector<std::string> chain = opt.chain.empty() ? default_chain() : opt.chain;
  std::vector<std::string> attempts;
  SolveReport best;
  if (p.capped() && e.size() == G.cols())
    if (std::string why = no_equilibrium(p, G, e); !why.empty())
    {
      best.solver = "none";
      best.lambda = Vector::Zero(p.q.size());
      best.u = p.q;
      best.alpha = Vector::Zero(G.cols());
      best.states.assign(static_cast<std::size_t>(p.pairs()), PairState::open);
      best.attempts = {why};
      return best;
    }
  bool tried = false;
  for (const auto& name : chain)
  {
    if (name != "newton_ac")
    {
      attempts.push_back(name + ": skipped (bodies held only by contact: only newton_ac "
                                "solves their equilibrium rows)");
      continue;
    }
    if (tried)
      continue;
    tried = true;
    // From the caller's start (the last increment), then from the all-stick start.
    best = solve_newton_bordered(p, G, e, lambda0, alpha0, opt);
    attempts.insert(attempts.end(), best.attempts.begin(), best.attempts.end());
    if (!best.converged && lambda0.size() && lambda0.cwiseAbs().maxCoeff() > 0.0)
    {
      SolveReport cold = solve_newton_bordered(p, G, e, Vector(), Vector(), opt);
      attempts.insert(attempts.end(), cold.attempts.begin(), cold.attempts.end());
      if (cold.converged || cold.residual < best.residual)
        best = std::move(cold);
    }
  }
  if (!tried)
  {
    best.solver = "none";
    best.lambda = Vector::Zero(p.q.size());
    best.alpha = Vector::Zero(G.cols());
  }
  best.attempts = std::move(attempts);
  return best;
}
} // namespace flexcontact
