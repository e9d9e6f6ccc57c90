// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file contact_testing.hpp
/// @brief Test helpers: random SPD Delassus matrices, an independent check of the
/// Signorini–Coulomb laws (so that tests do not trust any solver's own stopping test), and
/// the small builders and hand-solved problems that several test files share.

#include "flexcontact/pairs.hpp"
#include "flexcontact/problem.hpp"
#include "flexcontact/residual.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <functional>
#include <initializer_list>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace flexcontact::testing
{
/// @brief What f throws, as text ("" if it does not throw): tests assert on the words.
inline std::string message_of(const std::function<void()>& f)
{
  try
  {
    f();
  }
  catch (const std::exception& e)
  {
    return e.what();
  }
  return "";
}

/// @brief A vector written out in place, so that hand-derived values read as in the
/// derivation next to them.
inline Vector vec(std::initializer_list<double> v)
{
  Vector x(static_cast<Eigen::Index>(v.size()));
  Eigen::Index i = 0;
  for (double a : v)
    x[i++] = a;
  return x;
}

/// @brief A pair with the frame of normal n.
inline ContactPair make_pair(int slave, std::vector<int> masters, std::vector<double> weights,
                             const Vector& n)
{
  ContactPair c;
  c.slave = slave;
  c.masters = std::move(masters);
  c.weights = std::move(weights);
  c.frame = frame_from_normal(n);
  return c;
}

/// @brief Default options except for the solver chain.
inline SolverOptions chain_of(std::vector<std::string> names)
{
  SolverOptions o;
  o.chain = std::move(names);
  return o;
}

/// @brief Two coupled pairs (μ = 1/2) on which the active set cycles
/// (stick, stick) → (slip, slip) → (open, stick) → (stick, stick). The answer is pair 0
/// slipping, pair 1 sticking: u_n0 = u_n1 = u_t1 = 0 with λ_t0 = −λ_n0/2 gives
/// λ = (1/15, −1/30, 53/150, 4/25) and the slip u_t0 = 106/25 > 0 (along s = +1, against
/// λ_t0 < 0); pair 1 sticks since |λ_t1| = 4/25 < μ λ_n1 = 53/300.
struct CyclingPairs
{
  Matrix W = (Matrix(4, 4) << 15.0, -12.0, -6.0, -8.0, //
              -12.0, 15.0, 3.0, 3.0,                    //
              -6.0, 3.0, 15.0, -5.0,                    //
              -8.0, 3.0, -5.0, 15.0)
                 .finished();
  Vector q = vec({2.0, 4.0, -4.0, 0.0});
  Vector mu = vec({0.5, 0.5});
};

/// @brief Three decoupled 3D pairs (W = 2I, μ = 0.4) that come out open, stick and slip:
/// q_n0 > 0 opens pair 0; pair 1 sticks with λ = −q/2, |λ_t| ≈ .07 < μλ_n = .2; pair 2's
/// stick force |λ_t| = .25 is outside the cone, so it slips with λ_t = −.2 (.6, .8).
struct OpenStickSlipPairs
{
  Matrix W = 2.0 * Matrix::Identity(9, 9);
  Vector q = vec({1.0, 0.2, 0.0, -1.0, 0.1, 0.1, -1.0, 0.3, 0.4});
  Vector mu = vec({0.4, 0.4, 0.4});
  Vector lambda = vec({0.0, 0.0, 0.0, 0.5, -0.05, -0.05, 0.5, -0.12, -0.16});
};

/// @brief Random SPD n×n matrix with eigenvalues log-spaced in [1/cond, 1]·scale, rotated by
/// a product of random Householder reflections (O(n²) each, dense result).
inline Matrix random_spd(int n, double cond, unsigned seed, double scale = 1.0,
                         int reflections = 6)
{
  std::mt19937 gen(seed);
  std::normal_distribution<double> N(0.0, 1.0);
  Matrix W = Matrix::Zero(n, n);
  for (int i = 0; i < n; ++i)
  {
    const double t = n > 1 ? static_cast<double>(i) / (n - 1) : 0.0;
    W(i, i) = scale * std::pow(cond, -t);
  }
  // Shuffle the spectrum so that small eigenvalues are not tied to the last pairs.
  std::vector<int> perm(n);
  for (int i = 0; i < n; ++i)
    perm[i] = i;
  std::shuffle(perm.begin(), perm.end(), gen);
  Vector diag = W.diagonal();
  for (int i = 0; i < n; ++i)
    W(i, i) = diag[perm[i]];
  for (int r = 0; r < reflections; ++r)
  {
    Vector v(n);
    for (int i = 0; i < n; ++i)
      v[i] = N(gen);
    v /= v.norm();
    // W ← H W H with H = I − 2 v vᵀ
    const Vector Wv = W * v;
    const double vWv = v.dot(Wv);
    W -= 2.0 * (Wv * v.transpose() + v * Wv.transpose());
    W += 4.0 * vWv * (v * v.transpose());
  }
  return 0.5 * (W + W.transpose());
}

/// @brief Empty if (λ, u = Wλ + q) satisfies Signorini and Coulomb (with the normal force
/// caps of p, where a pair at its cap may crush, u_n ≤ 0) to tol, in force units
/// (ρ u with ρ = pair_rho), relative to S = max(‖λ‖, ‖ρ q‖); otherwise what fails, and where.
inline std::string check_laws(const ProblemView& p, const Vector& lambda, double tol)
{
  std::ostringstream err;
  if (!lambda.allFinite())
    return "lambda not finite";
  const int d = p.dim;
  const Vector u = p.W * lambda + p.q;
  const Vector rho = pair_rho(p);
  Vector rq(p.q.size());
  for (int k = 0; k < p.pairs(); ++k)
    rq.segment(k * d, d) = rho[k] * p.q.segment(k * d, d);
  const double S = std::max({lambda.norm(), rq.norm(), 1e-300});
  for (int k = 0; k < p.pairs(); ++k)
  {
    const double mu = p.mu[k];
    const double ln = lambda[k * d];
    const Vector lt = lambda.segment(k * d + 1, d - 1);
    const double un = rho[k] * u[k * d];
    const Vector ut = rho[k] * u.segment(k * d + 1, d - 1);
    const double cap = p.cap_of(k);
    if (ln < -tol * S)
      err << "pair " << k << ": lambda_n = " << ln << " < 0; ";
    if (ln > cap + tol * S)
      err << "pair " << k << ": lambda_n = " << ln << " above its cap " << cap << "; ";
    if (ln >= cap - tol * S)
    {
      // At the cap the surface may crush (u_n ≤ 0) but not separate.
      if (un > tol * S)
        err << "pair " << k << ": at its cap and separating, rho*u_n = " << un << "; ";
    }
    else
    {
      if (un < -tol * S)
        err << "pair " << k << ": penetration rho*u_n = " << un << "; ";
      if (std::abs(ln * un) > tol * S * std::max(S, std::abs(un)))
        err << "pair " << k << ": complementarity lambda_n*rho*u_n = " << ln * un << "; ";
    }
    if (lt.norm() > mu * ln + tol * S)
      err << "pair " << k << ": outside cone |lambda_t| = " << lt.norm() << " > mu lambda_n = "
          << mu * ln << "; ";
    // Maximal dissipation: λ_t |u_t| = −μ λ_n u_t; holds trivially for stick (u_t = 0).
    const double dis = (lt * ut.norm() + mu * ln * ut).norm();
    if (dis > tol * S * std::max(S, ut.norm()))
      err << "pair " << k << ": slip not opposed by mu lambda_n (" << dis << "); ";
  }
  return err.str();
}
} // namespace flexcontact::testing

