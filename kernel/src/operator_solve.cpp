// Copyright flexcontact developers. MIT licence.

/// @file operator_solve.cpp
/// @brief The matrix-free local solver: an accelerated projected fixed point on the
/// De Saxcé cone map that needs only W·x (operator_contact.hpp).

#include "flexcontact/operator_contact.hpp"
#include "flexcontact/residual.hpp"
#include "flexcontact/solvers.hpp"
#include "message_numbers.hpp"
#include "pair_columns.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>

namespace flexcontact
{
namespace
{
double tangent_norm(const double* r, int dim)
{
  return dim == 2 ? std::abs(r[1]) : std::hypot(r[1], r[2]);
}

void project_all(Vector& lambda, int dim, const Eigen::Ref<const Vector>& mu, const Vector& cap)
{
  for (Eigen::Index k = 0; k < mu.size(); ++k)
    project_on_truncated_cone(lambda.data() + k * dim, dim, mu[k],
                              cap.size() ? cap[k] : std::numeric_limits<double>::infinity());
}

/// @brief The De Saxcé modified velocity û = (u_n + μ|u_t|, u_t): its fixed point
/// λ = P_K(λ − ρ û) is the Coulomb law, not its associated (convex) relaxation.
Vector de_saxce(const Vector& u, int dim, const Eigen::Ref<const Vector>& mu)
{
  Vector v = u;
  for (Eigen::Index k = 0; k < mu.size(); ++k)
    v[k * dim] += mu[k] * tangent_norm(u.data() + k * dim, dim);
  return v;
}

/// @brief States read from (λ, u) as classify_states (residual.hpp) does, without W.
std::vector<PairState> states_of(const Vector& lambda, const Vector& u,
                                 const Eigen::Ref<const Vector>& q, int dim, const Vector& cap,
                                 double tol = 1e-8)
{
  const Eigen::Index m = q.size() / dim;
  const double lscale = lambda.size() ? lambda.cwiseAbs().maxCoeff() : 0.0;
  const double uscale = u.size() ? std::max(u.cwiseAbs().maxCoeff(), q.cwiseAbs().maxCoeff())
                                 : 0.0;
  std::vector<PairState> s(static_cast<std::size_t>(m), PairState::open);
  for (Eigen::Index k = 0; k < m; ++k)
  {
    if (!(lambda[k * dim] > tol * lscale) || lscale == 0.0)
      continue;
    if (cap.size() && lambda[k * dim] >= (1.0 - tol) * cap[k])
    {
      s[static_cast<std::size_t>(k)] = PairState::crush;
      continue;
    }
    const double ut = tangent_norm(u.data() + k * dim, dim);
    s[static_cast<std::size_t>(k)] = ut > tol * uscale ? PairState::slip : PairState::stick;
  }
  return s;
}

/// @brief The pairs that start the working set: those penetrating under q alone, and those
/// that carried a force in λ0 (their columns give u at the warm start).
std::vector<int> initial_set(const Eigen::Ref<const Vector>& q, const Vector& lam, int d)
{
  std::vector<int> A;
  for (Eigen::Index k = 0; k < q.size() / d; ++k)
    if (q[k * d] < 0.0 || lam[k * d] > 0.0)
      A.push_back(static_cast<int>(k));
  return A;
}

/// @brief The problem restricted to the set A, from the full λ and states.
struct Restricted
{
  Matrix W;
  Vector q, mu, lambda, cap;
  std::vector<PairState> states;
};

Restricted restrict_to(const PairColumns& c, const std::vector<int>& A, int d,
                       const Eigen::Ref<const Vector>& q, const Eigen::Ref<const Vector>& mu,
                       const Vector& lam, const std::vector<PairState>& states0,
                       const Vector& cap)
{
  Restricted r;
  if (cap.size())
  {
    r.cap.resize(static_cast<Eigen::Index>(A.size()));
    for (std::size_t a = 0; a < A.size(); ++a)
      r.cap[static_cast<Eigen::Index>(a)] = cap[A[a]];
  }
  r.W = detail::restricted_W(c, A, d);
  const Eigen::Index n = static_cast<Eigen::Index>(A.size()) * d;
  r.q.resize(n);
  r.lambda.resize(n);
  r.mu.resize(static_cast<Eigen::Index>(A.size()));
  for (std::size_t a = 0; a < A.size(); ++a)
  {
    const Eigen::Index i = static_cast<Eigen::Index>(a) * d, k = A[a] * d;
    r.q.segment(i, d) = q.segment(k, d);
    r.lambda.segment(i, d) = lam.segment(k, d);
    r.mu[static_cast<Eigen::Index>(a)] = mu[A[a]];
    if (states0.size() * d == static_cast<std::size_t>(q.size()))
      r.states.push_back(states0[static_cast<std::size_t>(A[a])]);
  }
  return r;
}
} // namespace

OperatorScales operator_scales(const LinearOperator& W, int dim, int pairs)
{
  const Eigen::Index n = static_cast<Eigen::Index>(pairs) * dim;
  OperatorScales s;
  if (n == 0)
    return s;
  // Power iteration from a fixed, non-symmetric start (it has a component on the top mode).
  Vector v(n);
  for (Eigen::Index i = 0; i < n; ++i)
    v[i] = 1.0 + 0.5 * std::sin(1.0 + 0.37 * static_cast<double>(i));
  v.normalize();
  double rayleigh = 0.0;
  for (int it = 0; it < 30; ++it)
  {
    Vector w = W(v);
    ++s.applications;
    rayleigh = v.dot(w);
    const double norm = w.norm();
    if (!(norm > 0.0))
      break;
    v = w / norm;
  }
  // The Rayleigh quotient approaches λ_max from below: the margin keeps the step stable.
  s.lipschitz = 1.1 * std::max(rayleigh, 0.0);
  // Hutchinson on the normal rows: E[z_n (W z)_n] = W_nn for Rademacher z on normal rows.
  std::mt19937 gen(20241);
  std::bernoulli_distribution coin(0.5);
  const int probes = 8;
  double sum = 0.0;
  for (int p = 0; p < probes; ++p)
  {
    Vector z = Vector::Zero(n);
    for (int k = 0; k < pairs; ++k)
      z[static_cast<Eigen::Index>(k) * dim] = coin(gen) ? 1.0 : -1.0;
    const Vector w = W(z);
    ++s.applications;
    for (int k = 0; k < pairs; ++k)
      sum += z[static_cast<Eigen::Index>(k) * dim] * w[static_cast<Eigen::Index>(k) * dim];
  }
  s.mean_normal = sum / (probes * static_cast<double>(pairs));
  return s;
}

SolveReport solve_operator(int dim, const LinearOperator& W, const OperatorScales& scales,
                           const Eigen::Ref<const Vector>& q, const Eigen::Ref<const Vector>& mu,
                           const Eigen::Ref<const Vector>& lambda0, const SolverOptions& opt,
                           const Vector& cap)
{
  const Eigen::Index n = q.size();
  const int m = static_cast<int>(n / dim);
  const Matrix none(0, 0); // the four-argument residual does not read W
  const ProblemView view{dim, none, q, mu, cap.size() ? cap.data() : nullptr};
  const double wbar = scales.mean_normal > 0.0 ? scales.mean_normal : scales.lipschitz;
  const Vector rho = Vector::Constant(m, wbar > 0.0 ? 1.0 / wbar : 1.0);
  const double step = scales.lipschitz > 0.0 ? 1.0 / scales.lipschitz : 1.0;

  SolveReport best;
  best.solver = "operator";
  Vector lam = lambda0.size() == n ? Vector(lambda0) : Vector::Zero(n);
  project_all(lam, dim, mu, cap);
  Vector u = W(lam) + q;
  auto keep = [&](const Vector& l, const Vector& ul, double res, int it)
  {
    if (res < best.residual || !std::isfinite(best.residual))
    {
      best.lambda = l;
      best.u = ul;
      best.residual = res;
      best.iterations = it;
    }
  };
  keep(lam, u, natural_map_residual(view, lam, u, rho), 0);
  Vector y = lam, uy = u;
  double theta = 1.0;
  int restarts = 0, it = 0;
  const int max_it = 100 * opt.max_iterations;
  while (best.residual >= opt.tolerance && it < max_it)
  {
    ++it;
    Vector z = y - step * de_saxce(uy, dim, mu);
    project_all(z, dim, mu, cap);
    Vector uz = W(z) + q;
    const double res = natural_map_residual(view, z, uz, rho);
    if (!std::isfinite(res))
      break;
    keep(z, uz, res, it);
    if ((y - z).dot(z - lam) > 0.0)
    {
      // The extrapolation overshot: restart the momentum (O'Donoghue and Candès).
      theta = 1.0;
      y = z;
      uy = uz;
      ++restarts;
    }
    else
    {
      const double next = 0.5 * (1.0 + std::sqrt(1.0 + 4.0 * theta * theta));
      const double beta = (theta - 1.0) / next;
      y = z + beta * (z - lam);
      uy = uz + beta * (uz - u); // W y + q by linearity: no extra product
      theta = next;
    }
    lam = std::move(z);
    u = std::move(uz);
    if (opt.verbose)
      std::fprintf(stderr, "operator it %d residual %.3e\n", it, res);
  }
  best.converged = best.residual < opt.tolerance;
  best.states = states_of(best.lambda, best.u, q, dim, cap);
  best.attempts.push_back("operator: " + std::to_string(it) + " iterations, "
                          + std::to_string(restarts) + " restarts, residual " + detail::exp3(best.residual)
                          + (best.converged ? " (converged)" : " (not converged)"));
  return best;
}

SolveReport solve_working_set(int dim, const PairColumns& columns, const FetchColumns& fetch,
                              const Eigen::Ref<const Vector>& q,
                              const Eigen::Ref<const Vector>& mu,
                              const Eigen::Ref<const Vector>& lambda0,
                              const std::vector<PairState>& states0, const SolverOptions& opt,
                              const SameOnAllRanks& same, const Vector& cap)
{
  const Eigen::Index n = q.size();
  const int m = static_cast<int>(n / dim);
  SolveReport out;
  out.solver = "working_set";
  Vector lam = lambda0.size() == n ? Vector(lambda0) : Vector::Zero(n);
  std::vector<int> A = initial_set(q, lam, dim);
  std::vector<char> in(static_cast<std::size_t>(m), 0);
  for (int k : A)
    in[static_cast<std::size_t>(k)] = 1;
  out.lambda = Vector::Zero(n);
  for (int k : A) // λ0 outside the set has no columns to act through: dropped
    out.lambda.segment(k * dim, dim) = lam.segment(k * dim, dim);
  const int max_rounds = 50;
  int inner = 0;
  for (int round = 1; round <= max_rounds; ++round)
  {
    if (A.empty())
    {
      // Nothing penetrates and nothing carried a force: λ = 0 is the answer.
      out.u = q;
      out.residual = 0.0;
      out.converged = true;
      out.states.assign(static_cast<std::size_t>(m), PairState::open);
      out.attempts.push_back("working_set: no pair penetrates (converged)");
      return out;
    }
    std::sort(A.begin(), A.end());
    if (!fetch(A))
    {
      out.attempts.push_back("working_set: " + std::to_string(A.size())
                             + " pairs pass the memory allowed for W's columns");
      return out;
    }
    const Restricted r = restrict_to(columns, A, dim, q, mu, out.lambda, states0, cap);
    const SolveReport rep = solve(
        ProblemView{dim, r.W, r.q, r.mu, r.cap.size() ? r.cap.data() : nullptr}, r.lambda,
        r.states, opt);
    inner += rep.iterations;
    // The chain is budgeted in work, so equal data give equal outcomes; the ranks still
    // compare before the collective solves that follow, which must not part ways.
    if (same)
      same(rep.converged ? static_cast<long>(A.size()) : -1L);
    out.lambda.setZero();
    for (std::size_t a = 0; a < A.size(); ++a)
      out.lambda.segment(A[a] * dim, dim) = rep.lambda.segment(static_cast<Eigen::Index>(a) * dim, dim);
    out.iterations = round;
    if (!rep.converged)
    {
      out.residual = rep.residual;
      out.attempts.push_back("working_set: round " + std::to_string(round) + ", "
                             + std::to_string(A.size()) + " pairs: the chain did not converge ("
                             + (rep.attempts.empty() ? rep.solver : rep.attempts.back()) + ")");
      return out;
    }
    Vector u = detail::full_u(columns, A, rep.lambda, q, dim);
    for (std::size_t a = 0; a < A.size(); ++a) // the restricted solve's own u: its residual
      u.segment(A[a] * dim, dim) = rep.u.segment(static_cast<Eigen::Index>(a) * dim, dim);
    const std::size_t before = A.size();
    for (int k = 0; k < m; ++k)
      if (!in[static_cast<std::size_t>(k)] && u[k * dim] < 0.0)
      {
        in[static_cast<std::size_t>(k)] = 1;
        A.push_back(k);
      }
    if (same)
      same(static_cast<long>(A.size()));
    if (A.size() == before)
    {
      out.u = std::move(u);
      out.residual = rep.residual; // bounds the whole problem's: see the header
      out.converged = true;
      out.states = states_of(out.lambda, out.u, q, dim, cap);
      out.attempts.push_back("working_set: " + std::to_string(round) + " rounds, "
                             + std::to_string(A.size()) + " of " + std::to_string(m)
                             + " pairs, " + rep.solver + " " + std::to_string(inner)
                             + " iterations in all, residual " + detail::exp3(rep.residual)
                             + " (converged)");
      return out;
    }
  }
  out.attempts.push_back("working_set: still growing after " + std::to_string(max_rounds)
                         + " rounds (" + std::to_string(A.size()) + " pairs)");
  return out;
}
} // namespace flexcontact
