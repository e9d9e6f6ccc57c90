// Copyright flexcontact developers. MIT licence.

/// @file impact.cpp
/// @brief The contact part of a Moreau–Jean time step: index set from the predicted gap,
/// the velocity-level local problem on it (restitution folded into q), impulses back to the
/// contact DOFs, and the contact terms of the energy balance.

#include "constrained.hpp"
#include "contact_checks.hpp"
#include "message_numbers.hpp"
#include "pair_columns.hpp"
#include "flexcontact/impact.hpp"
#include "flexcontact/increment.hpp"
#include "flexcontact/solvers.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace flexcontact
{
namespace
{
const std::string who = "flexcontact: ImpactContact: ";
using detail::num;

void check_dt(double dt)
{
  if (!std::isfinite(dt) || !(dt > 0.0))
    throw std::invalid_argument(who + "dt_s is " + num(dt) + "; it must be finite and > 0");
}

void check_mu(const Vector& mu, std::size_t m)
{
  detail::check_mu_count(mu, m, who);
  detail::check_friction(mu, who);
}

void check_vector(const char* name, const Eigen::Ref<const Vector>& v, Eigen::Index n)
{
  detail::check_contact_values(who + "step: ", name, v, n);
}

} // namespace

ImpactContact::ImpactContact(int dim, Matrix Fhat, Matrix X, std::vector<ContactPair> pairs,
                             Vector mu, double restitution, double dt_s, double theta,
                             std::vector<bool> constrained, SolverOptions options)
    : dim_(dim), F_(std::move(Fhat)), X_(std::move(X)), pairs_(std::move(pairs)),
      mu_(std::move(mu)), e_(restitution), dt_(dt_s), theta_(theta),
      constrained_(std::move(constrained)), options_(std::move(options))
{
  check_scheme();
  detail::check_flexibility(F_, contact_dofs(), "Fhat", who);
  check_mu(mu_, pairs_.size());
  zero_constrained(F_, constrained_, who);
  start();
  W_ = delassus(B_, F_);
  keep_read_rows();
  find_blocks();
}

void ImpactContact::find_blocks()
{
  // A block may end before DOF k when no entry couples the DOFs before k with those from
  // k on: no nonzero of the columns before k lies in a row ≥ k, nor one of the columns from
  // k on in a row < k.
  const Eigen::Index n = F_.rows();
  std::vector<Eigen::Index> last(n, -1), first(n, n);
  for (Eigen::Index j = 0; j < n; ++j)
    for (Eigen::Index i = 0; i < n; ++i)
      if (F_(i, j) != 0.0)
      {
        first[j] = std::min(first[j], i);
        last[j] = i;
      }
  std::vector<Eigen::Index> reach_below(n + 1, -1); // max last row of columns < k
  for (Eigen::Index k = 0; k < n; ++k)
    reach_below[k + 1] = std::max(reach_below[k], last[k]);
  std::vector<Eigen::Index> reach_above(n + 1, n);  // min first row of columns ≥ k
  for (Eigen::Index k = n - 1; k >= 0; --k)
    reach_above[k] = std::min(reach_above[k + 1], first[k]);
  blocks_.assign(1, 0);
  for (Eigen::Index k = 1; k < n; ++k)
    if (reach_below[k] < k && reach_above[k] >= k)
      blocks_.push_back(k);
  blocks_.push_back(n);
  symmetric_.assign(blocks_.size() - 1, false);
  for (std::size_t b = 0; b + 1 < blocks_.size(); ++b)
  {
    const Eigen::Index a = blocks_[b], s = blocks_[b + 1] - a;
    const auto block = F_.block(a, a, s, s);
    const double tol = 1e-12 * block.cwiseAbs().maxCoeff();
    bool sym = true;
    for (Eigen::Index j = 0; j < s && sym; ++j)
      for (Eigen::Index i = j + 1; i < s; ++i)
        if (std::abs(block(i, j) - block(j, i)) > tol)
        {
          sym = false;
          break;
        }
    symmetric_[b] = sym;
  }
}

Vector ImpactContact::product(const Vector& x) const
{
  Vector y = Vector::Zero(x.size());
  std::vector<Eigen::Index> nonzero;
  for (std::size_t b = 0; b + 1 < blocks_.size(); ++b)
  {
    const Eigen::Index a = blocks_[b], s = blocks_[b + 1] - a;
    nonzero.clear();
    for (Eigen::Index j = a; j < a + s; ++j)
      if (x[j] != 0.0)
        nonzero.push_back(j);
    if (nonzero.empty())
      continue;
    // A contact reaction lives on the closed pairs' DOFs only: reading just their columns
    // (contiguous, F̂ is column-major) costs nnz/s of the block. Past half, the whole block
    // product is as cheap and better vectorised.
    if (2 * static_cast<Eigen::Index>(nonzero.size()) < s)
      for (Eigen::Index j : nonzero)
        y.segment(a, s).noalias() += x[j] * F_.col(j).segment(a, s);
    else if (symmetric_[b])
      // The product streams the block from memory: its lower triangle is half the bytes.
      y.segment(a, s).noalias()
          = F_.block(a, a, s, s).selfadjointView<Eigen::Lower>() * x.segment(a, s);
    else
      y.segment(a, s).noalias() = F_.block(a, a, s, s) * x.segment(a, s);
  }
  return y;
}

void ImpactContact::keep_read_rows()
{
  read_.clear();
  for (Eigen::Index j = 0; j < B_.outerSize(); ++j)
    if (Eigen::SparseMatrix<double>::InnerIterator(B_, j))
      read_.push_back(j);
  if (2 * static_cast<Eigen::Index>(read_.size()) > F_.rows())
  {
    read_.clear();
    F_read_.resize(0, 0);
    return;
  }
  F_read_.resize(static_cast<Eigen::Index>(read_.size()), F_.cols());
  for (std::size_t a = 0; a < read_.size(); ++a)
    F_read_.row(static_cast<Eigen::Index>(a)) = F_.row(read_[a]);
}

void ImpactContact::check_scheme() const
{
  detail::checked_dim(dim_, who);
  detail::check_coordinates(X_, dim_, who);
  if (!(e_ >= 0.0 && e_ <= 1.0))
    throw std::invalid_argument(who + "restitution is " + num(e_)
                                + "; it must lie in [0, 1]");
  check_dt(dt_);
  if (!(theta_ >= 0.5 && theta_ <= 1.0))
    throw std::invalid_argument(who + "theta is " + num(theta_) + "; it must lie in [0.5, 1]");
}

void ImpactContact::start()
{
  B_ = gap_operator(dim_, static_cast<int>(X_.rows()), pairs_);
  x0_ = initial_gap(pairs_, X_);
  last_P_ = Vector::Zero(static_cast<Eigen::Index>(pairs_.size()) * dim_);
  last_states_.assign(pairs_.size(), PairState::open);
  crush_node_ = Vector::Zero(X_.rows());
}

ImpactContact::ImpactContact(int dim, BlockOperator Fhat, Matrix X,
                             std::vector<ContactPair> pairs, Vector mu, double restitution,
                             double dt_s, double theta, std::vector<bool> constrained,
                             SolverOptions options, double max_bytes)
    : dim_(dim), X_(std::move(X)), pairs_(std::move(pairs)), mu_(std::move(mu)),
      e_(restitution), dt_(dt_s), theta_(theta), constrained_(std::move(constrained)),
      options_(std::move(options)), block_(std::move(Fhat)), max_bytes_(max_bytes)
{
  if (!block_)
    throw std::invalid_argument(who + "the factor path needs a block operator Fhat");
  check_scheme();
  if (!(max_bytes_ > 0.0))
    throw std::invalid_argument(who + "max_bytes is " + num(max_bytes_)
                                + "; the factor path needs room for W_eff's columns");
  check_constrained(constrained_, contact_dofs(), who);
  check_mu(mu_, pairs_.size());
  start();
  columns_.slot.assign(pairs_.size(), -1);
}

void ImpactContact::set_crushing(Vector cap)
{
  detail::check_caps(cap, pairs_.size(), who);
  cap_ = std::move(cap);
}

void ImpactContact::set_block_flexibility(BlockOperator Fhat, double dt_s)
{
  if (!factor_path())
    throw std::logic_error(who + "set_block_flexibility: this object holds F̂ (dense path)");
  check_dt(dt_s);
  if (!Fhat)
    throw std::invalid_argument(who + "set_block_flexibility: no block operator");
  block_ = std::move(Fhat);
  dt_ = dt_s;
  columns_ = PairColumns{};
  columns_.slot.assign(pairs_.size(), -1);
}

void ImpactContact::set_flexibility(Matrix Fhat, double dt_s)
{
  if (factor_path())
    throw std::logic_error(who + "set_flexibility: this object applies F̂ through a factor (set_block_flexibility)");
  check_dt(dt_s);
  detail::check_flexibility(Fhat, F_.rows(), "Fhat", who);
  zero_constrained(Fhat, constrained_, who);
  W_ = delassus(B_, Fhat);
  F_ = std::move(Fhat);
  dt_ = dt_s;
  keep_read_rows();
  find_blocks();
}

void ImpactContact::set_pairs(std::vector<ContactPair> pairs, Vector mu, Vector cap)
{
  check_mu(mu, pairs.size());
  detail::check_caps(cap, pairs.size(), who);
  // Built aside first, so that bad pairs leave the object as it was.
  auto B = gap_operator(dim_, static_cast<int>(X_.rows()), pairs);
  Vector x0 = initial_gap(pairs, X_);
  Matrix W = factor_path() ? Matrix() : delassus(B, F_);
  if (pairs.size() != pairs_.size())
  {
    last_P_ = Vector::Zero(static_cast<Eigen::Index>(pairs.size()) * dim_);
    last_states_.assign(pairs.size(), PairState::open);
  }
  B_ = std::move(B);
  x0_ = std::move(x0);
  W_ = std::move(W);
  pairs_ = std::move(pairs);
  mu_ = std::move(mu);
  cap_ = std::move(cap);
  columns_ = PairColumns{}; // they depend on B
  columns_.slot.assign(pairs_.size(), -1);
  if (!factor_path())
    keep_read_rows();
}

ImpactStep ImpactContact::step(const Eigen::Ref<const Vector>& u_c,
                               const Eigen::Ref<const Vector>& v_c,
                               const Eigen::Ref<const Vector>& vfree_c)
{
  check_vector("u_c", u_c, contact_dofs());
  check_vector("v_c", v_c, contact_dofs());
  check_vector("vfree_c", vfree_c, contact_dofs());
  const int m = pairs(), d = dim_;
  ImpactStep r;
  r.gap = B_ * u_c + x0_;
  r.velocity_before = B_ * v_c;
  const Vector Ufree = B_ * vfree_c;
  r.active.assign(m, false);
  for (int k = 0; k < m; ++k)
  {
    // Predicted gap at θ of the step: pairs that may close within it take part.
    const double predicted = r.gap[k * d] + crush_of(k) + dt_ * theta_ * r.velocity_before[k * d];
    r.active[k] = predicted <= 0.0;
    r.active_pairs += r.active[k] ? 1 : 0;
  }
  r.impulse = Vector::Zero(m * d);
  r.states.assign(m, PairState::open);
  if (r.active_pairs > 0)
    solve_active(r, Ufree);
  else
  {
    r.report.solver = "none";
    r.report.converged = true;
    r.report.residual = 0.0;
  }
  if (factor_path())
  {
    // P is zero outside the index set, whose columns the solve fetched.
    std::vector<int> act;
    Vector P_act(static_cast<Eigen::Index>(r.active_pairs) * dim_);
    for (int k = 0; k < m; ++k)
      if (r.active[k])
      {
        P_act.segment(static_cast<Eigen::Index>(act.size()) * d, d) = r.impulse.segment(k * d, d);
        act.push_back(k);
      }
    r.velocity = detail::full_u(columns_, act, P_act, Ufree, d);
  }
  else
    r.velocity = Ufree + impulse_effect(r);
  finish(r);
  if (cap_.size())
    crush(r);
  last_P_ = r.impulse;
  last_states_ = r.states;
  return r;
}

ImpactStep ImpactContact::step_condensed(const Eigen::Ref<const Vector>& u_c,
                                         const Eigen::Ref<const Vector>& v_c,
                                         const Eigen::Ref<const Vector>& b_c)
{
  if (factor_path())
    throw std::logic_error(who + "step_condensed needs F̂; on the factor path use step() with "
                                 "the free velocity of a full solve");
  check_vector("b_c", b_c, contact_dofs());
  check_vector("v_c", v_c, contact_dofs());
  // F_ has the held rows and columns zeroed; Ŵ's identity rows give them (Ŵ⁻¹)_ii = 1.
  // Before the solve only the DOFs that B reads need v_free; when they are few, the whole
  // velocity change F̂ (b̃_c + r_c) is then one product with F̂ instead of two. When they
  // are many, F̂ b̃_c is formed whole before the solve and only F̂ r_c after it, which reads
  // the closed pairs' columns only. A body at rest (b̃_c = 0) and a step without impulse
  // cost no product at all.
  const auto held = [&](Eigen::Index i)
  { return static_cast<std::size_t>(i) < constrained_.size() && constrained_[i]; };
  const bool loaded = !(b_c.array() == 0.0).all();
  Vector vfree_c = v_c;
  if (loaded && !read_.empty())
  {
    const Vector dv = F_read_ * b_c;
    for (std::size_t a = 0; a < read_.size(); ++a)
    {
      const Eigen::Index i = read_[a];
      vfree_c[i] += held(i) ? b_c[i] : dv[static_cast<Eigen::Index>(a)];
    }
  }
  Vector dv_load; // F̂ b̃_c when formed whole: the reaction's part is then added to it
  if (loaded && read_.empty())
  {
    dv_load = product(b_c);
    for (Eigen::Index i = 0; i < dv_load.size(); ++i)
      vfree_c[i] += held(i) ? b_c[i] : dv_load[i];
  }
  ImpactStep r = step(u_c, v_c, vfree_c);
  const Vector load = b_c + r.reaction;
  if (dv_load.size())
    r.velocity_change_c = dv_load + product(r.reaction);
  else
    r.velocity_change_c = (load.array() == 0.0).all() ? Vector::Zero(load.size())
                                                      : product(load);
  // r_c is zero on held DOFs, where F_'s zeroed rows leave b̃_c's value to set.
  for (Eigen::Index i = 0; i < load.size(); ++i)
    if (held(i))
      r.velocity_change_c[i] = b_c[i];
  r.velocity_c = v_c + r.velocity_change_c;
  return r;
}

void ImpactContact::solve_active(ImpactStep& r, const Vector& Ufree)
{
  const int m = pairs(), d = dim_;
  std::vector<int> idx; // unknowns of the active pairs
  std::vector<int> act;
  for (int k = 0; k < m; ++k)
    if (r.active[k])
    {
      act.push_back(k);
      for (int j = 0; j < d; ++j)
        idx.push_back(k * d + j);
    }
  const Eigen::Index n = static_cast<Eigen::Index>(idx.size());
  Matrix W(n, n);
  if (factor_path())
  {
    fetch(act);
    W = detail::restricted_W(columns_, act, d);
  }
  else
    for (Eigen::Index a = 0; a < n; ++a)
      for (Eigen::Index b = 0; b < n; ++b)
        W(a, b) = W_(idx[a], idx[b]);
  Vector q(n), mu(act.size()), P0(n);
  std::vector<PairState> s0(act.size());
  for (Eigen::Index a = 0; a < n; ++a)
  {
    q[a] = Ufree[idx[a]];
    P0[a] = last_P_[idx[a]];
  }
  for (std::size_t a = 0; a < act.size(); ++a)
  {
    // Newton's law U_n⁺ ≥ −e U_n⁻ becomes x_n = U_n⁺ + e U_n⁻ ≥ 0, a shift of q only.
    // It is a law for closing pairs. A pair of the index set that opens at the start of
    // the step (U_n⁻ > 0, already overlapping) gets x_n = U_n⁺ + (1 − θ)/θ U_n⁻ = U_n^θ/θ
    // instead: its gap may not shrink over the step, and its impulse does no work
    // (P_n U_n^θ = 0) where Newton's law would let it do positive work (1 − θ − θe) P_n U_n⁻.
    const double Un = r.velocity_before[act[a] * d];
    q[a * d] += (Un <= 0.0 ? e_ : (1.0 - theta_) / theta_) * Un;
    mu[a] = mu_[act[a]];
    s0[a] = last_states_[act[a]] == PairState::open ? PairState::stick : last_states_[act[a]];
  }
  Vector cap;
  if (cap_.size())
  {
    cap.resize(static_cast<Eigen::Index>(act.size()));
    for (std::size_t a = 0; a < act.size(); ++a)
      cap[static_cast<Eigen::Index>(a)] = cap_[act[a]] * dt_; // a cap on the impulse
  }
  const ProblemView view{d, W, q, mu, cap.size() ? cap.data() : nullptr};
  SolveReport rep = solve(view, P0, s0, options_);
  if (!rep.converged)
  {
    std::string what = who + "time step contact did not converge; best residual "
                       + num(rep.residual) + " (tolerance " + num(options_.tolerance)
                       + ") from " + rep.solver + ". Tried:";
    for (const auto& a : rep.attempts)
      what += " [" + a + "]";
    throw ConvergenceError(what, std::move(rep),
                           std::make_shared<const LocalProblem>(LocalProblem{
                               d, W, q, mu, cap, P0, s0, options_, "ImpactSolver: time step"}));
  }
  for (Eigen::Index a = 0; a < n; ++a)
    r.impulse[idx[a]] = rep.lambda[a];
  for (std::size_t a = 0; a < act.size(); ++a)
    r.states[act[a]] = rep.states[a];
  r.report = std::move(rep);
}

Vector ImpactContact::impulse_effect(const ImpactStep& r) const
{
  // P is zero outside the index set. When few pairs are in it, their columns of W (column
  // major, so contiguous) are all the product needs: at the main job's 1,400 crushing
  // pairs, W is 140 MB, read whole each step for an index set of a few hundred at most.
  const int m = pairs(), d = dim_;
  if (2 * r.active_pairs >= m)
    return W_ * r.impulse;
  Vector y = Vector::Zero(W_.rows());
  for (int k = 0; k < m; ++k)
    if (r.active[k])
      y.noalias() += W_.middleCols(k * d, d) * r.impulse.segment(k * d, d);
  return y;
}

void ImpactContact::finish(ImpactStep& r) const
{
  const int m = pairs(), d = dim_;
  r.slave_impulse = Vector::Zero(d);
  r.pair_tangential = Matrix::Zero(m, d);
  // The works are taken at the θ-velocity: u⁺ − u⁻ = h v_θ, so U_θ h is the relative
  // displacement of the step (the slip, for the tangential rows) and P·U_θ is exactly the
  // contact term of the scheme's energy balance for every θ (docs/impact.md).
  const Vector Utheta = theta_ * r.velocity + (1.0 - theta_) * r.velocity_before;
  double min_gap = 0.0;
  for (int k = 0; k < m; ++k)
  {
    const Matrix& T = pairs_[k].frame;
    r.normal_impulse += r.impulse[k * d];
    r.slave_impulse += T.transpose() * r.impulse.segment(k * d, d);
    min_gap = std::min(min_gap, r.gap[k * d] + crush_of(k));
    for (int j = 1; j < d; ++j)
    {
      r.pair_tangential.row(k) += r.impulse[k * d + j] * T.row(j);
      r.friction_work += r.impulse[k * d + j] * Utheta[k * d + j];
    }
  }
  r.contact_work = r.impulse.dot(Utheta);
  r.max_penetration = std::max(0.0, -min_gap);
  r.reaction = B_.transpose() * r.impulse;
  for (std::size_t i = 0; i < constrained_.size(); ++i)
    if (constrained_[i])
      r.reaction[static_cast<Eigen::Index>(i)] = 0.0;
}

void ImpactContact::fetch(const std::vector<int>& pairs)
{
  const bool held = detail::fetch_pair_columns(
      columns_, pairs, max_bytes_, B_.rows(), dim_, pairs_.size(),
      [this](const std::vector<int>& p)
      {
        ++block_products_;
        block_columns_ += static_cast<long>(p.size()) * dim_;
        return detail::delassus_columns(B_, constrained_, block_, p, dim_, who);
      });
  if (!held)
    throw std::runtime_error(
        who + "the index set's " + std::to_string(pairs.size()) + " pairs need "
        + num(8.0 * static_cast<double>(B_.rows()) * dim_ * static_cast<double>(pairs.size()) / 1e9)
        + " GB for W_eff's columns, more than the " + num(max_bytes_ / 1e9) + " GB allowed");
}

double ImpactContact::crush_of(int k) const
{
  return cap_.size() ? crush_node_[pairs_[static_cast<std::size_t>(k)].slave] : 0.0;
}

void ImpactContact::crush(ImpactStep& r)
{
  // A pair at its cap crushes by what its crushed surface would otherwise overlap at the end
  // of the step, −(g_n + δ + h U_n^θ) (the gap moves by h U_n^θ, the θ-velocity of the
  // scheme's energy balance), but by no more than the surfaces approached in the step,
  // h max(0, −U_n^θ). While it crushes, g + δ stays at zero and the two agree. Measured from
  // the gap, the increment is continuous where a pair reaches its cap within the step, so
  // the answer does not hang on which side of the cap the rounding puts the impulse; the
  // bound keeps a gap the velocity-level scheme let drift from counting as crush, so the
  // crushing work (capped force × increment) never exceeds the pair's share of the contact
  // work and the contact dissipation stays ≥ 0.
  const int d = dim_;
  const Vector Utheta = theta_ * r.velocity + (1.0 - theta_) * r.velocity_before;
  for (int k = 0; k < pairs(); ++k)
  {
    if (r.states[k] != PairState::crush)
      continue;
    const double approach = -dt_ * Utheta[k * d];
    const double overlap = std::min(-(r.gap[k * d] + crush_of(k)) + approach, approach);
    if (overlap > 0.0)
    {
      crush_node_[pairs_[static_cast<std::size_t>(k)].slave] += overlap;
      r.crush_work += r.impulse[k * d] / dt_ * overlap;
    }
  }
  r.crush_depth.resize(pairs());
  for (int k = 0; k < pairs(); ++k)
    r.crush_depth[k] = crush_of(k);
}
} // namespace flexcontact
