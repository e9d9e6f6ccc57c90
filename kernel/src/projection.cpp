// Copyright flexcontact developers. MIT licence.

/// @file projection.cpp
/// @brief The projection method: nonsmooth Gauss–Seidel over pairs, each pair's problem with
/// its diagonal block solved exactly (the De Saxcé–Feng fixed point with the optimal local ρ),
/// the plain bi-potential step as the fallback for degenerate blocks.

#include "flexcontact/residual.hpp"
#include "flexcontact/solvers.hpp"

#include "ac_pair.hpp"
#include "work_meter.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace flexcontact
{
namespace
{
using Mat3 = Eigen::Matrix3d;
using Vec3 = Eigen::Vector3d;

double tnorm(const Vec3& v, int d) { return d == 2 ? std::abs(v[1]) : std::hypot(v[1], v[2]); }

/// @brief Local Alart–Curnier Newton for one pair, u = A λ + c; true if Φ vanished (to
/// rounding) from the start λ. ρ = 1/A_nn.
bool local_newton(const Mat3& A, const Vec3& c, double mu, int d, Vec3& lam, double cap)
{
  const double rho = 1.0 / A(0, 0);
  const double at = d == 2 ? A(1, 1) : 0.5 * (A(1, 1) + A(2, 2));
  const double rt = at > 0.0 ? 1.0 / at : rho;
  // Relative to the current λ: the answer of a nearly singular block can be far larger than
  // the start.
  auto scale = [&] { return std::max(lam.head(d).norm(), rho * c.head(d).norm()); };
  Vec3 phi = Vec3::Zero(), phit = Vec3::Zero();
  double dPr[9];
  auto eval = [&](const Vec3& l, Vec3& ph, double* dp)
  {
    const Vec3 u = A * l + c;
    detail::ac_pair(l.data(), u.data(), mu, rho, rt, d, ph.data(), dp, cap);
  };
  eval(lam, phi, dPr);
  for (int it = 0; it < 50; ++it)
  {
    const double f = phi.head(d).squaredNorm();
    if (std::sqrt(f) <= 1e-15 * scale())
      return true;
    // Fixed 3×3 even in 2D (row and column 2 of D and A are zero, so J's are e₂): the
    // dynamic-size d×d LU and temporaries cost 15% of a chain solve under callgrind.
    const Vec3 R(rho, rt, rt);
    Mat3 D = Mat3::Zero();
    for (int i = 0; i < d; ++i)
      for (int j = 0; j < d; ++j)
        D(i, j) = dPr[i * d + j];
    const Mat3 J = Mat3::Identity() - D * (Mat3::Identity() - R.asDiagonal() * A);
    // Partial pivoting first (a third of the full-pivoting cost); full pivoting only when
    // J is singular, where it still gives a finite direction.
    Vec3 dl = J.partialPivLu().solve(-phi);
    if (!dl.allFinite())
      dl = J.fullPivLu().solve(-phi);
    if (!dl.allFinite())
      return false;
    double alpha = 1.0;
    bool ok = false;
    for (int ls = 0; ls < 30; ++ls, alpha *= 0.5)
    {
      const Vec3 lt = lam + alpha * dl;
      eval(lt, phit, nullptr);
      if (phit.head(d).squaredNorm() <= (1.0 - 2e-4 * alpha) * f)
      {
        lam = lt;
        ok = true;
        break;
      }
    }
    if (!ok)
      return std::sqrt(f) <= 1e-10 * scale();
    eval(lam, phi, dPr);
  }
  // An inexact local answer still beats the fallback step; the outer residual decides.
  return phi.head(d).norm() <= 1e-10 * scale();
}

/// @brief 3D slip by the slip angle: λ = λ_n (1, μ cos θ, μ sin θ), u_n = 0 fixes λ_n(θ), and
/// u_t(θ) must point against (cos θ, sin θ). A scan of θ then bisection on the cross product:
/// slower than Newton but indifferent to the conditioning of the block.
bool slip_by_angle(const Mat3& A, const Vec3& c, double mu, Vec3& lam)
{
  auto state = [&](double th, double& ln, Vec3& u)
  {
    const Vec3 g(1.0, mu * std::cos(th), mu * std::sin(th));
    const double an = A.row(0).dot(g);
    if (!(an > 0.0))
      return false;
    ln = -c[0] / an;
    u = ln * (A * g) + c;
    return true;
  };
  auto cross = [&](double th, const Vec3& u) { return u[1] * std::sin(th) - u[2] * std::cos(th); };
  constexpr int samples = 256;
  const double pi2 = 2.0 * 3.14159265358979323846;
  double best = std::numeric_limits<double>::infinity();
  double ln;
  Vec3 u;
  double prev_th = 0.0, prev_h = 0.0;
  bool prev_ok = false;
  for (int i = 0; i <= samples; ++i)
  {
    const double th = pi2 * i / samples;
    const bool ok = state(th, ln, u);
    const double h = ok ? cross(th, u) : 0.0;
    if (ok && prev_ok && (h == 0.0 || (h > 0.0) != (prev_h > 0.0)))
    {
      double a = prev_th, b = th, ha = prev_h;
      for (int it = 0; it < 60; ++it)
      {
        const double mid = 0.5 * (a + b);
        if (!state(mid, ln, u))
          break;
        const double hm = cross(mid, u);
        if ((hm > 0.0) == (ha > 0.0))
        {
          a = mid;
          ha = hm;
        }
        else
          b = mid;
      }
      const double th0 = 0.5 * (a + b);
      if (state(th0, ln, u) && ln > 0.0)
      {
        // u_t must oppose the friction direction (the other root is the wrong branch).
        const double dot = u[1] * std::cos(th0) + u[2] * std::sin(th0);
        if (dot <= 0.0 && std::abs(cross(th0, u)) < best)
        {
          best = std::abs(cross(th0, u));
          lam = Vec3(ln, mu * ln * std::cos(th0), mu * ln * std::sin(th0));
        }
      }
    }
    prev_th = th;
    prev_h = h;
    prev_ok = ok;
  }
  return std::isfinite(best);
}

/// @brief The crushing candidates of one pair, λ_n = cap and u_n ≤ 0 (problem.hpp): the
/// tangential force with the normal one fixed, stick (u_t = 0) inside the disc, or in 2D
/// slip on its rim against u_t. False if none of them holds; 3D slip is left to the caller.
bool crushed_solve(const Mat3& A, const Vec3& c, double mu, int d, double cap, Vec3& lam)
{
  auto un = [&](const Vec3& l) { return A.row(0).dot(l) + c[0]; };
  Vec3 l(cap, 0.0, 0.0);
  if (mu == 0.0)
  {
    if (un(l) <= 0.0)
    {
      lam = l;
      return true;
    }
    return false;
  }
  // Stick: A_tt λ_t = −(A_tn cap + c_t).
  const Eigen::Vector2d bt(A(1, 0) * cap + c[1], A(2, 0) * cap + c[2]);
  Eigen::Matrix2d Att = A.block<2, 2>(1, 1);
  if (d == 2)
    Att(1, 1) = A(1, 1) > 0.0 ? A(1, 1) : 1.0;
  const Eigen::FullPivLU<Eigen::Matrix2d> lu(Att);
  if (lu.isInvertible())
  {
    Eigen::Vector2d lt = lu.solve(-bt);
    if (d == 2)
      lt[1] = 0.0;
    l = Vec3(cap, lt[0], lt[1]);
    if (l.allFinite() && tnorm(l, d) <= mu * cap && un(l) <= 0.0)
    {
      lam = l;
      return true;
    }
  }
  if (d == 3)
    return false;
  for (double sg : {1.0, -1.0})
  {
    l = Vec3(cap, -mu * sg * cap, 0.0);
    const double ut = A(1, 0) * l[0] + A(1, 1) * l[1] + c[1];
    if (sg * ut >= 0.0 && un(l) <= 0.0)
    {
      lam = l;
      return true;
    }
  }
  return false;
}

/// @brief Exact solution of one pair's problem u = A λ + c (A the pair's diagonal block of W,
/// c the rest of u), with the normal force capped at `cap` (+∞: no cap). Returns false when
/// the block is too degenerate for every case.
bool local_solve(const Mat3& A, const Vec3& c, double mu, int d, Vec3& lam, double cap)
{
  // Open: with λ = 0 the pair does not penetrate.
  if (c[0] >= 0.0)
  {
    lam.setZero();
    return true;
  }
  const double ann = A(0, 0);
  if (!(ann > 0.0))
    return cap < std::numeric_limits<double>::infinity() && crushed_solve(A, c, mu, d, cap, lam);
  if (mu == 0.0)
  {
    // Frictionless: λ_t = 0, and the normal row alone closes the gap (or crushes).
    lam.setZero();
    lam[0] = -c[0] / ann;
    if (lam[0] > cap)
      lam[0] = cap;
    return true;
  }
  // Stick: u = 0.
  {
    // Fixed-size LU (A's row and column 2 are zero in 2D: solve with a unit there).
    Mat3 As = A;
    if (d == 2)
      As(2, 2) = A(0, 0); // on the block's scale: FullPivLU's rank threshold is relative
    const Eigen::FullPivLU<Mat3> lu(As);
    if (lu.isInvertible())
    {
      Vec3 s = lu.solve(-c);
      s[2] = d == 2 ? 0.0 : s[2];
      if (s.allFinite() && s[0] >= 0.0 && tnorm(s, d) <= mu * s[0] && !(s[0] > cap))
      {
        lam = s;
        return true;
      }
    }
  }
  if (d == 2)
  {
    // Slip with λ_t = −μ σ λ_n: u_n = 0 fixes λ_n; σ must be the sign of the slip u_t.
    for (double sg : {1.0, -1.0})
    {
      const double den = ann - mu * sg * A(0, 1);
      if (!(den > 0.0))
        continue;
      const double ln = -c[0] / den;
      const double lt = -mu * sg * ln;
      const double ut = A(1, 0) * ln + A(1, 1) * lt + c[1];
      if (sg * ut >= 0.0 && !(ln > cap))
      {
        lam = Vec3(ln, lt, 0.0);
        return true;
      }
    }
    return cap < std::numeric_limits<double>::infinity() && crushed_solve(A, c, mu, d, cap, lam);
  }
  if (cap < std::numeric_limits<double>::infinity() && crushed_solve(A, c, mu, d, cap, lam))
    return true;
  // 3D slip: the direction is unknown; local Newton, warm then from the stick guess projected.
  Vec3 l0 = lam;
  if (local_newton(A, c, mu, d, l0, cap))
  {
    lam = l0;
    return true;
  }
  l0.setZero();
  l0[0] = std::min(-c[0] / ann, cap);
  if (local_newton(A, c, mu, d, l0, cap))
  {
    lam = l0;
    return true;
  }
  // The angle scan knows no cap: its answer counts only within it.
  Vec3 ls = lam;
  if (slip_by_angle(A, c, mu, ls) && !(ls[0] > cap))
  {
    lam = ls;
    return true;
  }
  return false;
}
} // namespace

int detail::nsgs_sweep(const ProblemView& p, const Vector& rho, Vector& lam, Vector& u)
{
  const int d = p.dim;
  int fallbacks = 0;
  Mat3 A;
  Vec3 c, l, delta;
  for (int k = 0; k < p.pairs(); ++k)
  {
    const int o = k * d;
    A.setZero();
    c.setZero();
    l.setZero();
    A.topLeftCorner(d, d) = p.W.block(o, o, d, d);
    l.head(d) = lam.segment(o, d);
    c.head(d) = u.segment(o, d) - A.topLeftCorner(d, d) * l.head(d);
    Vec3 lnew = l;
    if (!local_solve(A, c, p.mu[k], d, lnew, p.cap_of(k)))
    {
      // Degenerate block: the De Saxcé–Feng step with the problem's ρ.
      ++fallbacks;
      Vec3 uk = Vec3::Zero();
      uk.head(d) = u.segment(o, d);
      lnew = l - rho[k] * uk;
      lnew[0] = l[0] - rho[k] * (uk[0] + p.mu[k] * tnorm(uk, d));
      project_on_truncated_cone(lnew.data(), d, p.mu[k], p.cap_of(k));
    }
    delta = lnew - l;
    if (delta.squaredNorm() > 0.0)
    {
      // Column by column: a dynamic-size view of the fixed 3-vector trips GCC 12's
      // -Warray-bounds inside Eigen's vectorised product.
      for (int i = 0; i < d; ++i)
      {
        lam[o + i] = lnew[i];
        if (delta[i] != 0.0)
          u += delta[i] * p.W.col(o + i);
      }
    }
  }
  return fallbacks;
}

SolveReport solve_projection(const ProblemView& p, const Eigen::Ref<const Vector>& lambda0,
                             const SolverOptions& opt)
{
  detail::check_problem(p, lambda0, "solve_projection");
  const int d = p.dim;
  const int m = p.pairs();
  const int n = m * d;
  const Vector rho = pair_rho(p);
  const long max_sweeps = 50L * std::max(opt.max_iterations, 0);

  SolveReport rep;
  rep.solver = "projection";
  Vector lam = lambda0.size() ? Vector(lambda0) : Vector::Zero(n);
  Vector u = p.W * lam + p.q;
  double res = natural_map_residual(p, lam, u, rho);
  long sweep = 0;
  int fallbacks = 0;
  std::string why;
  detail::WorkMeter work(opt.work_budget_gflop);
  while (res > opt.tolerance && sweep < max_sweeps)
  {
    if (work.spent())
    {
      why = ", work budget spent";
      break;
    }
    ++sweep;
    // A sweep passes once over W's columns (u += δ W_j for each unknown that moved).
    work.charge(detail::product_flops(n));
    fallbacks += detail::nsgs_sweep(p, rho, lam, u);
    if (!lam.allFinite())
    {
      why = ", non-finite iterate";
      break;
    }
    res = natural_map_residual(p, lam, u, rho);
    // Confirm with a fresh u: the running update drifts by rounding over many sweeps.
    if (res <= opt.tolerance || sweep % 50 == 0)
    {
      u.noalias() = p.W * lam + p.q;
      res = natural_map_residual(p, lam, u, rho);
    }
    if (opt.verbose)
      std::fprintf(stderr, "projection sweep %ld: residual %.3e\n", sweep, res);
  }

  rep.iterations = static_cast<int>(sweep);
  rep.lambda = lam.allFinite() ? lam : Vector(Vector::Zero(n));
  rep.u = p.W * rep.lambda + p.q;
  rep.residual = natural_map_residual(p, rep.lambda);
  rep.converged = rep.residual <= opt.tolerance;
  rep.states = classify_states(p, rep.lambda, rep.u);
  rep.work_gflop = work.used_gflop();
  if (fallbacks > 0)
    why += ", " + std::to_string(fallbacks) + " degenerate local solves";
  rep.attempts.push_back("projection: " + std::string(rep.converged ? "converged" : "not converged")
                         + " in " + std::to_string(sweep) + " sweeps, residual "
                         + std::to_string(rep.residual) + why);
  return rep;
}
} // namespace flexcontact
