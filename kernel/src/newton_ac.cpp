// Copyright flexcontact developers. MIT licence.

/// @file newton_ac.cpp
/// @brief Semi-smooth Newton on the Alart–Curnier formulation with a line search.

#include "flexcontact/residual.hpp"
#include "flexcontact/solvers.hpp"

#include "ac_pair.hpp"
#include "newton_step.hpp"
#include "work_meter.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
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

/// @brief ρ of the Alart–Curnier map Φ (normal and tangential), and of the natural-map
/// residual, which the Gauss–Seidel sweeps share.
struct NewtonRho
{
  Vector residual, normal, tangential;
};

NewtonRho newton_rho(const ProblemView& p, const detail::NewtonSettings& settings)
{
  NewtonRho r;
  r.residual = pair_rho(p);
  r.normal = r.residual;
  r.tangential = detail::tangential_rho(p, r.normal);
  if (settings.block_rho)
    spectral_rho(p, r.residual, r.normal, r.tangential);
  return r;
}

/// @brief The residual's history: the best iterate met (full steps make the iteration
/// non-monotone) and the last iteration that halved the residual, which decides when
/// Newton has stalled.
class Progress
{
public:
  Progress(double res, const Vector& lam) : gain_ref_{res}, best_{res}, best_lam_(lam) {}

  /// @brief After an accepted step of iteration it.
  void stepped(int it, double res, const Vector& lam)
  {
    if (res < 0.5 * gain_ref_)
    {
      gain_ref_ = res;
      last_gain_ = it;
    }
    keep_best(res, lam);
  }

  /// @brief After Gauss–Seidel restarted iteration it: the stall count starts again.
  void restarted(int it, double res, const Vector& lam)
  {
    last_gain_ = it;
    gain_ref_ = std::min(gain_ref_, res);
    keep_best(res, lam);
  }

  bool stalled(int it) const { return it - last_gain_ >= stall; }

  double best() const { return best_; }
  const Vector& best_lambda() const { return best_lam_; }

private:
  void keep_best(double res, const Vector& lam)
  {
    if (res < best_)
    {
      best_ = res;
      best_lam_ = lam;
    }
  }

  /// Iterations without halving the residual before Newton is declared stalled.
  static constexpr int stall = 8;
  int last_gain_ = 0;
  double gain_ref_, best_;
  Vector best_lam_;
};

/// @brief One run of the Newton of detail::newton_ac(): the iterate (λ, u = Wλ + q), Φ and
/// its blocks ∂P/∂z there, and the globalisation's state.
class NewtonRun
{
public:
  NewtonRun(const ProblemView& p, const Eigen::Ref<const Vector>& lambda0,
            const SolverOptions& opt, const detail::NewtonSettings& settings)
      : p_(p), opt_(opt), settings_(settings), rho_(newton_rho(p, settings)),
        lam_(lambda0.size() ? Vector(lambda0) : Vector::Zero(p.q.size())),
        u_(p.W * lam_ + p.q), phi_(p.q.size()), dl_(p.q.size()),
        trial_{Vector(p.q.size()), Vector(p.q.size()), Vector(p.q.size()), Vector(p.q.size())},
        dP_(static_cast<std::size_t>(p.pairs()) * p.dim * p.dim),
        f_(detail::merit(p, rho_.normal, rho_.tangential, lam_, u_, phi_, dP_)),
        res_(natural_map_residual(p, lam_, u_, rho_.residual)), history_(f_),
        progress_(res_, lam_), work_(opt.work_budget_gflop)
  {
    closed_.reserve(p.pairs());
  }

  SolveReport run();

private:
  bool globalised_step();
  bool gauss_seidel_restart();
  void charge_step();
  void take_trial();

  const ProblemView& p_;
  const SolverOptions& opt_;
  const detail::NewtonSettings& settings_;
  const NewtonRho rho_;
  Vector lam_, u_, phi_, dl_;
  detail::Trial trial_;
  std::vector<double> dP_;
  std::vector<int> closed_;
  std::vector<double> factorised_; ///< the orders of the LUs of this step's direction
  double f_;   ///< merit ½‖Φ‖² at λ
  double res_; ///< natural-map residual at λ
  detail::MeritHistory history_;
  Progress progress_;
  detail::WorkMeter work_;
  int it_ = 0, sweeps_used_ = 0, full_steps_ = 0;
};

