// Copyright flexcontact developers. MIT licence.

/// @file increment.cpp
/// @brief The incremental driver (seed eqs. 12–18): friction is path dependent, so each
/// increment's local problem measures slip from the previous increment's tangential gap.

#include "flexcontact/increment.hpp"
#include "flexcontact/solvers.hpp"

#include "contact_checks.hpp"
#include "message_numbers.hpp"

#include <cmath>
#include <string>

namespace flexcontact
{
namespace
{
using detail::num;

/// @brief Throws naming the first non-finite entry of W and its pair.
void check_finite(const std::string& who, const Matrix& W, int dim)
{
  for (Eigen::Index j = 0; j < W.cols(); ++j)
    for (Eigen::Index i = 0; i < W.rows(); ++i)
      if (!std::isfinite(W(i, j)))
        throw std::invalid_argument(who + "W(" + std::to_string(i) + ", " + std::to_string(j)
                                    + ") is " + num(W(i, j)) + " (pair "
                                    + std::to_string(i / dim) + "); W must be finite");
}

/// @brief Throws unless the pair-by-pair vector `name` has n entries, naming its first
/// non-finite entry and that entry's pair.
void check_pair_vector(const std::string& who, const char* name,
                       const Eigen::Ref<const Vector>& v, Eigen::Index n, int dim)
{
  if (v.size() != n)
    throw std::invalid_argument(who + name + " has size " + std::to_string(v.size())
                                + ", expected " + std::to_string(n));
  for (Eigen::Index i = 0; i < v.size(); ++i)
    if (!std::isfinite(v[i]))
      throw std::invalid_argument(who + name + "[" + std::to_string(i) + "] (pair "
                                  + std::to_string(i / dim) + ") is " + num(v[i]) + "; "
                                  + name + " must be finite");
}
} // namespace

IncrementalSolver::IncrementalSolver(int dim, Matrix W, Vector mu, SolverOptions options)
    : dim_(dim), W_(std::move(W)), mu_(std::move(mu)), options_(std::move(options))
{
  const std::string who = "flexcontact: IncrementalSolver: ";
  detail::checked_dim(dim_, who);
  const Eigen::Index n = mu_.size() * dim_;
  if (W_.rows() != W_.cols())
    throw std::invalid_argument(who + "W is " + std::to_string(W_.rows()) + "x"
                                + std::to_string(W_.cols()) + "; it must be square");
  if (W_.rows() != n)
    throw std::invalid_argument(who + "W has " + std::to_string(W_.rows()) + " rows but "
                                + std::to_string(mu_.size()) + " pairs in " + std::to_string(dim_)
                                + "D need " + std::to_string(n));
  detail::check_friction(mu_, who);
  check_finite(who, W_, dim_);
  detail::check_iteration_options(options_, who);
  // Unknown solver names are reported now rather than at the first increment.
  for (const auto& name : options_.chain)
  {
    bool known = false;
    for (const auto& k : solver_names())
      known = known || k == name;
    if (!known)
      throw std::invalid_argument(who + "unknown solver '" + name + "' in the chain");
  }
  // Before the first increment nothing has slipped and nothing touches.
  x_ = Vector::Zero(n);
  lambda_ = Vector::Zero(n);
  G_ = Matrix::Zero(n, 0);
}

void IncrementalSolver::set_border(Matrix G)
{
  const std::string who = "flexcontact: IncrementalSolver::set_border: ";
  if (G.rows() != W_.rows())
    throw std::invalid_argument(who + "G has " + std::to_string(G.rows()) + " rows, expected "
                                + std::to_string(W_.rows()));
  if (!G.allFinite())
    throw std::invalid_argument(who + "G is not finite");
  G_ = std::move(G);
  alpha_ = Vector::Zero(G_.cols());
}

void IncrementalSolver::set_initial_gap(const Eigen::Ref<const Vector>& x0)
{
  check_pair_vector("flexcontact: IncrementalSolver::set_initial_gap: ", "x0", x0, x_.size(),
                    dim_);
  x_ = x0;
}

void IncrementalSolver::set_delassus(Matrix W)
{
  const std::string who = "flexcontact: IncrementalSolver::set_delassus: ";
  if (W.rows() != W_.rows() || W.cols() != W_.cols())
    throw std::invalid_argument(who + "W is " + std::to_string(W.rows()) + "x"
                                + std::to_string(W.cols()) + ", expected "
                                + std::to_string(W_.rows()) + "x" + std::to_string(W_.cols()));
  check_finite(who, W, dim_);
  W_ = std::move(W);
}

void IncrementalSolver::set_warm_start(Vector lambda, std::vector<PairState> states)
{
  const std::string who = "flexcontact: IncrementalSolver::set_warm_start: ";
  if (lambda.size() != x_.size())
    throw std::invalid_argument(who + "lambda has size " + std::to_string(lambda.size())
                                + ", expected " + std::to_string(x_.size()));
  if (states.size() != static_cast<std::size_t>(pairs()))
    throw std::invalid_argument(who + "states has " + std::to_string(states.size())
                                + " entries, expected " + std::to_string(pairs()));
  if (!lambda.allFinite())
    throw std::invalid_argument(who + "lambda is not finite");
  lambda_ = std::move(lambda);
  states_ = std::move(states);
}

void IncrementalSolver::set_crushing(Vector cap, Vector crush_depth)
{
  const std::string who = "flexcontact: IncrementalSolver::set_crushing: ";
  if (cap.size() == 0 && crush_depth.size() == 0)
  {
    cap_ = Vector();
    crush_ = Vector();
    return;
  }
  if (cap.size() != pairs() || crush_depth.size() != pairs())
    throw std::invalid_argument(who + "cap has " + std::to_string(cap.size())
                                + " and crush_depth " + std::to_string(crush_depth.size())
                                + " entries, expected one per pair (" + std::to_string(pairs())
                                + ")");
  detail::check_caps(cap, static_cast<std::size_t>(pairs()), who);
  for (int k = 0; k < pairs(); ++k)
  {
    if (!(crush_depth[k] >= 0.0) || !std::isfinite(crush_depth[k]))
      throw std::invalid_argument(who + "the crush depth of pair " + std::to_string(k)
                                  + " is " + num(crush_depth[k])
                                  + " m; it must be finite and >= 0");
  }
  cap_ = std::move(cap);
  crush_ = std::move(crush_depth);
}

Vector IncrementalSolver::local_q(const Eigen::Ref<const Vector>& q_total) const
{
  // The slip of this increment is x_t − x_t,prev: remove the previous tangential gap.
  Vector q = q_total;
  for (int k = 0; k < pairs(); ++k)
    for (int j = 1; j < dim_; ++j)
      q[k * dim_ + j] -= x_[k * dim_ + j];
  // The crushed surface is δ behind the elastic one.
  for (Eigen::Index k = 0; k < crush_.size(); ++k)
    q[k * dim_] += crush_[k];
  return q;
}

const SolveReport& IncrementalSolver::step(const Eigen::Ref<const Vector>& q_total)
{
  return step(q_total, Vector::Zero(G_.cols()));
}

const SolveReport& IncrementalSolver::step(const Eigen::Ref<const Vector>& q_total,
                                           const Eigen::Ref<const Vector>& e)
{
  const std::string who = "flexcontact: IncrementalSolver::step: ";
  check_pair_vector(who, "q", q_total, W_.rows(), dim_);

  if (e.size() != G_.cols())
    throw std::invalid_argument(who + "e has " + std::to_string(e.size())
                                + " entries but the border G has " + std::to_string(G_.cols())
                                + " rigid modes");
  if (!e.allFinite())
    throw std::invalid_argument(who + "e (the loads along the rigid modes) is not finite");

  const Vector q = local_q(q_total);
  const ProblemView view{dim_, W_, q, mu_, cap_.size() ? cap_.data() : nullptr};
  SolveReport r = G_.cols() ? solve(view, G_, e, lambda_, alpha_, options_)
                            : solve(view, lambda_, states_, options_);
  if (!r.converged)
  {
    // What the chain was given, to be saved for a bug report (bordered problems excepted:
    // the file has no place for the rigid modes).
    std::shared_ptr<const LocalProblem> given;
    if (G_.cols() == 0)
      given = std::make_shared<const LocalProblem>(LocalProblem{
          dim_, W_, q, mu_, cap_, lambda_, states_, options_, "IncrementalSolver::step"});
    // A load the capped forces cannot carry has no answer to converge to: say that first.
    if (r.attempts.size() == 1 && r.attempts.front().rfind("no equilibrium", 0) == 0)
    {
      const std::string what = "flexcontact: " + r.attempts.front();
      throw ConvergenceError(what, std::move(r), std::move(given));
    }
    std::string what = "flexcontact: increment did not converge; best residual "
                       + num(r.residual) + " (tolerance " + num(options_.tolerance)
                       + ") from " + r.solver + ". Tried:";
    for (const auto& a : r.attempts)
      what += " [" + a + "]";
    throw ConvergenceError(what, std::move(r), std::move(given));
  }
  x_ = W_ * r.lambda + q_total;
  if (G_.cols())
  {
    x_ += G_ * r.alpha;
    alpha_ = r.alpha;
  }
  lambda_ = r.lambda;
  states_ = r.states;
  crush_work_ = 0.0;
  for (Eigen::Index k = 0; k < crush_.size(); ++k)
    if (states_[static_cast<std::size_t>(k)] == PairState::crush && -x_[k * dim_] > crush_[k])
    {
      crush_work_ += lambda_[k * dim_] * (-x_[k * dim_] - crush_[k]);
      crush_[k] = -x_[k * dim_];
    }
  last_ = std::move(r);
  return last_;
}
} // namespace flexcontact
