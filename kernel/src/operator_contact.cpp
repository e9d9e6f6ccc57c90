// Copyright flexcontact developers. MIT licence.

/// @file operator_contact.cpp
/// @brief The condensed contact problem with F* an operator: B, x0 and one increment, W
/// applied and never formed.

#include "flexcontact/operator_contact.hpp"
#include "carry_over.hpp"
#include "constrained.hpp"
#include "contact_checks.hpp"
#include "message_numbers.hpp"
#include "pair_columns.hpp"
#include "step_summary.hpp"

#include <stdexcept>
#include <string>

namespace flexcontact
{
namespace
{
const std::string who = "flexcontact: OperatorContact: ";
} // namespace

OperatorContact::OperatorContact(int dim, LinearOperator flexibility, Matrix X,
                                 std::vector<ContactPair> pairs, Vector mu,
                                 std::vector<bool> constrained, SolverOptions options)
    : dim_(detail::checked_dim(dim, who)), F_(std::move(flexibility)), X_(std::move(X)),
      constrained_(std::move(constrained)), options_(std::move(options))
{
  if (!F_)
    throw std::invalid_argument(who + "the flexibility operator is empty");
  detail::check_coordinates(X_, dim_, who);
  check_constrained(constrained_, contact_dofs(), who);
  detail::check_iteration_options(options_, who);
  crush_node_ = Vector::Zero(X_.rows());
  set_pairs(std::move(pairs), std::move(mu));
}

void OperatorContact::set_crushing(Vector cap)
{
  detail::check_caps(cap, pairs_.size(), who + "set_crushing: ");
  cap_ = std::move(cap);
}

Vector OperatorContact::flex(Vector r) const
{
  for (std::size_t i = 0; i < constrained_.size(); ++i)
    if (constrained_[i])
      r[static_cast<Eigen::Index>(i)] = 0.0;
  Vector f = F_(r);
  ++applications_;
  if (f.size() != r.size())
    throw std::runtime_error(who + "the flexibility operator returned "
                             + std::to_string(f.size()) + " values for "
                             + std::to_string(r.size()));
  for (std::size_t i = 0; i < constrained_.size(); ++i)
    if (constrained_[i])
      f[static_cast<Eigen::Index>(i)] = 0.0;
  return f;
}

Vector OperatorContact::apply_W(const Vector& x) const
{
  return B_ * flex(B_.transpose() * x);
}

void OperatorContact::set_pairs(std::vector<ContactPair> pairs, Vector mu, Vector cap)
{
  detail::check_mu_count(mu, pairs.size(), who);
  detail::check_friction(mu, who);
  detail::check_caps(cap, pairs.size(), who + "set_pairs: ");
  auto B = gap_operator(dim_, static_cast<int>(X_.rows()), pairs);
  Vector x0 = initial_gap(pairs, X_);
  // Slip of the next increment is measured from the new pairs' gap where the bodies are.
  Vector x = up_c_.size() ? Vector(B * (up_c_ + flex(reaction_)) + x0) : x0;
  const std::vector<int> previous = detail::previous_pair_of(pairs_, pairs, X_.rows());
  Vector lambda = detail::carried_force(pairs_, lambda_, pairs, previous, dim_);
  std::vector<PairState> states = detail::carried_states(states_, previous);
  B_ = std::move(B);
  x0_ = std::move(x0);
  x_ = std::move(x);
  lambda_ = std::move(lambda);
  states_ = std::move(states);
  pairs_ = std::move(pairs);
  mu_ = std::move(mu);
  cap_ = std::move(cap);
  // Both depend on B: the scales are estimated again when solve_operator next runs.
  scales_ = OperatorScales{};
  columns_ = PairColumns{};
  columns_.slot.assign(pairs_.size(), -1);
}

void OperatorContact::use_working_set(BlockOperator block, double max_bytes,
                                      SameOnAllRanks same)
{
  block_ = std::move(block);
  max_bytes_ = block_ ? max_bytes : 0.0;
  same_ = std::move(same);
}

Matrix OperatorContact::W_columns(const std::vector<int>& pairs) const
{
  if (!block_)
    throw std::logic_error(who + "W_columns needs a block operator (use_working_set)");
  Matrix W = detail::delassus_columns(B_, constrained_, block_, pairs, dim_, who);
  ++block_products_;
  block_columns_ += static_cast<long>(pairs.size()) * dim_;
  return W;
}

bool OperatorContact::fetch_columns(const std::vector<int>& pairs)
{
  return detail::fetch_pair_columns(columns_, pairs, max_bytes_, B_.rows(), dim_, pairs_.size(),
                                    [this](const std::vector<int>& p) { return W_columns(p); });
}

SolveReport OperatorContact::solve_local(const Vector& q)
{
  SolveReport ws;
  if (block_ && max_bytes_ > 0.0)
  {
    ws = solve_working_set(dim_, columns_,
                           [this](const std::vector<int>& p) { return fetch_columns(p); }, q,
                           mu_, lambda_, states_, options_, same_, cap_);
    if (ws.converged)
      return ws;
  }
  auto W = [this](const Vector& v) { return apply_W(v); };
  if (scales_.applications == 0 && !pairs_.empty())
    scales_ = operator_scales(W, dim_, pairs());
  const Vector start = ws.lambda.size() == q.size() ? ws.lambda : lambda_;
  SolveReport r = solve_operator(dim_, W, scales_, q, mu_, start, options_, cap_);
  r.attempts.insert(r.attempts.begin(), ws.attempts.begin(), ws.attempts.end());
  return r;
}

CondensedStep OperatorContact::step(const Eigen::Ref<const Vector>& up_c)
{
  detail::check_contact_values(who + "step: ", "up_c", up_c, contact_dofs());
  const Vector q_total = B_ * up_c + x0_;
  CondensedStep r;
  // The slip of this increment is x_t − x_t,prev: remove the previous tangential gap.
  r.local_q = q_total;
  const int m = pairs(), d = dim_;
  for (int k = 0; k < m; ++k)
    for (int j = 1; j < d; ++j)
      r.local_q[k * d + j] -= x_[k * d + j];
  // The crushed surface is δ behind the elastic one (docs/crushing.md).
  for (int k = 0; k < m && cap_.size(); ++k)
    r.local_q[k * d] += crush_of(k);
  const long before = applications_, columns_before = block_columns_;
  r.report = solve_local(r.local_q);
  r.report.attempts.back() += ", " + std::to_string(applications_ - before) + " F* products, "
                              + std::to_string(block_columns_ - columns_before)
                              + " F* columns in blocks";
  if (!r.report.converged)
    throw ConvergenceError("flexcontact: increment did not converge; best residual "
                               + detail::exp3(r.report.residual) + " (tolerance "
                               + detail::exp3(options_.tolerance) + ") from " + r.report.solver
                               + " (contact_operator='factor') after "
                               + std::to_string(r.report.iterations) + " iterations",
                           r.report);
  r.lambda = r.report.lambda;
  r.gap = r.report.u; // u = W λ + q' ; the total gap adds back the previous tangential gap
  for (int k = 0; k < m; ++k)
    for (int j = 1; j < d; ++j)
      r.gap[k * d + j] += x_[k * d + j];
  r.states = r.report.states;
  if (cap_.size())
  {
    // The elastic gap; a pair at its cap deepens its slave node's crush to −x_n.
    r.crush_depth.resize(m);
    for (int k = 0; k < m; ++k)
    {
      const double before_k = crush_of(k);
      r.gap[k * d] -= before_k;
      double depth = before_k;
      if (r.states[k] == PairState::crush && -r.gap[k * d] > before_k)
      {
        depth = -r.gap[k * d];
        r.crush_work += r.lambda[k * d] * (depth - before_k);
      }
      crush_node_[pairs_[static_cast<std::size_t>(k)].slave] = depth;
      r.crush_depth[k] = depth;
    }
  }
  detail::summarize_step(r, pairs_, d, x_, B_, constrained_);
  r.alpha = Vector::Zero(0);
  r.undetermined = Matrix::Zero(0, 0);
  x_ = r.gap;
  lambda_ = r.lambda;
  states_ = r.states;
  up_c_ = up_c;
  reaction_ = r.reaction;
  return r;
}

double OperatorContact::crush_of(int k) const
{
  return crush_node_[pairs_[static_cast<std::size_t>(k)].slave];
}
} // namespace flexcontact