SolveReport NewtonRun::run()
{
  const long maxit
      = static_cast<long>(opt_.max_iterations) * std::max(settings_.iteration_factor, 1);
  std::string why;
  while (res_ > opt_.tolerance && it_ < maxit)
  {
    if (work_.spent())
    {
      why = ", work budget spent";
      break;
    }
    ++it_;
    detail::closed_pairs(dP_, p_.pairs(), p_.dim, closed_);
    factorised_.clear();
    const bool solved = detail::newton_direction(p_, rho_.normal, rho_.tangential, phi_, dP_,
                                                 closed_, dl_, &factorised_);
    charge_step();
    if (!solved)
    {
      why = ", linear system not solvable";
      break;
    }
    // Even after an accepted step a stalled Newton restarts from λ (not from the trial).
    const bool accepted = globalised_step();
    if (!accepted || (!settings_.full_step && progress_.stalled(it_)))
    {
      if (!gauss_seidel_restart())
      {
        why = ", non-finite iterate";
        break;
      }
      continue;
    }
    take_trial();
  }
  if (full_steps_ > 0)
    why += ", full steps " + std::to_string(full_steps_);
  // Full steps make the iteration non-monotone: report the best iterate met.
  if (settings_.full_step && !(res_ <= opt_.tolerance) && progress_.best() < res_)
    lam_ = progress_.best_lambda();

  SolveReport rep;
  rep.solver = "newton_ac";
  finish_report(p_, lam_, it_, sweeps_used_, why, opt_.tolerance, rep);
  rep.work_gflop = work_.used_gflop();
  return rep;
}

/// @brief The line search along the Newton direction, or with full_step Siconos' rule where
/// it finds no decrease. Returns true with the next iterate in trial_.
bool NewtonRun::globalised_step()
{
  const Vector& rn = rho_.normal;
  const Vector& rt = rho_.tangential;
  const bool found = settings_.full_step && settings_.goldstein_price
                         ? detail::goldstein_price(p_, rn, rt, lam_, u_, f_, dl_, trial_)
                         : detail::line_search(p_, rn, rt, lam_, u_, phi_, f_, history_,
                                               settings_.full_step, dl_, trial_);
  if (found || !settings_.full_step)
    return found;
  // Siconos' rule: no decrease along the Newton direction, take the full step anyway.
  ++full_steps_;
  trial_.lam = lam_ + dl_;
  trial_.u.noalias() = p_.W * trial_.lam + p_.q;
  return trial_.lam.allFinite();
}

/// @brief Stalled: the sweeps move λ to where Newton converges fast again. Returns false if
/// they leave a non-finite λ.
bool NewtonRun::gauss_seidel_restart()
{
  ++sweeps_used_;
  // Five sweeps at most, each a pass over W's columns and a fresh u.
  work_.charge(5.0 * 2.0 * detail::product_flops(static_cast<double>(p_.q.size())));
  gauss_seidel_sweeps(p_, rho_.residual, opt_.tolerance, lam_, u_, res_);
  if (!lam_.allFinite())
    return false;
  f_ = detail::merit(p_, rho_.normal, rho_.tangential, lam_, u_, phi_, dP_);
  history_.reset(f_);
  progress_.restarted(it_, res_, lam_);
  if (opt_.verbose)
    std::fprintf(stderr, "newton_ac it %d: Gauss-Seidel sweeps, residual %.3e\n", it_, res_);
  return true;
}

/// @brief One Newton step's work: W Δ₀ and W Δ (two products with W), the closed block
/// (d flops per entry of each d×d product) and the LUs its direction took.
void NewtonRun::charge_step()
{
  const double n = static_cast<double>(p_.q.size());
  const double s = static_cast<double>(closed_.size()) * p_.dim;
  double lu = 0.0;
  for (double order : factorised_)
    lu += detail::lu_flops(order);
  work_.charge(2.0 * detail::product_flops(n) + 2.0 * p_.dim * s * s + lu);
}

/// @brief Moves to the accepted trial iterate and evaluates Φ, the merit and the residual.
void NewtonRun::take_trial()
{
  lam_.swap(trial_.lam);
  // Recompute u now and then: the running update accumulates rounding on long runs.
  if (it_ % 20 == 0)
    u_.noalias() = p_.W * lam_ + p_.q;
  else
    u_.swap(trial_.u);
  f_ = detail::merit(p_, rho_.normal, rho_.tangential, lam_, u_, phi_, dP_);
  history_.push(f_);
  res_ = natural_map_residual(p_, lam_, u_, rho_.residual);
  progress_.stepped(it_, res_, lam_);
  if (opt_.verbose)
    std::fprintf(stderr, "newton_ac it %d: closed %d, merit %.3e, residual %.3e\n", it_,
                 static_cast<int>(closed_.size()), f_, res_);
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
  return NewtonRun(p, lambda0, opt, settings).run();
}
} // namespace flexcontact
