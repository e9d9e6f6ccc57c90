// Copyright flexcontact developers. MIT licence.

/// @file residual.cpp
/// @brief Coulomb cone projection, natural-map residual and state classification.

#include "flexcontact/residual.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace flexcontact
{
namespace
{
/// @brief Euclidean norm of the tangential part of one pair (d − 1 values).
double tangent_norm(const double* r, int dim)
{
  return dim == 2 ? std::abs(r[1]) : std::hypot(r[1], r[2]);
}

/// @brief Throws if dim is not 2 or 3 or the sizes of the view disagree.
void check_view(const ProblemView& p)
{
  if (p.dim != 2 && p.dim != 3)
    throw std::invalid_argument("flexcontact: dim must be 2 or 3, got " + std::to_string(p.dim));
  const auto n = p.q.size();
  if (n % p.dim != 0 || p.W.rows() != n || p.W.cols() != n || p.mu.size() != n / p.dim)
    throw std::invalid_argument(
        "flexcontact: problem sizes disagree (q " + std::to_string(n) + ", W "
        + std::to_string(p.W.rows()) + "x" + std::to_string(p.W.cols()) + ", mu "
        + std::to_string(p.mu.size()) + ", dim " + std::to_string(p.dim) + ")");
}
} // namespace

void project_on_cone(double* r, int dim, double mu)
{
  const double rn = r[0];
  const double rt = tangent_norm(r, dim);
  // rn ≥ 0 matters for μ = 0: rt = 0 ≤ 0·rn would otherwise accept a tensile normal force.
  if (rn >= 0.0 && rt <= mu * rn)
    return; // inside, including the apex
  if (mu * rt <= -rn)
  {
    // polar cone: the closest point is the apex
    for (int i = 0; i < dim; ++i)
      r[i] = 0.0;
    return;
  }
  // Boundary: here rt > 0 (rt = 0 is inside for rn ≥ 0 and polar for rn ≤ 0).
  const double n = (rn + mu * rt) / (1.0 + mu * mu);
  const double s = mu * n / rt;
  r[0] = n;
  for (int i = 1; i < dim; ++i)
    r[i] *= s;
}

void project_on_truncated_cone(double* r, int dim, double mu, double cap)
{
  project_on_cone(r, dim, mu);
  if (!(r[0] > cap))
    return;
  // Beyond the cap the nearest point is on the cap's disc, (cap, P_disc(μ·cap)(z_t)). The
  // cone's answer has z's tangential direction and, when it left the cone, |z_t| > μ·cap
  // (else z_n > cap would put z inside): the disc's projection of it is the same point.
  const double rt = tangent_norm(r, dim);
  const double limit = mu * cap;
  r[0] = cap;
  if (rt > limit)
    for (int i = 1; i < dim; ++i)
      r[i] *= limit / rt;
}

Vector pair_rho(const ProblemView& p)
{
  check_view(p);
  const int m = p.pairs();
  double wmax = 0.0;
  for (Eigen::Index i = 0; i < p.W.rows(); ++i)
    if (std::isfinite(p.W(i, i)))
      wmax = std::max(wmax, p.W(i, i));
  // A pair whose normal compliance is zero or negligible (constrained DOFs) gets the
  // problem's stiffest-scale ρ; a zero W leaves no scale at all, so ρ = 1.
  const double floor = wmax > 0.0 ? 1e-12 * wmax : 0.0;
  const double rho_fallback = wmax > 0.0 ? 1.0 / wmax : 1.0;
  Vector rho(m);
  for (int k = 0; k < m; ++k)
  {
    const double w = p.W(k * p.dim, k * p.dim);
    rho[k] = (std::isfinite(w) && w > floor) ? 1.0 / w : rho_fallback;
  }
  return rho;
}

double natural_map_residual(const ProblemView& p, const Eigen::Ref<const Vector>& lambda)
{
  check_view(p);
  if (lambda.size() != p.q.size())
    throw std::invalid_argument("flexcontact: natural_map_residual: lambda has size "
                                + std::to_string(lambda.size()) + ", expected "
                                + std::to_string(p.q.size()));
  const Vector u = p.W * lambda + p.q;
  return natural_map_residual(p, lambda, u, pair_rho(p));
}

double natural_map_residual(const ProblemView& p, const Eigen::Ref<const Vector>& lambda,
                            const Eigen::Ref<const Vector>& u, const Eigen::Ref<const Vector>& rho)
{
  const int d = p.dim;
  const int m = p.pairs();
  if (lambda.size() != m * d || u.size() != m * d || rho.size() != m)
    throw std::invalid_argument("flexcontact: natural_map_residual: sizes of lambda ("
                                + std::to_string(lambda.size()) + "), u ("
                                + std::to_string(u.size()) + ") or rho ("
                                + std::to_string(rho.size()) + ") disagree with the problem");
  Vector e(m * d), rq(m * d);
  double z[3];
  for (int k = 0; k < m; ++k)
  {
    const double* uk = u.data() + k * d;
    const double mu = p.mu[k];
    const double unhat = uk[0] + mu * tangent_norm(uk, d);
    z[0] = lambda[k * d] - rho[k] * unhat;
    for (int i = 1; i < d; ++i)
      z[i] = lambda[k * d + i] - rho[k] * uk[i];
    project_on_truncated_cone(z, d, mu, p.cap_of(k));
    for (int i = 0; i < d; ++i)
    {
      e[k * d + i] = lambda[k * d + i] - z[i];
      rq[k * d + i] = rho[k] * p.q[k * d + i];
    }
  }
  // stableNorm: huge but finite input must not overflow into inf/inf = NaN.
  const double num = e.stableNorm();
  const double den = std::max({lambda.stableNorm(), rq.stableNorm(),
                               std::numeric_limits<double>::min()});
  if (!std::isfinite(num) || !std::isfinite(den))
    return std::numeric_limits<double>::infinity();
  return num / den;
}

std::vector<PairState> classify_states(const ProblemView& p,
                                       const Eigen::Ref<const Vector>& lambda,
                                       const Eigen::Ref<const Vector>& u, double tol)
{
  check_view(p);
  if (lambda.size() != p.q.size() || u.size() != p.q.size())
    throw std::invalid_argument("flexcontact: classify_states: lambda/u sizes "
                                + std::to_string(lambda.size()) + "/"
                                + std::to_string(u.size()) + " differ from q size "
                                + std::to_string(p.q.size()));
  const int d = p.dim;
  const int m = p.pairs();
  // Scales of the problem: a force scale for "λ_n is zero" and a length scale for
  // "u_t is zero", so that the classification does not depend on units.
  const double lscale = lambda.size() ? lambda.cwiseAbs().maxCoeff() : 0.0;
  double uscale = 0.0;
  if (u.size())
    uscale = std::max(u.cwiseAbs().maxCoeff(), p.q.cwiseAbs().maxCoeff());
  std::vector<PairState> s(m, PairState::open);
  for (int k = 0; k < m; ++k)
  {
    const double ln = lambda[k * d];
    if (!(ln > tol * lscale) || lscale == 0.0)
      continue; // open
    if (ln >= (1.0 - tol) * p.cap_of(k))
    {
      s[k] = PairState::crush;
      continue;
    }
    const double ut = tangent_norm(u.data() + k * d, d);
    s[k] = (ut > tol * uscale) ? PairState::slip : PairState::stick;
  }
  return s;
}
} // namespace flexcontact
