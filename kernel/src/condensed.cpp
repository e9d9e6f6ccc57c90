// Copyright flexcontact developers. MIT licence.

/// @file condensed.cpp
/// @brief The condensed contact problem: B, x0, W = B F* Bᵀ from pairs and F*, and one
/// increment from u_p on the contact DOFs to λ, gap, states and contact forces.

#include "carry_over.hpp"
#include "constrained.hpp"
#include "contact_checks.hpp"
#include "flexcontact/condensed.hpp"
#include "message_numbers.hpp"
#include "python_float.hpp"
#include "step_summary.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

namespace flexcontact
{
namespace
{
const std::string who = "flexcontact: CondensedContact: ";
} // namespace

CondensedContact::CondensedContact(int dim, Matrix Fstar, Matrix X,
                                   std::vector<ContactPair> pairs, Vector mu,
                                   std::vector<bool> constrained, SolverOptions options)
    : CondensedContact(dim, BlockFlexibility(std::move(Fstar)), std::move(X), std::move(pairs),
                       std::move(mu), std::move(constrained), std::move(options))
{
}

CondensedContact::CondensedContact(int dim, BlockFlexibility Fstar, Matrix X,
                                   std::vector<ContactPair> pairs, Vector mu,
                                   std::vector<bool> constrained, SolverOptions options)
    : dim_(detail::checked_dim(dim, who)), F_(std::move(Fstar)), X_(std::move(X)),
      pairs_(std::move(pairs)), mu_(std::move(mu)), constrained_(std::move(constrained)),
      options_(std::move(options)), solver_(dim_, Matrix(), Vector(), options_)
{
  detail::check_coordinates(X_, dim_, who);
  const Eigen::Index n_c = X_.rows() * dim_;
  if (F_.factored())
    detail::check_flexibility_rows(F_.rows(), n_c, "F*", who);
  else
    detail::check_flexibility(F_.given(), n_c, "F*", who);
  detail::check_mu_count(mu_, pairs_.size(), who);
  check_constrained(constrained_, n_c, who);
  F_.set_constrained(constrained_);
  // gap_operator and initial_gap check the pairs against the node count and dimension.
  B_ = gap_operator(dim_, static_cast<int>(X_.rows()), pairs_);
  x0_ = initial_gap(pairs_, X_);
  solver_ = IncrementalSolver(dim_, F_.delassus(B_), mu_, options_);
  solver_.set_initial_gap(x0_);
  R_ = Matrix::Zero(n_c, 0);
  crush_node_ = Vector::Zero(X_.rows());
}

void CondensedContact::set_crushing(Vector cap)
{
  if (cap.size() == 0)
  {
    cap_ = Vector();
    solver_.set_crushing(Vector(), Vector());
    return;
  }
  solver_.set_crushing(cap, detail::at_slaves(pairs_, crush_node_)); // checks sizes, values
  cap_ = std::move(cap);
}

void CondensedContact::set_rigid_modes(Matrix Rc)
{
  if (Rc.rows() != F_.rows())
    throw std::invalid_argument(who + "set_rigid_modes: R_c has " + std::to_string(Rc.rows())
                                + " rows, expected n_c = " + std::to_string(F_.rows()));
  if (!Rc.allFinite())
    throw std::invalid_argument(who + "set_rigid_modes: R_c is not finite");
  solver_.set_border(B_ * Rc);
  R_ = std::move(Rc);
}

void CondensedContact::set_flexibility(Matrix Fstar)
{
  detail::check_flexibility(Fstar, F_.rows(), "F*", who);
  BlockFlexibility F(std::move(Fstar));
  F.set_constrained(constrained_);
  solver_.set_delassus(F.delassus(B_));
  F_ = std::move(F);
}

void CondensedContact::set_pairs(std::vector<ContactPair> pairs, Vector mu, Vector cap)
{
  detail::check_mu_count(mu, pairs.size(), who);
  detail::check_caps(cap, pairs.size(), who + "set_pairs: ");
  // Built aside first, so that bad pairs leave the object as it was.
  auto B = gap_operator(dim_, static_cast<int>(X_.rows()), pairs);
  Vector x0 = initial_gap(pairs, X_);
  IncrementalSolver solver(dim_, F_.delassus(B), mu, options_);
  solver.set_initial_gap(u_c_.size() ? Vector(B * u_c_ + x0) : x0);
  if (!solver_.states().empty())
  {
    const std::vector<int> previous = detail::previous_pair_of(pairs_, pairs, X_.rows());
    solver.set_warm_start(detail::carried_force(pairs_, solver_.force(), pairs, previous, dim_),
                          detail::carried_states(solver_.states(), previous));
  }
  if (R_.cols())
    solver.set_border(B * R_);
  if (cap.size())
    solver.set_crushing(cap, detail::at_slaves(pairs, crush_node_));
  B_ = std::move(B);
  x0_ = std::move(x0);
  solver_ = std::move(solver);
  pairs_ = std::move(pairs);
  mu_ = std::move(mu);
  cap_ = std::move(cap);
}

std::string CondensedContact::held_and_penetrating(const Vector& q) const
{
  // A pair whose nodes are all held by Dirichlet conditions has no normal flexibility; if
  // the prescribed motion makes it penetrate, no contact force can open it and the
  // iterations would only make λ grow.
  const Matrix& W = solver_.W();
  const int m = pairs();
  double wmax = 0.0;
  for (int k = 0; k < m; ++k)
    wmax = std::max(wmax, W(k * dim_, k * dim_));
  const double rigid = 1e-12 * std::max(wmax, 1e-300);
  const double scale = std::max(q.size() ? q.cwiseAbs().maxCoeff() : 0.0, 1e-300);
  int count = 0, first = -1;
  for (int k = 0; k < m; ++k)
    if (W(k * dim_, k * dim_) <= rigid && q[k * dim_] < -1e-12 * scale
        && !(cap_.size() && cap_[k] < std::numeric_limits<double>::infinity()))
    {
      if (count++ == 0)
        first = k;
    }
  if (count == 0)
    return "";
  std::string at = "[";
  for (int c = 0; c < dim_; ++c)
    at += (c ? ", " : "") + detail::python_float(X_(pairs_[first].slave, c));
  at += "]";
  return std::to_string(count)
         + " contact pair(s) are held by Dirichlet conditions on both sides and pushed into "
           "each other, so no contact force can separate them; e.g. the slave node at "
         + at + " penetrates by " + detail::exp3(-q[first * dim_])
         + " m. Release one side or change the prescribed displacements";
}

CondensedStep CondensedContact::step(const Eigen::Ref<const Vector>& up_c)
{
  return step(up_c, Vector::Zero(R_.cols()));
}

CondensedStep CondensedContact::step_condensed(const Eigen::Ref<const Vector>& b_c,
                                               const Eigen::Ref<const Vector>& e)
{
  if (b_c.size() != F_.rows())
    throw std::invalid_argument(who + "step_condensed: b_c has " + std::to_string(b_c.size())
                                + " entries, expected n_c = " + std::to_string(F_.rows()));
  // F_ is zero on the constrained rows and columns; K's identity rows give them F* = 1.
  Vector up_c = F_.apply(b_c);
  for (std::size_t i = 0; i < constrained_.size(); ++i)
    if (constrained_[i])
      up_c[static_cast<Eigen::Index>(i)] = b_c[static_cast<Eigen::Index>(i)];
  return step(up_c, e);
}

CondensedStep CondensedContact::step(const Eigen::Ref<const Vector>& up_c,
                                     const Eigen::Ref<const Vector>& e)
{
  if (e.size() != R_.cols())
    throw std::invalid_argument(who + "step: e has " + std::to_string(e.size())
                                + " entries, expected one per rigid mode ("
                                + std::to_string(R_.cols()) + ")");
  detail::check_contact_values(who + "step: ", "up_c", up_c, F_.rows());
  q_ = B_ * up_c + x0_;
  const std::string held = held_and_penetrating(q_);
  if (!held.empty())
  {
    SolveReport none;
    none.solver = "none";
    none.attempts = {"not solved: held pairs pushed into each other"};
    throw ConvergenceError(held, std::move(none));
  }

  CondensedStep r;
  r.local_q = solver_.local_q(q_);
  const Vector previous = solver_.gap();
  r.report = solver_.step(q_, e);
  r.alpha = solver_.alpha();
  r.undetermined = r.report.undetermined;
  r.lambda = solver_.force();
  r.gap = solver_.gap();
  r.states = solver_.states();
  if (cap_.size())
  {
    r.crush_depth = solver_.crush_depth();
    r.crush_work = solver_.crush_work();
    for (int k = 0; k < pairs(); ++k)
      crush_node_[pairs_[static_cast<std::size_t>(k)].slave] = r.crush_depth[k];
  }

  detail::summarize_step(r, pairs_, dim_, previous, B_, constrained_);
  r.solution_c = up_c + F_.apply(r.reaction);
  // Kept for re-pairing: the gap of new pairs at this displacement is their slip origin.
  u_c_ = r.solution_c;
  if (R_.cols())
    u_c_ += R_ * r.alpha;
  return r;
}
} // namespace flexcontact
