// Copyright flexcontact developers. MIT licence.

/// @file operator_solve.cpp
/// @brief The matrix-free local solver: an accelerated projected fixed point on the
/// De Saxcé cone map that needs only W·x (operator_contact.hpp).

#include "flexcontact/operator_contact.hpp"
#include "flexcontact/residual.hpp"

#include <cmath>
#include <cstdio>
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

void project_all(Vector& lambda, int dim, const Eigen::Ref<const Vector>& mu)
{
  for (Eigen::Index k = 0; k < mu.size(); ++k)
    project_on_cone(lambda.data() + k * dim, dim, mu[k]);
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
                                 const Eigen::Ref<const Vector>& q, int dim, double tol = 1e-8)
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
    const double ut = tangent_norm(u.data() + k * dim, dim);
    s[static_cast<std::size_t>(k)] = ut > tol * uscale ? PairState::slip : PairState::stick;
  }
  return s;
}

std::string sci(double v)
{
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
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
                           const Eigen::Ref<const Vector>& lambda0, const SolverOptions& opt)
{
  const Eigen::Index n = q.size();
  const int m = static_cast<int>(n / dim);
  const Matrix none(0, 0); // the four-argument residual does not read W
  const ProblemView view{dim, none, q, mu};
  const double wbar = scales.mean_normal > 0.0 ? scales.mean_normal : scales.lipschitz;
  const Vector rho = Vector::Constant(m, wbar > 0.0 ? 1.0 / wbar : 1.0);
  const double step = scales.lipschitz > 0.0 ? 1.0 / scales.lipschitz : 1.0;

  SolveReport best;
  best.solver = "operator";
  Vector lam = lambda0.size() == n ? Vector(lambda0) : Vector::Zero(n);
  project_all(lam, dim, mu);
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
  const int cap = 100 * opt.max_iterations;
  while (best.residual >= opt.tolerance && it < cap)
  {
    ++it;
    Vector z = y - step * de_saxce(uy, dim, mu);
    project_all(z, dim, mu);
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
  best.states = states_of(best.lambda, best.u, q, dim);
  best.attempts.push_back("operator: " + std::to_string(it) + " iterations, "
                          + std::to_string(restarts) + " restarts, residual " + sci(best.residual)
                          + (best.converged ? " (converged)" : " (not converged)"));
  return best;
}
} // namespace flexcontact
