// Copyright flexcontact developers. MIT licence.

/// @file active_set.cpp
/// @brief The Feng–Touzot active-set method (seed eqs. 12–18): each pair is stick, slip or
/// open, each state replaces the pair's rows of u = W λ + q, the modified dense system is
/// solved and the states are switched until none changes.

#include "flexcontact/residual.hpp"
#include "flexcontact/solvers.hpp"

#include "ac_pair.hpp"
#include "work_meter.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <limits>
#include <set>
#include <stdexcept>
#include <string>

namespace flexcontact
{
namespace
{
constexpr double tiny = std::numeric_limits<double>::min();

/// @brief Throws if the problem's sizes, λ0 or states0 disagree.
void check_inputs(const ProblemView& p, const Eigen::Ref<const Vector>& lambda0,
                  const std::vector<PairState>& states0)
{
  if (p.dim != 2 && p.dim != 3)
    throw std::invalid_argument("flexcontact: active set: dim must be 2 or 3, got "
                                + std::to_string(p.dim));
  const auto n = p.q.size();
  if (n % p.dim != 0 || p.W.rows() != n || p.W.cols() != n || p.mu.size() != n / p.dim)
    throw std::invalid_argument("flexcontact: active set: sizes disagree (q "
                                + std::to_string(n) + ", W " + std::to_string(p.W.rows())
                                + "x" + std::to_string(p.W.cols()) + ", mu "
                                + std::to_string(p.mu.size()) + ", dim "
                                + std::to_string(p.dim) + ")");
  if (lambda0.size() != 0 && lambda0.size() != n)
    throw std::invalid_argument("flexcontact: active set: starting lambda has size "
                                + std::to_string(lambda0.size()) + ", expected 0 or "
                                + std::to_string(n));
  if (lambda0.size() != 0 && !lambda0.allFinite())
    throw std::invalid_argument("flexcontact: active set: starting lambda is not finite");
  if (!states0.empty() && static_cast<Eigen::Index>(states0.size()) != n / p.dim)
    throw std::invalid_argument("flexcontact: active set: " + std::to_string(states0.size())
                                + " starting states for " + std::to_string(n / p.dim)
                                + " pairs");
}

/// @brief Compliance c_k of pair k's normal row, used to scale the rows that state a force
/// (λ = 0, friction law) so that every row of the modified system has the units and the
/// size of a W row; pairs with no compliance (constrained DOFs) get the largest one.
Vector row_scales(const ProblemView& p)
{
  const int m = p.pairs();
  double wmax = 0.0;
  for (Eigen::Index i = 0; i < p.W.rows(); ++i)
    wmax = std::max(wmax, std::abs(p.W(i, i)));
  if (!(wmax > 0.0))
    wmax = 1.0;
  Vector c(m);
  for (int k = 0; k < m; ++k)
  {
    const double w = p.W(k * p.dim, k * p.dim);
    c[k] = (w > 1e-12 * wmax) ? w : wmax;
  }
  return c;
}

/// @brief Solves A x = b; falls back from LU to a rank-revealing least-squares solve when
/// A is (nearly) singular, which happens with a semi-definite W (zero rows of constrained
/// DOFs, two pairs on one node). Returns false if no finite solution came out.
bool solve_dense(const Matrix& A, const Vector& b, Vector& x)
{
  if (A.rows() == 0)
  {
    x.resize(0);
    return true;
  }
  Eigen::PartialPivLU<Matrix> lu(A);
  if (lu.rcond() > 1e-12)
  {
    x = lu.solve(b);
    if (x.allFinite())
      return true;
  }
  // Minimum-norm least squares: a redundant constraint shares the force, an inconsistent
  // one leaves a residual that the switching rules and the final residual then see.
  Eigen::CompleteOrthogonalDecomposition<Matrix> cod;
  cod.setThreshold(1e-11);
  cod.compute(A);
  x = cod.solve(b);
  return x.allFinite();
}

/// @brief Tangential part of pair k of v (d − 1 values).
Eigen::VectorXd tangent(const Vector& v, int k, int d)
{
  return v.segment(k * d + 1, d - 1);
}

/// @brief The discrete part of the iteration: states, and the slip directions that enter
/// the system (2D signs exactly, 3D directions rounded), for revisit detection.
std::vector<std::int64_t> state_key(const std::vector<PairState>& states,
                                    const std::vector<char>& crush_slip, const Matrix& dir,
                                    const Eigen::Ref<const Vector>& mu)
{
  std::vector<std::int64_t> key;
  key.reserve(states.size() * 3);
  for (std::size_t k = 0; k < states.size(); ++k)
  {
    const bool crushing = states[k] == PairState::crush;
    key.push_back(static_cast<std::int64_t>(states[k]) + (crushing && crush_slip[k] ? 10 : 0));
    // A direction changes the system only for a slipping pair with friction.
    const bool slipping = states[k] == PairState::slip || (crushing && crush_slip[k]);
    if (!slipping || mu[static_cast<Eigen::Index>(k)] == 0.0)
      continue;
    for (Eigen::Index j = 0; j < dir.rows(); ++j)
      key.push_back(static_cast<std::int64_t>(std::llround(dir(j, k) * 1e6)));
  }
  return key;
}

/// @brief Starting slip direction of pair k: the predicted slip u_t if any, else against
/// the force, else against the load q_t, else the first tangent.
Eigen::VectorXd initial_direction(const ProblemView& p, const Vector& lambda, const Vector& u,
                                  int k)
{
  const int d = p.dim;
  for (int source = 0; source < 3; ++source)
  {
    Eigen::VectorXd v = source == 0   ? tangent(u, k, d)
                        : source == 1 ? Eigen::VectorXd(-tangent(lambda, k, d))
                                      : Eigen::VectorXd(p.q.segment(k * d + 1, d - 1));
    const double len = v.norm();
    if (len > 0.0 && std::isfinite(len))
      return v / len;
  }
  Eigen::VectorXd e = Eigen::VectorXd::Zero(d - 1);
  e[0] = 1.0;
  return e;
}

const char* state_name(PairState s)
{
  return s == PairState::open    ? "open"
         : s == PairState::stick ? "stick"
         : s == PairState::slip  ? "slip"
                                 : "crush";
}

/// @brief Fills A and b with the modified system: each pair's state replaces its rows of
/// u = W λ + q. The rows that state a force are scaled by c_k (see row_scales). A crushing
/// pair (docs/crushing.md) has its normal force at the cap, λ_n = cap, and tangential rows
/// as a stick pair's (u_t = 0) or, where crush_slip, as a slip pair's.
void build_modified_system(const ProblemView& p, const std::vector<PairState>& states,
                           const std::vector<char>& crush_slip, const Matrix& dir,
                           const Vector& c, Matrix& A, Vector& b)
{
  const int d = p.dim;
  for (int k = 0; k < p.pairs(); ++k)
  {
    const int i = k * d;
    switch (states[k])
    {
    case PairState::crush:
      A.row(i).setZero();
      A(i, i) = c[k];
      b[i] = c[k] * p.cap_of(k);
      for (int j = 1; j < d; ++j)
      {
        if (crush_slip[k])
        {
          A.row(i + j).setZero();
          A(i + j, i + j) = c[k];
          A(i + j, i) = c[k] * p.mu[k] * dir(j - 1, k);
          b[i + j] = 0.0;
        }
        else
        {
          A.row(i + j) = p.W.row(i + j);
          b[i + j] = -p.q[i + j];
        }
      }
      break;
    case PairState::stick: // u_k = 0: the pair's rows of W λ + q
      A.middleRows(i, d) = p.W.middleRows(i, d);
      b.segment(i, d) = -p.q.segment(i, d);
      break;
    case PairState::slip: // u_n = 0 and λ_t + μ λ_n s = 0 (friction opposes slip s)
      A.row(i) = p.W.row(i);
      b[i] = -p.q[i];
      A.middleRows(i + 1, d - 1).setZero();
      for (int j = 1; j < d; ++j)
      {
        A(i + j, i + j) = c[k];
        A(i + j, i) = c[k] * p.mu[k] * dir(j - 1, k);
        b[i + j] = 0.0;
      }
      break;
    case PairState::open: // λ_k = 0
      A.middleRows(i, d).setZero();
      for (int j = 0; j < d; ++j)
      {
        A(i + j, i + j) = c[k];
        b[i + j] = 0.0;
      }
      break;
    case PairState::none:
      throw std::logic_error("active set: pair " + std::to_string(k)
                             + " has a state the active set does not take");
    }
  }
}

/// @brief What the switching rules compare against: force and displacement thresholds,
/// below which a value counts as zero, and the relaxation of the 3D direction update.
struct SwitchParams
{
  double ftol;
  double gtol;
  double omega;
};

/// @brief Next slip direction of a frictional 3D pair k that keeps slipping; raises turn
/// to the change of the direction.
void update_slip_direction(const ProblemView& p, int k, double ln, const Eigen::VectorXd& ut,
                           const Vector& c, double omega, Matrix& dir, double& turn)
{
  // The seed's projection form of the explicit method: the next direction is
  // that of λ_t − ρ u_t projected on the disc of radius μλ_n, i.e. the assumed
  // direction weighted by the friction force μλ_n and this iterate's slip by
  // ρ|u_t| = |u_t|/c_k. The weights are in force units, so a pair that barely
  // slips keeps its direction and one that slides far takes its slip's; relaxed
  // further (omega < 1) once the update has been seen to oscillate.
  const double wf = p.mu[k] * std::max(ln, 0.0);
  Eigen::VectorXd s = wf * dir.col(k) + ut / c[k];
  s = omega * s / s.norm() + (1.0 - omega) * dir.col(k);
  if (!(s.norm() > 0.5 * omega))
    s = ut; // the slip turned round: relaxation would cancel, take it as is
  s.normalize();
  turn = std::max(turn, (s - dir.col(k)).norm());
  dir.col(k) = s;
}

/// @brief The switching rules: the state pair k takes from this iterate's λ and u, given
/// its state in the system just solved. May update the pair's slip direction.
PairState switch_pair(const ProblemView& p, int k, PairState state, const Vector& lambda,
                      const Vector& u, const Vector& c, const SwitchParams& sw, Matrix& dir,
                      double& turn, char& crush_slip)
{
  const int d = p.dim;
  const int i = k * d;
  const double ln = lambda[i];
  const double cap = p.cap_of(k);
  const Eigen::VectorXd lt = tangent(lambda, k, d), ut = tangent(u, k, d);
  // A closed pair whose normal force passes its cap crushes, keeping its tangential state.
  if ((state == PairState::stick || state == PairState::slip) && ln > cap + sw.ftol)
  {
    crush_slip = state == PairState::slip;
    return PairState::crush;
  }
  switch (state)
  {
  case PairState::crush:
    // At the cap the surface may not separate: a pair opening there unloads from the cap.
    if (u[i] > sw.gtol)
      return crush_slip ? PairState::slip : PairState::stick;
    if (!crush_slip && lt.norm() > p.mu[k] * cap + sw.ftol && lt.norm() > sw.ftol)
    {
      dir.col(k) = -lt / lt.norm();
      crush_slip = 1;
    }
    else if (crush_slip && p.mu[k] > 0.0 && ut.dot(dir.col(k)) < -sw.gtol)
      crush_slip = 0;
    else if (crush_slip && d == 3 && p.mu[k] > 0.0 && ut.norm() > sw.gtol)
      update_slip_direction(p, k, cap, ut, c, sw.omega, dir, turn);
    break;
  case PairState::stick:
    // Slip is tried before open: a stuck pair pulled apart (λ_n < 0) while sheared
    // may well be sliding, and going straight to open is what makes the plain
    // iteration cycle (stick → open → stick). A slip pair still in tension opens next.
    if (lt.norm() > p.mu[k] * ln + sw.ftol && lt.norm() > sw.ftol)
    {
      dir.col(k) = -lt / lt.norm(); // the slip opposes the force that broke adhesion
      return PairState::slip;
    }
    if (ln < -sw.ftol)
      return PairState::open;
    break;
  case PairState::slip:
    if (ln < -sw.ftol)
      return PairState::open;
    if (p.mu[k] == 0.0)
    {
      // No friction: the direction does not enter the system; keep it for reporting.
      if (ut.norm() > sw.gtol)
        dir.col(k) = ut / ut.norm();
    }
    else if (ut.dot(dir.col(k)) < -sw.gtol)
      return PairState::stick; // the assumed slip reversed
    else if (d == 3 && ut.norm() > sw.gtol)
      update_slip_direction(p, k, ln, ut, c, sw.omega, dir, turn);
    break;
  case PairState::open:
    if (u[i] < -sw.gtol)
      return PairState::stick;
    break;
  case PairState::none:
    break;
  }
  return state;
}

/// @brief Applies the switching rules to every pair; returns the number of state changes
/// and raises turn to the largest change of a 3D slip direction.
int switch_states(const ProblemView& p, const Vector& lambda, const Vector& u, const Vector& c,
                  const SwitchParams& sw, int iteration, bool verbose,
                  std::vector<PairState>& states, std::vector<char>& crush_slip, Matrix& dir,
                  double& turn)
{
  int changes = 0;
  for (int k = 0; k < p.pairs(); ++k)
  {
    const PairState old = states[k];
    const char old_slip = crush_slip[k];
    states[k] = switch_pair(p, k, old, lambda, u, c, sw, dir, turn, crush_slip[k]);
    if (states[k] == PairState::crush && old == PairState::crush && crush_slip[k] != old_slip)
      ++changes;
    if (states[k] != old)
    {
      ++changes;
      if (verbose)
        std::cerr << "active_set: iteration " << iteration << ": pair " << k << " "
                  << state_name(old) << " -> " << state_name(states[k]) << "\n";
    }
  }
  return changes;
}

/// @brief Revisit detection on the discrete part of the iteration (state_key). Changed
/// states that come back are a cycle; 3D directions alone that come back mean the explicit
/// direction update oscillates, which halves its relaxation omega instead.
class CycleDetector
{
public:
  CycleDetector(const std::vector<PairState>& states, const std::vector<char>& crush_slip,
                const Matrix& dir, const Eigen::Ref<const Vector>& mu)
      : last_key_(state_key(states, crush_slip, dir, mu))
  {
    seen_.insert(last_key_);
  }

