// Copyright flexcontact developers. MIT licence.

/// @file solve.cpp
/// @brief The dispatcher: the solvers of the chain in order, each from the best λ found so
/// far and from the caller's start, until one returns a certified answer.

#include "flexcontact/residual.hpp"
#include "flexcontact/solvers.hpp"

#include "ac_pair.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <stdexcept>

namespace flexcontact
{
std::vector<std::string> solver_names() { return {"active_set", "projection", "newton_ac"}; }

double chain_time_budget_s(long n)
{
  const double k = static_cast<double>(std::max(n, 0L)) / 1000.0;
  return 10.0 + 10.0 * k * k * k;
}

std::vector<std::string> default_chain()
{
  // Newton converges fast where it converges; the active set is the seed's method and
  // exact when its states settle; the projection fixed point is slow but hardly ever fails.
  return {"newton_ac", "active_set", "projection"};
}

namespace
{
/// @brief Throws unless every name of the chain is a known solver.
void check_chain(const std::vector<std::string>& chain)
{
  const auto known = solver_names();
  for (const auto& name : chain)
  {
    bool found = false;
    for (const auto& k : known)
      found = found || (k == name);
    if (!found)
    {
      std::string list;
      for (const auto& k : known)
        list += (list.empty() ? "" : ", ") + k;
      throw std::invalid_argument("flexcontact: unknown solver '" + name
                                  + "' in the chain; known solvers: " + list);
    }
  }
}

/// @brief One line of SolveReport::attempts.
std::string attempt_line(const SolveReport& r)
{
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.3e", r.residual);
  std::string line = r.solver + ": " + std::to_string(r.iterations) + " iterations, residual "
                     + buf;
  if (r.state_changes > 0)
    line += ", " + std::to_string(r.state_changes) + " state changes";
  line += r.converged ? ", converged" : (r.cycled ? ", cycled" : ", not converged");
  return line;
}

/// @brief Sets to zero the friction components that move nothing.
///
/// A tangential unknown whose column of W is zero (both nodes held along that tangent, e.g.
/// on a symmetry plane) is not determined by the contact laws: any value inside the cone
/// solves them, and solvers leave different ones (projection sweeps stop on the cone). Zero
/// is always admissible: it changes no u, keeps λ_t in the cone, and a pair that slips
/// along its other tangent needs it (friction opposes the slip). It is also what the
/// supports then carry, so the reported friction is the force the interface transmits.
/// W is positive semi-definite, so a zero diagonal entry means a zero row and column.
void zero_undetermined_friction(const ProblemView& p, SolveReport& r)
{
  const int d = p.dim;
  const double w_scale = p.W.diagonal().cwiseAbs().maxCoeff();
  const double q_scale = p.q.cwiseAbs().maxCoeff();
  bool changed = false;
  for (int k = 0; k < p.pairs(); ++k)
    for (int i = 1; i < d; ++i)
    {
      const int j = k * d + i;
      // q_j ≠ 0 would be a prescribed slip along j, which does determine the friction.
      if (std::abs(p.W(j, j)) <= 1e-14 * w_scale && std::abs(p.q(j)) <= 1e-14 * q_scale
          && r.lambda(j) != 0.0)
      {
        r.lambda(j) = 0.0;
        changed = true;
      }
    }
  if (!changed)
    return;
  r.u = p.W * r.lambda + p.q;
  r.residual = natural_map_residual(p, r.lambda);
  r.states = classify_states(p, r.lambda, r.u);
}
/// @brief Newton's step budget from the caller's start, as a multiple of max_iterations.
/// On ill-conditioned random problems (condition 1e10) Newton needs hundreds of damped steps
/// (Siconos' NSN_AC, given 1000, used 9–911 on those the chain lost): with 100 it solved
/// none of 30 such problems, with 1000 it solved 18.
constexpr int long_newton = 10;

/// @brief The Newton variants tried from zero after Newton from the caller's start and
/// from the best answer failed, each with its line in `attempts`. Of the 19 ill-conditioned
/// and rank-deficient 3D problems of the campaign (seed 1) that Siconos' NSN_AC solved and
/// the chain did not, Newton from zero with its restarts solved 1 in 1,000 steps. With
/// Siconos' globalisation (the full step where the line search finds no decrease), the
/// first three variants solved 7, 11 and 9, 17 together, each a different subset (which
/// ones depends on rounding: hundreds of non-monotone steps on condition numbers of 1e10).
/// The restarted Newton with the block ρ, the chain's earlier fallback, solved 1 of them,
/// and others before (8 and 12 of 30 ill-conditioned problems left by the two ρ).
struct NewtonVariant
{
  detail::NewtonSettings settings;
  const char* label;
};
const NewtonVariant newton_variants[] = {
    {{true, long_newton, true, true}, " (block rho, Goldstein-Price, full steps, from zero)"},
    {{true, long_newton, true, false}, " (block rho, Armijo, full steps, from zero)"},
    {{false, long_newton, true, false}, " (Armijo, full steps, from zero)"},
    {{true, long_newton, false, false}, " (block rho, from zero)"},
};

/// @brief One solver of the chain from the given start; `cold` marks the caller's start.
SolveReport run_solver(const std::string& name, const ProblemView& p, const Vector& start,
                       const std::vector<PairState>& states, const SolverOptions& opt,
                       bool cold)
{
  SolveReport r;
  if (name == "active_set")
    r = solve_active_set(p, start, states, opt);
  else if (name == "projection")
    r = solve_projection(p, start, opt);
  else
    r = detail::newton_ac(p, start, opt,
                          detail::NewtonSettings{false, cold ? long_newton : 1});
  r.solver = name;
  return r;
}
/// @brief Keeps r as the best answer if it is; logs the attempt when verbose.
void keep_best(SolveReport&& r, const SolverOptions& opt, SolveReport& best, bool& have_best,
               const std::vector<std::string>& attempts)
{
  if (opt.verbose)
    std::cerr << "solve: " << attempts.back() << "\n";
  if (!have_best || r.residual < best.residual || (r.converged && !best.converged))
  {
    best = std::move(r);
    have_best = true;
  }
}
} // namespace

SolveReport solve(const ProblemView& p, const Eigen::Ref<const Vector>& lambda0,
                  const std::vector<PairState>& states0, const SolverOptions& opt)
{
  const std::vector<std::string> chain = opt.chain.empty() ? default_chain() : opt.chain;
  check_chain(chain);
  if (!(opt.time_budget_s >= 0.0) || !std::isfinite(opt.time_budget_s))
    throw std::invalid_argument("flexcontact: solver options: time_budget_s = "
                                + std::to_string(opt.time_budget_s)
                                + "; it must be 0 (automatic) or a positive number of seconds");

  std::vector<std::string> attempts;
  SolveReport best;
  bool have_best = false;
  const double budget_s = opt.time_budget_s > 0.0 ? opt.time_budget_s
                                                  : chain_time_budget_s(p.q.size());
  const detail::Deadline deadline(budget_s);
  // Each attempt gets what is left of the chain's budget.
  auto left = [&]
  {
    SolverOptions o = opt;
    o.time_budget_s = std::max(deadline.left_s(), 1e-9);
    return o;
  };
  auto in_chain = [&](const char* name)
  { return std::find(chain.begin(), chain.end(), name) != chain.end(); };
  bool budget_noted = false;
  auto out_of_time = [&]
  {
    if (!deadline.passed())
      return false;
    if (!budget_noted)
    {
      char buf[96];
      std::snprintf(buf, sizeof buf, "time budget of %.3g s spent: no further attempts",
                    budget_s);
      attempts.emplace_back(buf);
      budget_noted = true;
    }
    return true;
  };
  // Below this many unknowns a Newton step (dense LU, ~n³/3) costs less than the 50 warm
  // sweeps (~50 n²) it would save: on random problems of up to 180 unknowns Newton from
  // zero took 0.17 ms (median) against 0.67 ms for the chain with sweeps first.
  constexpr int warm_start_unknowns = 300;
  if (opt.chain.empty() and p.q.size() >= warm_start_unknowns)
  {
    // Default chain: a few projection sweeps first. They are cheap (O((m·d)²) each) and
    // find the open/stick/slip pattern of most pairs, from where Newton converges in one
    // or two steps: on 2367 unknowns of a sliding block, 50 sweeps + 2 Newton steps took
    // 0.85 s against 6.6 s for Newton from zero (22 steps of a dense LU).
    SolverOptions warm = left();
    warm.max_iterations = 1; // the projection solver runs 50 × max_iterations sweeps
    best = solve_projection(p, lambda0, warm);
    best.solver = "projection";
    attempts.push_back(attempt_line(best) + " (warm start)");
    if (opt.verbose)
      std::cerr << "solve: " << attempts.back() << "\n";
    have_best = best.lambda.allFinite() && std::isfinite(best.residual);
    if (!have_best)
      best = SolveReport{};
  }
  for (const auto& name : chain)
  {
    if (have_best && best.converged)
      break;
    // Two starts per solver: the best answer so far (a near-miss of one solver is often a
    // good start for the next) and the caller's own (λ0, states0), for when it is not. On
    // random ill-conditioned problems Newton after the projection sweeps stalled at 1e-5
    // where Newton from zero converged; the active set from a failed Newton iterate can
    // switch states thousands of times where from zero it needs a few iterations. So
    // Newton and the projection start warm, the active set cold, each with the other start
    // as its second try.
    const bool warm_first = name != "active_set";
    const bool had_best = have_best;
    for (int attempt = 0; attempt < 2 && !(have_best && best.converged); ++attempt)
    {
      if (attempt == 1 && !had_best)
        break; // both starts would be the caller's
      if (out_of_time())
        break;
      const bool warm = had_best && (attempt == 0) == warm_first;
      SolveReport r = run_solver(name, p, warm ? best.lambda : Vector(lambda0),
                                 warm ? best.states : states0, left(), !warm);
      attempts.push_back(attempt_line(r) + (warm ? " (from the best so far)"
                                                 : " (from the given start)"));
      keep_best(std::move(r), opt, best, have_best, attempts);
    }
    if (name == "newton_ac")
      for (const auto& variant : newton_variants)
      {
        if ((have_best && best.converged) || out_of_time())
          break;
        SolveReport r = detail::newton_ac(p, Vector::Zero(p.q.size()), left(), variant.settings);
        r.solver = name;
        attempts.push_back(attempt_line(r) + variant.label);
        keep_best(std::move(r), opt, best, have_best, attempts);
      }
  }
  // The projection can end a little short of an answer (1e-6) from where Newton converges
  // in two steps, though every Newton before it failed from its own starts: on
  // ill_conditioned-3d-m49-7335 of the campaign (condition 1e10) the projection reached
  // 9.7e-7 and Newton from there 3.7e-14. So an answer Newton did not itself end on gets
  // one last Newton from it.
  if (have_best && !best.converged && best.solver != "newton_ac" && in_chain("newton_ac")
      && !out_of_time())
  {
    SolveReport r = run_solver("newton_ac", p, best.lambda, best.states, left(), false);
    attempts.push_back(attempt_line(r) + " (from the best so far, last)");
    keep_best(std::move(r), opt, best, have_best, attempts);
  }
  if (!have_best)
  {
    // The budget ran out before any attempt: report the caller's start as it is.
    best.solver = chain.front();
    best.lambda = lambda0.size() ? Vector(lambda0) : Vector::Zero(p.q.size());
    best.u = p.W * best.lambda + p.q;
    best.residual = natural_map_residual(p, best.lambda);
    best.converged = best.residual <= opt.tolerance;
    best.states = classify_states(p, best.lambda, best.u);
  }
  if (best.lambda.size() == p.q.size() && best.lambda.allFinite())
  {
    const double before = best.residual;
    zero_undetermined_friction(p, best);
    // Zeroing can only remove a spurious friction component; it must not spoil an answer.
    if (best.converged && !(best.residual <= std::max(opt.tolerance, before)))
      best.converged = false;
  }
  best.attempts = std::move(attempts);
  return best;
}
} // namespace flexcontact
