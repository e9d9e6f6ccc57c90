// Copyright flexcontact developers. MIT licence.

/// @file newton_step.cpp
/// @brief One step of the semi-smooth Alart–Curnier Newton: Φ and its generalised
/// Jacobian's blocks, the Newton direction, and the line searches that globalise it.

#include "newton_step.hpp"

#include "ac_pair.hpp"

#include <Eigen/LU>
#include <Eigen/QR>
#include <cmath>
#include <limits>

namespace flexcontact::detail
{
namespace
{
/// @brief A x = b by a pivoted LU; false unless x is finite and its residual within 1e-8
/// of ‖b‖.
bool lu_solve(const Matrix& A, const Vector& b, Vector& x)
{
  Eigen::PartialPivLU<Matrix> lu(A);
  x = lu.solve(b);
  return x.allFinite() && (A * x - b).norm() <= 1e-8 * std::max(b.norm(), 1e-300);
}

/// @brief Solve A x = b, pivoted LU first. A singular A (semi-definite W, fully constrained
/// pairs) gets the minimum-norm least-squares step instead: it moves nothing along the null
/// space, where an LU or a small regularisation would send λ off to huge values that the
/// relative residual then mistakes for convergence. Beyond a size where a rank-revealing
/// factorisation is too slow, a Tikhonov-regularised LU is the fallback. Returns false if
/// no finite solution was found.
bool linear_solve(const Matrix& A, const Vector& b, Vector& x)
{
  if (lu_solve(A, b, x))
    return true;
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

/// @brief A x = b by the LU of the rows keep only, the rows fixed being the identity's (x = b
/// there). False if that LU fails.
bool reduced_solve(const Matrix& A, const Vector& b, const std::vector<Eigen::Index>& keep,
                   const std::vector<Eigen::Index>& fixed, Vector& x)
{
  x = b;
  if (!keep.empty())
  {
    Vector xk;
    if (!lu_solve(A(keep, keep), b(keep) - A(keep, fixed) * b(fixed), xk))
      return false;
    x(keep) = xk;
  }
  return x.allFinite();
}

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
} // namespace

Matrix scaled_dp(const std::vector<double>& dP, int k, int d, double rho_n, double rho_t)
{
  Matrix Dr = dp_block(dP, k, d);
  Dr.col(0) *= rho_n;
  Dr.rightCols(d - 1) *= rho_t;
  return Dr;
}

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

void ac_all(const ProblemView& p, const Vector& rho, const Vector& rho_t, const Vector& lam,
            const Vector& u, Vector& phi, std::vector<double>* dP)
{
  const int d = p.dim;
  for (int k = 0; k < p.pairs(); ++k)
    ac_pair(lam.data() + k * d, u.data() + k * d, p.mu[k], rho[k], rho_t[k], d,
            phi.data() + k * d, dP ? dP->data() + k * d * d : nullptr, p.cap_of(k));
}

double merit(const ProblemView& p, const Vector& rho, const Vector& rho_t, const Vector& lam,
             const Vector& u, Vector& phi, std::vector<double>& dP)
{
  ac_all(p, rho, rho_t, lam, u, phi, &dP);
  return 0.5 * phi.squaredNorm();
}

namespace
{
/// @brief The rows of the closed pairs' Newton block (local indices a·d + i, ascending) whose
/// row of ∂P/∂z is not zero (keep), and the others (fixed).
void split_rows(const std::vector<double>& dP, const std::vector<int>& closed, int d,
                std::vector<Eigen::Index>& keep, std::vector<Eigen::Index>& fixed)
{
  for (std::size_t a = 0; a < closed.size(); ++a)
  {
    const DpBlock D = dp_block(dP, closed[a], d);
    for (int i = 0; i < d; ++i)
      ((D.row(i).array() != 0.0).any() ? keep : fixed)
          .push_back(static_cast<Eigen::Index>(a) * d + i);
  }
}
} // namespace

bool newton_direction(const ProblemView& p, const Vector& rho, const Vector& rho_t,
                      const Vector& phi, const std::vector<double>& dP,
                      const std::vector<int>& closed, Vector& dl,
                      std::vector<double>* factorised)
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
  // W's closed block is gathered once, then each pair's rows are multiplied by its D_k ρ_k
  // in place: one d × d by d × (nc·d) product per pair instead of nc products of d × d
  // blocks, whose per-call overhead was half a Newton step at a few hundred closed pairs.
  std::vector<Eigen::Index> unknowns(static_cast<std::size_t>(nc) * d);
  for (int a = 0; a < nc; ++a)
    for (int i = 0; i < d; ++i)
      unknowns[static_cast<std::size_t>(a) * d + i] = static_cast<Eigen::Index>(closed[a]) * d + i;
  Matrix A = p.W(unknowns, unknowns);
  Vector b(nc * d);
  Matrix rows(d, nc * d);
  for (int a = 0; a < nc; ++a)
  {
    const int k = closed[a];
    const Matrix Dr = scaled_dp(dP, k, d, rho[k], rho_t[k]);
    rows.noalias() = Dr.lazyProduct(A.middleRows(a * d, d));
    A.middleRows(a * d, d) = rows;
    A.block(a * d, a * d, d, d) += Matrix::Identity(d, d) - dp_block(dP, k, d);
    b.segment(a * d, d) = -phi.segment(k * d, d) - Dr * Wd0.segment(k * d, d);
  }
  // A row of ∂P/∂z that is zero (a normal impulse at its cap, a frictionless tangent) makes
  // that row of A the identity's and of b −Φ: x = b there, as on an open pair, and its
  // column moves to the right-hand side. Only the other rows are factorised: at a crushing
  // front, where every closed pair sits at its cap, two thirds of them in 3D. A block whose
  // reduced LU fails is solved whole, as before: on a singular, inconsistent block the
  // least-squares step of all rows is not the one that holds the identity rows exactly.
  // Below reduce_from_rows the whole block's LU is cheap and is kept: the reduced one
  // differs from it in rounding only, which on an ill-conditioned block changes Newton's
  // path, and one of the hard test problems (ill_conditioned-3d-m36-3407, 108 unknowns)
  // was then lost by the build of one stack.
  constexpr Eigen::Index reduce_from_rows = 300;
  std::vector<Eigen::Index> keep, fixed;
  if (A.rows() >= reduce_from_rows)
    split_rows(dP, closed, d, keep, fixed);
  const auto took = [&](Eigen::Index order)
  {
    if (factorised)
      factorised->push_back(static_cast<double>(order));
  };
  Vector x;
  const bool reduced = !fixed.empty();
  if (reduced)
    took(static_cast<Eigen::Index>(keep.size()));
  if (!(reduced && reduced_solve(A, b, keep, fixed, x)))
  {
    took(A.rows());
    if (!linear_solve(A, b, x))
      return false;
  }
  for (int a = 0; a < nc; ++a)
    dl.segment(closed[a] * d, d) = x.segment(a * d, d);
  return true;
}

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
} // namespace flexcontact::detail
