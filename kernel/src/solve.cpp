// Copyright flexcontact developers. MIT licence.

/// @file solve.cpp
/// @brief The dispatcher: the solvers of the chain in order, each from the best λ found so
/// far and from the caller's start, until one returns a certified answer.

#include "flexcontact/residual.hpp"
#include "flexcontact/solvers.hpp"

#include "ac_pair.hpp"
#include "message_numbers.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <stdexcept>

namespace flexcontact
{
std::vector<std::string> solver_names() { return {"active_set", "projection", "newton_ac"}; }

namespace
{
// docs/solvers.md, "The work budget": the constant is more than every solver of the chain
// can do within its iteration caps below 200 unknowns (36 Gflop there), so a small problem
// never stops on work; the cubic term is 300 LU factorisations of the whole n × n matrix.
// On the reference machine (19 Gflop/s on large problems, 2–9 on small ones) they match
// the wall-clock budget they replaced, 10 s + 10 s·(n/1000)³.
constexpr double chain_work_constant_gflop = 50.0;
constexpr double chain_work_cubic_gflop = 200.0;
} // namespace

double chain_work_budget_gflop(long n)
{
  const double k = static_cast<double>(std::max(n, 0L)) / 1000.0;
  return chain_work_constant_gflop + chain_work_cubic_gflop * k * k * k;
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
  std::string line = r.solver + ": " + std::to_string(r.iterations) + " iterations, residual "
                     + detail::exp3(r.residual);
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

/// @brief One run of the chain: the best answer so far, the attempts' lines, and the work
/// budget that the attempts share.
class ChainRun
{
public:
  ChainRun(const ProblemView& p, const Eigen::Ref<const Vector>& lambda0,
           const std::vector<PairState>& states0, const SolverOptions& opt)
      : p_(p), lambda0_(lambda0), states0_(states0), opt_(opt),
        budget_gflop_(opt.work_budget_gflop > 0.0 ? opt.work_budget_gflop
                                                  : chain_work_budget_gflop(p.q.size()))
  {
  }

  SolveReport run(const std::vector<std::string>& chain);

private:
  bool solved() const { return have_best_ && best_.converged; }
  SolverOptions left() const;
  bool out_of_work();
  void projection_warm_start();
  void from_two_starts(const std::string& name);
  void newton_variants_from_zero();
  void newton_polish(const std::vector<std::string>& chain);
  void keep_best(SolveReport&& r, const std::string& how);
  void report_the_start(const std::string& solver);

  const ProblemView& p_;
  const Eigen::Ref<const Vector>& lambda0_;
  const std::vector<PairState>& states0_;
  const SolverOptions& opt_;
  const double budget_gflop_;
  double used_gflop_ = 0.0;
  std::vector<std::string> attempts_;
  SolveReport best_;
  bool have_best_ = false;
  bool budget_noted_ = false;
};

SolveReport ChainRun::run(const std::vector<std::string>& chain)
{
  // Below this many unknowns a Newton step (dense LU, ~n³/3) costs less than the 50 warm
  // sweeps (~50 n²) it would save: on random problems of up to 180 unknowns Newton from
  // zero took 0.17 ms (median) against 0.67 ms for the chain with sweeps first.
  constexpr int warm_start_unknowns = 300;
  if (opt_.chain.empty() and p_.q.size() >= warm_start_unknowns)
    projection_warm_start();
  for (const auto& name : chain)
  {
    if (solved())
      break;
    from_two_starts(name);
    if (name == "newton_ac")
      newton_variants_from_zero();
  }
  newton_polish(chain);
  if (!have_best_)
    report_the_start(chain.front());
  if (best_.lambda.size() == p_.q.size() && best_.lambda.allFinite())
  {
    const double before = best_.residual;
    zero_undetermined_friction(p_, best_);
    // Zeroing can only remove a spurious friction component; it must not spoil an answer.
    if (best_.converged && !(best_.residual <= std::max(opt_.tolerance, before)))
      best_.converged = false;
  }
  best_.attempts = std::move(attempts_);
  best_.work_gflop = used_gflop_;
  return std::move(best_);
}

/// @brief The options of the next attempt: what is left of the chain's budget (never 0,
/// which would mean none).
SolverOptions ChainRun::left() const
{
  SolverOptions o = opt_;
  o.work_budget_gflop = std::max(budget_gflop_ - used_gflop_, 1e-12);
  return o;
}

/// @brief True once the budget is spent; the first time, says so in `attempts`.
bool ChainRun::out_of_work()
{
  if (used_gflop_ < budget_gflop_)
    return false;
  if (!budget_noted_)
  {
    char buf[96];
    std::snprintf(buf, sizeof buf, "work budget of %.3g Gflop spent: no further attempts",
                  budget_gflop_);
    attempts_.emplace_back(buf);
    budget_noted_ = true;
  }
  return true;
}

/// @brief Default chain on a large problem: a few projection sweeps first. They are cheap
/// (O((m·d)²) each) and find the open/stick/slip pattern of most pairs, from where Newton
/// converges in one or two steps: on 2367 unknowns of a sliding block, 50 sweeps + 2 Newton
/// steps took 0.85 s against 6.6 s for Newton from zero (22 steps of a dense LU).
void ChainRun::projection_warm_start()
{
  SolverOptions warm = left();
  warm.max_iterations = 1; // the projection solver runs 50 × max_iterations sweeps
  best_ = solve_projection(p_, lambda0_, warm);
  used_gflop_ += best_.work_gflop;
  best_.solver = "projection";
  attempts_.push_back(attempt_line(best_) + " (warm start)");
  if (opt_.verbose)
    std::cerr << "solve: " << attempts_.back() << "\n";
  have_best_ = best_.lambda.allFinite() && std::isfinite(best_.residual);
  if (!have_best_)
    best_ = SolveReport{};
}

/// @brief Two starts per solver: the best answer so far (a near-miss of one solver is often
/// a good start for the next) and the caller's own (λ0, states0), for when it is not. On
/// random ill-conditioned problems Newton after the projection sweeps stalled at 1e-5 where
/// Newton from zero converged; the active set from a failed Newton iterate can switch
/// states thousands of times where from zero it needs a few iterations. So Newton and the
/// projection start warm, the active set cold, each with the other start as its second try.
void ChainRun::from_two_starts(const std::string& name)
{
  const bool warm_first = name != "active_set";
  const bool had_best = have_best_;
  for (int attempt = 0; attempt < 2 && !solved(); ++attempt)
  {
    if (attempt == 1 && !had_best)
      break; // both starts would be the caller's
    if (out_of_work())
      break;
    const bool warm = had_best && (attempt == 0) == warm_first;
    SolveReport r = run_solver(name, p_, warm ? best_.lambda : Vector(lambda0_),
                               warm ? best_.states : states0_, left(), !warm);
    keep_best(std::move(r), warm ? " (from the best so far)" : " (from the given start)");
  }
}

/// @brief The projection can end a little short of an answer (1e-6) from where Newton
/// converges in two steps, though every Newton before it failed from its own starts: on
/// ill_conditioned-3d-m49-7335 of the campaign (condition 1e10) the projection reached
/// 9.7e-7 and Newton from there 3.7e-14. So an answer Newton did not itself end on gets one
/// last Newton from it.
void ChainRun::newton_polish(const std::vector<std::string>& chain)
{
  if (!have_best_ || best_.converged || best_.solver == "newton_ac"
      || std::find(chain.begin(), chain.end(), "newton_ac") == chain.end() || out_of_work())
    return;
  SolveReport r = run_solver("newton_ac", p_, best_.lambda, best_.states, left(), false);
  keep_best(std::move(r), " (from the best so far, last)");
}

void ChainRun::newton_variants_from_zero()
{
  for (const auto& variant : newton_variants)
  {
    if (solved() || out_of_work())
      break;
    SolveReport r = detail::newton_ac(p_, Vector::Zero(p_.q.size()), left(), variant.settings);
    r.solver = "newton_ac";
    keep_best(std::move(r), variant.label);
  }
}

/// @brief Records r's attempt line (how: its start) and keeps r as the best answer if it is.
void ChainRun::keep_best(SolveReport&& r, const std::string& how)
{
  used_gflop_ += r.work_gflop;
  attempts_.push_back(attempt_line(r) + how);
  if (opt_.verbose)
    std::cerr << "solve: " << attempts_.back() << "\n";
  if (!have_best_ || r.residual < best_.residual || (r.converged && !best_.converged))
  {
    best_ = std::move(r);
    have_best_ = true;
  }
}

/// @brief The budget ran out before any attempt: the caller's start as it is.
void ChainRun::report_the_start(const std::string& solver)
{
  best_.solver = solver;
  best_.lambda = lambda0_.size() ? Vector(lambda0_) : Vector::Zero(p_.q.size());
  best_.u = p_.W * best_.lambda + p_.q;
  best_.residual = natural_map_residual(p_, best_.lambda);
  best_.converged = best_.residual <= opt_.tolerance;
  best_.states = classify_states(p_, best_.lambda, best_.u);
}
} // namespace

SolveReport solve(const ProblemView& p, const Eigen::Ref<const Vector>& lambda0,
                  const std::vector<PairState>& states0, const SolverOptions& opt)
{
  const std::vector<std::string> chain = opt.chain.empty() ? default_chain() : opt.chain;
  check_chain(chain);
  if (!(opt.work_budget_gflop >= 0.0) || !std::isfinite(opt.work_budget_gflop))
    throw std::invalid_argument("flexcontact: solver options: work_budget_gflop = "
                                + std::to_string(opt.work_budget_gflop)
                                + "; it must be 0 (automatic) or a positive number of Gflop");

  return ChainRun(p, lambda0, states0, opt).run(chain);
}
} // namespace flexcontact