  /// @brief Relaxation of the 3D slip-direction update.
  double omega() const { return omega_; }

  /// @brief Records the states and directions after a switching pass that made `changes`
  /// changes; true if the iteration cycles.
  bool cycles(const std::vector<PairState>& states, const std::vector<char>& crush_slip,
              const Matrix& dir, const Eigen::Ref<const Vector>& mu, int changes, int iteration,
              bool verbose)
  {
    auto key = state_key(states, crush_slip, dir, mu);
    const bool same_as_last = (key == last_key_);
    last_key_ = key;
    if (changes == 0 && same_as_last)
      return false; // directions still settling below the key's resolution: not a revisit
    if (seen_.insert(std::move(key)).second)
      return false;
    if (changes == 0 && omega_ > 1.0 / 64.0)
    {
      // Only 3D directions moved and they came back: the explicit update oscillates
      // about the answer. Relax it and forget the directions seen so far.
      omega_ *= 0.5;
      seen_.clear();
      seen_.insert(state_key(states, crush_slip, dir, mu));
      if (verbose)
        std::cerr << "active_set: iteration " << iteration
                  << ": slip directions oscillate; relaxation " << omega_ << "\n";
      return false;
    }
    if (verbose)
      std::cerr << "active_set: iteration " << iteration
                << ": state vector seen before; the iteration cycles\n";
    return true;
  }

private:
  std::set<std::vector<std::int64_t>> seen_;
  std::vector<std::int64_t> last_key_;
  double omega_ = 1.0;
};

/// @brief Fills the report's answer from the best iterate, which need not be the last when
/// the iteration cycled or ran out of iterations.
void finish_report(const ProblemView& p, const Vector& best_lambda, double tolerance,
                   SolveReport& rep)
{
  rep.lambda = best_lambda;
  rep.u = p.W * rep.lambda + p.q;
  rep.residual = natural_map_residual(p, rep.lambda);
  rep.states = classify_states(p, rep.lambda, rep.u);
  rep.converged = rep.residual <= tolerance;
}
} // namespace

SolveReport solve_active_set(const ProblemView& p, const Eigen::Ref<const Vector>& lambda0,
                             const std::vector<PairState>& states0, const SolverOptions& opt)
{
  check_inputs(p, lambda0, states0);
  const int d = p.dim;
  const int m = p.pairs();
  const Eigen::Index n = p.q.size();

  SolveReport rep;
  rep.solver = "active_set";
  Vector lambda = lambda0.size() ? Vector(lambda0) : Vector(Vector::Zero(n));
  Vector u = p.W * lambda + p.q;
  std::vector<PairState> states
      = states0.empty() ? std::vector<PairState>(m, PairState::stick) : states0;
  // A start that crushes where there is no cap (any more) starts stuck instead.
  for (int k = 0; k < m; ++k)
    if (states[k] == PairState::crush && !(p.cap_of(k) < std::numeric_limits<double>::infinity()))
      states[k] = PairState::stick;
  std::vector<char> crush_slip(static_cast<std::size_t>(m), 0);
  Matrix dir = Matrix::Zero(d - 1, m); // unit slip direction in the pair's tangent plane
  for (int k = 0; k < m; ++k)
    dir.col(k) = initial_direction(p, lambda, u, k);

  const Vector c = row_scales(p);
  // Switching thresholds relative to the problem's scale; a tenth of the requested
  // tolerance so that what is left unswitched cannot spoil the certificate.
  const double tau = std::max(0.1 * opt.tolerance, 1e3 * std::numeric_limits<double>::epsilon());
  Vector rho_q(n);
  for (int k = 0; k < m; ++k)
    rho_q.segment(k * d, d) = p.q.segment(k * d, d) / c[k];

  Vector best_lambda = lambda;
  double best_residual = natural_map_residual(p, lambda);
  CycleDetector detector(states, crush_slip, dir, p.mu);

  Matrix A(n, n);
  Vector b(n), x(n);
  detail::WorkMeter work(opt.work_budget_gflop);
  while (rep.iterations < opt.max_iterations && !work.spent())
  {
    // The modified system (copied from W) and its LU, then u = W λ + q.
    work.charge(detail::lu_flops(n) + 2.0 * detail::product_flops(n));
    build_modified_system(p, states, crush_slip, dir, c, A, b);
    ++rep.iterations;
    if (!solve_dense(A, b, x))
    {
      if (opt.verbose)
        std::cerr << "active_set: iteration " << rep.iterations
                  << ": the modified system gave no finite solution; stopping\n";
      break;
    }
    lambda = x;
    u = p.W * lambda + p.q; // the unmodified rows: gaps of open pairs, slips of slip pairs

    const double res = natural_map_residual(p, lambda);
    if (res < best_residual)
    {
      best_residual = res;
      best_lambda = lambda;
    }

    const double fscale = std::max({lambda.cwiseAbs().maxCoeff(), rho_q.cwiseAbs().maxCoeff(), tiny});
    const double gscale = std::max({u.cwiseAbs().maxCoeff(), p.q.cwiseAbs().maxCoeff(), tiny});
    const SwitchParams sw{tau * fscale, tau * gscale, detector.omega()};
    double turn = 0.0;
    const int changes
        = switch_states(p, lambda, u, c, sw, rep.iterations, opt.verbose, states, crush_slip,
                        dir, turn);
    rep.state_changes += changes;
    if (opt.verbose)
      std::cerr << "active_set: iteration " << rep.iterations << ": " << changes
                << " switches, residual " << res << "\n";

    if (res <= opt.tolerance)
      break; // certified: nothing left to switch that matters
    if (changes == 0 && turn <= 1e-14)
      break; // fixed point of states and directions (uncertified if res > tolerance)
    if (detector.cycles(states, crush_slip, dir, p.mu, changes, rep.iterations, opt.verbose))
    {
      rep.cycled = true;
      break;
    }
  }

  finish_report(p, best_lambda, opt.tolerance, rep);
  rep.work_gflop = work.used_gflop();
  return rep;
}
} // namespace flexcontact