namespace flexcontact::testing
{
/// @brief A single-pair problem with its exact, hand-derived answer.
struct ExactCase
{
  std::string name;
  int dim;
  Matrix W;
  Vector q, mu, lambda;
};

/// @brief Open, stick and slip pairs in 2D and 3D, with normal–tangent coupling.
///
/// 2D: W = [[2, .5], [.5, 1]], q = (−1, .1). Stick λ = −W⁻¹q = (.6, −.4), in the cone for
/// μ = 1. For μ = .5 slip with λ_t = −μλ_n (u_t > 0): λ_n = 1/(2 − .25) = 4/7, λ_t = −2/7,
/// u_t = .5·4/7 − 2/7 + .1 = .1 > 0. 3D: the same embedded and rotated by θ in the tangent
/// plane (cone and law are invariant), and the isotropic W = 2I with q = (−1, .3, .4),
/// μ = .4: λ_n = .5, λ_t = −μλ_n q_t/|q_t| = (−.12, −.16).
inline std::vector<ExactCase> exact_cases()
{
  std::vector<ExactCase> c;
  Matrix W2(2, 2);
  W2 << 2.0, 0.5, 0.5, 1.0;
  c.push_back({"2d_open", 2, W2, vec({1.0, 0.3}), vec({0.5}), vec({0.0, 0.0})});
  c.push_back({"2d_stick", 2, W2, vec({-1.0, 0.1}), vec({1.0}), vec({0.6, -0.4})});
  c.push_back({"2d_slip", 2, W2, vec({-1.0, 0.1}), vec({0.5}), vec({4.0 / 7, -2.0 / 7})});
  // q_t < 0: stick λ = (.95, −.3)/1.75 is inside the cone for μ = .5 …
  c.push_back({"2d_stick_neg", 2, W2, vec({-1.0, -0.1}), vec({0.5}),
               vec({0.95 / 1.75, -0.3 / 1.75})});
  // … and for q = (−1, −.5), μ = .2 it slips backwards: λ_t = +μλ_n, λ_n = 1/(2 + .1),
  // u_t = .5/2.1 + .2/2.1 − .5 = −1/6 < 0.
  c.push_back({"2d_slip_neg", 2, W2, vec({-1.0, -0.5}), vec({0.2}),
               vec({1.0 / 2.1, 0.2 / 2.1})});
  c.push_back({"2d_frictionless", 2, W2, vec({-1.0, 0.1}), vec({0.0}), vec({0.5, 0.0})});
  Matrix W3 = Matrix::Zero(3, 3);
  W3.topLeftCorner(2, 2) = W2;
  W3(2, 2) = 1.0;
  for (double th : {0.0, 0.7, 2.5})
  {
    Matrix R = Matrix::Identity(3, 3);
    R(1, 1) = std::cos(th);
    R(1, 2) = -std::sin(th);
    R(2, 1) = std::sin(th);
    R(2, 2) = std::cos(th);
    const Matrix W = R * W3 * R.transpose();
    const std::string t = std::to_string(th);
    c.push_back({"3d_stick_" + t, 3, W, R * vec({-1.0, 0.1, 0.0}), vec({1.0}),
                 R * vec({0.6, -0.4, 0.0})});
    c.push_back({"3d_slip_" + t, 3, W, R * vec({-1.0, 0.1, 0.0}), vec({0.5}),
                 R * vec({4.0 / 7, -2.0 / 7, 0.0})});
  }
  const Matrix I2 = 2.0 * Matrix::Identity(3, 3);
  c.push_back({"3d_open", 3, I2, vec({0.5, 0.3, 0.4}), vec({0.4}), vec({0.0, 0.0, 0.0})});
  c.push_back({"3d_slip_iso", 3, I2, vec({-1.0, 0.3, 0.4}), vec({0.4}), vec({0.5, -0.12, -0.16})});
  c.push_back({"3d_stick_iso", 3, I2, vec({-1.0, 0.3, 0.4}), vec({1.0}), vec({0.5, -0.15, -0.2})});
  return c;
}
} // namespace flexcontact::testing
