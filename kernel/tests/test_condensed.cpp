// Copyright flexcontact developers. MIT licence.

/// @file test_condensed.cpp
/// @brief The condensed problem as one object: B, x0, W against hand values, Dirichlet-held
/// contact DOFs, a spring on a wall with known forces, the global friction force of rotated
/// frames, replacing F* or the pairs, and the messages of bad input.

#include "contact_testing.hpp"
#include "flexcontact/condensed.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

using namespace flexcontact;
using namespace flexcontact::testing;

namespace
{
// The message text, shown when the expected part is missing.
#define EXPECT_CONTAINS(text, part)                                                          \
  do                                                                                         \
  {                                                                                          \
    const std::string t_ = (text);                                                           \
    EXPECT_NE(t_.find(part), std::string::npos) << t_;                                       \
  } while (0)

// One 2D pair: slave node 0 above master node 1, n = (0, 1) so t = (−1, 0).
const Matrix X2 = (Matrix(2, 2) << 0.5, 0.1, 0.5, 0.0).finished();

std::vector<ContactPair> one_pair() { return {make_pair(0, {1}, {1.0}, vec({0.0, 1.0}))}; }

// A spring on a wall: the slave node hangs on springs k (normal) and k_t (tangential); the
// master node is held (its DOFs constrained), so W = diag(1/k, 1/k_t) in (n, t).
constexpr double k = 1e3, kt = 1e2, mu0 = 0.5, gap0 = 0.1;

Matrix spring_flexibility()
{
  Matrix F = Matrix::Identity(4, 4); // the held master's 1s must be zeroed by the mask
  F(0, 0) = 1.0 / kt;
  F(1, 1) = 1.0 / k;
  return F;
}

const std::vector<bool> master_held{false, false, true, true};
} // namespace

TEST(Condensed, GapOperatorInitialGapAndDelassusMatchHandValues)
{
  const Matrix F = random_spd(4, 10.0, 7);
  CondensedContact c(2, F, X2, one_pair(), vec({0.3}));
  // Row block T (e_s − e_m) with T rows n = (0, 1), t = (−1, 0).
  const Matrix B = (Matrix(2, 4) << 0, 1, 0, -1, -1, 0, 1, 0).finished();
  EXPECT_LT((Matrix(c.B()) - B).norm(), 1e-15) << Matrix(c.B());
  EXPECT_LT((c.x0() - vec({gap0, 0.0})).norm(), 1e-15) << c.x0().transpose();
  const Matrix W = B * F * B.transpose();
  EXPECT_LT((c.W() - W).norm(), 1e-14 * W.norm()) << c.W();
  EXPECT_EQ(c.pairs(), 1);
  EXPECT_EQ(c.contact_dofs(), 4);
  EXPECT_EQ(c.dim(), 2);
}

TEST(Condensed, ConstrainedDofsHaveNoFlexibilityAndNoReaction)
{
  const Matrix F = random_spd(4, 10.0, 11);
  CondensedContact c(2, F, X2, one_pair(), vec({0.3}), master_held);
  // Only the slave's block remains: W = T F_ss Tᵀ.
  const Matrix T = one_pair()[0].frame;
  const Matrix W = T * F.topLeftCorner(2, 2) * T.transpose();
  EXPECT_LT((c.W() - W).norm(), 1e-14 * W.norm());
  EXPECT_EQ(c.flexibility().rightCols(2).norm(), 0.0);
  EXPECT_EQ(c.flexibility().bottomRows(2).norm(), 0.0);

  // Pushed down through the wall: the held master's entries of r_c stay zero.
  const CondensedStep r = c.step(vec({0.0, -0.2, 0.0, 0.0}));
  EXPECT_GT(r.lambda[0], 0.0);
  EXPECT_EQ(r.reaction[2], 0.0);
  EXPECT_EQ(r.reaction[3], 0.0);
  EXPECT_LT((r.reaction.head(2) - T.transpose() * r.lambda).norm(), 1e-15 * r.lambda.norm());
}

TEST(Condensed, SpringOnWallSticksThenSlips)
{
  CondensedContact c(2, spring_flexibility(), X2, one_pair(), vec({mu0}), master_held);
  const Matrix W = (Matrix(2, 2) << 1.0 / k, 0.0, 0.0, 1.0 / kt).finished();
  EXPECT_LT((c.W() - W).norm(), 1e-15);

  // Slave pushed down by δ (past the gap) and sideways by u_x: q = (g0 − δ, −u_x).
  const double delta = 0.11, N = k * (delta - gap0);
  const double ux1 = 0.01; // k_t u_x = 1 < μN = 5: stick
  const CondensedStep s = c.step(vec({ux1, -delta, 0.0, 0.0}));
  EXPECT_EQ(s.states[0], PairState::stick);
  EXPECT_NEAR(s.lambda[0], N, 1e-10 * N);
  EXPECT_NEAR(s.lambda[1], kt * ux1, 1e-10 * N);
  EXPECT_NEAR(s.normal_force, N, 1e-10 * N);
  // Friction on the slave opposes the push along +x: t λ_t = (−k_t u_x, 0).
  EXPECT_NEAR(s.tangential_force[0], -kt * ux1, 1e-10 * N);
  EXPECT_NEAR(s.tangential_force[1], 0.0, 1e-10 * N);
  EXPECT_LT((s.reaction - vec({-kt * ux1, N, 0.0, 0.0})).norm(), 1e-10 * N);
  EXPECT_NEAR(s.slip[0], 0.0, 1e-14);
  EXPECT_LT(s.max_penetration, 1e-14);
  EXPECT_EQ(s.report.converged, true);
  EXPECT_LT((s.local_q - vec({gap0 - delta, -ux1})).norm(), 1e-15);

  // Pushed to k_t u_x = 8 > μN: slip, friction at μN, slip x_t = −(u_x − μN/k_t).
  const double ux2 = 0.08;
  const CondensedStep p = c.step(vec({ux2, -delta, 0.0, 0.0}));
  EXPECT_EQ(p.states[0], PairState::slip);
  EXPECT_NEAR(p.lambda[1], mu0 * N, 1e-10 * N);
  EXPECT_NEAR(p.tangential_force[0], -mu0 * N, 1e-10 * N);
  EXPECT_NEAR(p.gap[1], -(ux2 - mu0 * N / kt), 1e-14);
  EXPECT_NEAR(p.slip[0], p.gap[1] - s.gap[1], 1e-14);
  EXPECT_LT((p.pair_tangential.row(0) - p.tangential_force.transpose()).norm(), 1e-15 * N);
}

TEST(Condensed, TangentialForceIsGlobalForRotatedFrames2D)
{
  // Two slaves (nodes 0, 1) on held masters (2, 3); n_0 = (0, 1), n_1 = (0.6, 0.8). With
  // F*_ss = c I each W_k = c I, so a stick answer is λ_k = −q_k / c.
  const double cf = 1e-3;
  const std::vector<ContactPair> pairs{make_pair(0, {2}, {1.0}, vec({0.0, 1.0})),
                                       make_pair(1, {3}, {1.0}, vec({0.6, 0.8}))};
  const Matrix X = Matrix::Zero(4, 2); // touching: x0 = 0
  Matrix F = Matrix::Zero(8, 8);
  F.topLeftCorner(4, 4) = cf * Matrix::Identity(4, 4);
  std::vector<bool> held(8, false);
  for (int i = 4; i < 8; ++i)
    held[i] = true;
  CondensedContact c(2, F, X, pairs, vec({1.0, 1.0}), held);

  // Slave k displaced by T_kᵀ (−a_k, −b_k), so that q_k = (−a_k, −b_k): closed and sticking.
  const Vector a = vec({2e-3, 3e-3}), b = vec({1e-3, -0.5e-3});
  Vector up = Vector::Zero(8);
  for (int kk = 0; kk < 2; ++kk)
    up.segment(2 * kk, 2) = pairs[kk].frame.transpose() * vec({-a[kk], -b[kk]});
  const CondensedStep r = c.step(up);
  ASSERT_EQ(r.states[0], PairState::stick);
  ASSERT_EQ(r.states[1], PairState::stick);
  Vector expected = Vector::Zero(2);
  for (int kk = 0; kk < 2; ++kk)
  {
    EXPECT_NEAR(r.lambda[2 * kk + 1], b[kk] / cf, 1e-9);
    const Vector t = pairs[kk].frame.row(1).transpose();
    EXPECT_LT((r.pair_tangential.row(kk).transpose() - b[kk] / cf * t).norm(), 1e-9);
    expected += b[kk] / cf * t;
  }
  EXPECT_LT((r.tangential_force - expected).norm(), 1e-9) << r.tangential_force.transpose();
  // The frames differ, so the sum of λ_t in the pairs' own frames would be another vector.
  EXPECT_GT(std::abs(r.tangential_force[0] - (b[0] + b[1]) / cf), 0.1);
  EXPECT_NEAR(r.normal_force, (a[0] + a[1]) / cf, 1e-9);
}

TEST(Condensed, NewFlexibilityKeepsPairsAndHistory)
{
  CondensedContact c(2, spring_flexibility(), X2, one_pair(), vec({mu0}), master_held);
  const Vector up = vec({0.01, -0.11, 0.0, 0.0});
  const CondensedStep s = c.step(up);
  const Vector q = c.last_q();
  const Vector q_before = c.local_q(q);

  c.set_flexibility(2.0 * spring_flexibility());
  EXPECT_LT((c.W() - (Matrix(2, 2) << 2.0 / k, 0.0, 0.0, 2.0 / kt).finished()).norm(), 1e-15);
  EXPECT_EQ(c.flexibility().bottomRows(2).norm(), 0.0); // the mask still holds
  EXPECT_LT((c.local_q(q) - q_before).norm(), 1e-15);   // the gap history is kept
  // The same loading against a wall twice as soft: half the force.
  const CondensedStep h = c.step(up);
  EXPECT_NEAR(h.lambda[0], 0.5 * s.lambda[0], 1e-10 * s.lambda[0]);
  EXPECT_NEAR(h.lambda[1], 0.5 * s.lambda[1], 1e-10 * s.lambda[0]);

  EXPECT_CONTAINS(message_of([&] { c.set_flexibility(Matrix::Identity(3, 3)); }),
                  "F* is 3x3, expected 4x4");
}

TEST(Condensed, NewPairsRebuildFromStoredFlexibility)
{
  const Matrix F = random_spd(4, 10.0, 3);
  CondensedContact c(2, F, X2, one_pair(), vec({0.3}));
  const CondensedStep s = c.step(vec({0.001, -0.2, 0.0, 0.0}));
  const Vector q = c.last_q();
  const Vector q_before = c.local_q(q);
  ASSERT_GT(s.lambda[0], 0.0); // closed: there is a history to carry over

  // The same pairs again: the slip origin is the current gap, so nothing changes.
  c.set_pairs(one_pair(), vec({0.3}));
  EXPECT_LT((c.local_q(q) - q_before).norm(), 1e-15 * q.norm());

  // Master node 1 now seen along a tilted normal, with another μ.
  const std::vector<ContactPair> tilted{make_pair(0, {1}, {1.0}, vec({0.6, 0.8}))};
  c.set_pairs(tilted, vec({0.5}));
  const Matrix B = Matrix(gap_operator(2, 2, tilted));
  EXPECT_LT((Matrix(c.B()) - B).norm(), 1e-15);
  EXPECT_LT((c.x0() - initial_gap(tilted, X2)).norm(), 1e-15);
  EXPECT_LT((c.W() - B * F * B.transpose()).norm(), 1e-14 * F.norm());
  EXPECT_EQ(c.mu()[0], 0.5);
  // The slave node keeps its state, and its force in global axes as the warm start.
  ASSERT_EQ(c.solver().states().size(), 1u);
  EXPECT_EQ(c.solver().states()[0], s.states[0]);
  const Vector f_before = one_pair()[0].frame.transpose() * s.lambda;
  const Vector f_after = tilted[0].frame.transpose() * c.solver().force();
  EXPECT_LT((f_after - f_before).norm(), 1e-14 * f_before.norm());

  // A pair of another slave node starts from nothing.
  CondensedContact other(2, F, X2, one_pair(), vec({0.3}));
  other.step(vec({0.001, -0.2, 0.0, 0.0}));
  other.set_pairs({make_pair(1, {0}, {1.0}, vec({0.0, -1.0}))}, vec({0.3}));
  ASSERT_EQ(other.solver().states().size(), 1u);
  EXPECT_EQ(other.solver().states()[0], PairState::open);
  EXPECT_EQ(other.solver().force().norm(), 0.0);

  // Bad pairs leave the object as it was.
  EXPECT_CONTAINS(message_of([&] { c.set_pairs({make_pair(5, {1}, {1.0}, vec({0.0, 1.0}))},
                                           vec({0.3})); }), "slave node 5");
  EXPECT_CONTAINS(message_of([&] { c.set_pairs(tilted, vec({0.3, 0.3})); }),
                  "mu has 2 entries but there are 1 pairs");
  EXPECT_LT((Matrix(c.B()) - B).norm(), 1e-15);
  EXPECT_EQ(c.mu()[0], 0.5);
}

TEST(Condensed, HeldPairPushedIntoPenetrationIsNamed)
{
  // Both nodes held: no flexibility at all, and the prescribed motion closes the gap.
  const Matrix X = (Matrix(2, 2) << 0.25, 1e-05, 0.25, 0.0).finished();
  CondensedContact c(2, Matrix::Identity(4, 4), X, one_pair(), vec({0.3}),
                     std::vector<bool>(4, true));
  try
  {
    c.step(vec({0.0, -1.1e-05, 0.0, 0.0}));
    FAIL() << "no ConvergenceError";
  }
  catch (const ConvergenceError& e)
  {
    EXPECT_EQ(std::string(e.what()),
              "1 contact pair(s) are held by Dirichlet conditions on both sides and pushed "
              "into each other, so no contact force can separate them; e.g. the slave node at "
              "[0.25, 1e-05] penetrates by 1.000e-06 m. Release one side or change the "
              "prescribed displacements");
    EXPECT_FALSE(e.report.converged);
  }
  EXPECT_EQ(c.solver().states().size(), 0u); // nothing recorded
}

TEST(Condensed, BadSizesAreNamed)
{
  const Matrix F = Matrix::Identity(4, 4);
  const Vector mu = vec({0.3});
  auto msg = [&](auto&& make) { return message_of(make); };
  EXPECT_CONTAINS(msg([&] { CondensedContact(4, F, X2, one_pair(), mu); }), "dim is 4");
  EXPECT_CONTAINS(msg([&] { CondensedContact(2, Matrix::Identity(3, 3), X2, one_pair(), mu); }),
                  "F* is 3x3, expected 4x4");
  EXPECT_CONTAINS(msg([&] { CondensedContact(3, Matrix::Identity(6, 6), X2, one_pair(), mu); }),
                  "X is 2x2; it must have dim = 3 columns");
  EXPECT_CONTAINS(msg([&] { CondensedContact(2, F, X2, one_pair(), vec({0.3, 0.1})); }),
                  "mu has 2 entries but there are 1 pairs");
  EXPECT_CONTAINS(msg([&] { CondensedContact(2, F, X2, one_pair(), mu, {true, false}); }),
                  "constrained has 2 entries, expected 0 or n_c = 4");
  EXPECT_CONTAINS(msg([&] { CondensedContact(2, F, X2, one_pair(), vec({-1.0})); }),
                  "friction coefficient of pair 0");
  CondensedContact c(2, F, X2, one_pair(), mu);
  EXPECT_CONTAINS(msg([&] { c.step(vec({0.0, 0.0})); }), "up_c has 2 entries, expected n_c = 4");
  EXPECT_CONTAINS(msg([&] { c.step(vec({0.0, NAN, 0.0, 0.0})); }), "up_c is not finite");
  for (auto make : std::vector<std::function<void()>>{
           [&] { CondensedContact(4, F, X2, one_pair(), mu); },
           [&] { CondensedContact(2, F, X2, one_pair(), vec({0.3, 0.1})); },
           [&] { c.step(vec({0.0})); }})
    EXPECT_THROW(make(), std::invalid_argument);
}

TEST(Condensed, CondensedLoadGivesTheSameIncrementAndItsSolution)
{
  // step_condensed(b) is step(F* b) with the held DOFs' entries taken as given; solution_c
  // is u_p,c + F* r_c, the contact values of K⁻¹ (p + Bᵀ λ).
  const Matrix F = random_spd(4, 10.0, 13);
  CondensedContact a(2, F, X2, one_pair(), vec({0.3}), master_held);
  CondensedContact b(2, F, X2, one_pair(), vec({0.3}), master_held);
  const Vector load = vec({0.2, -40.0, 0.01, -0.02}); // the held master moved by (0.01, −0.02)
  Matrix Fz = F;
  Fz.rightCols(2).setZero();
  Fz.bottomRows(2).setZero();
  Vector up_c = Fz * load;
  up_c.tail(2) = load.tail(2);
  const CondensedStep r = a.step_condensed(load, Vector::Zero(0));
  const CondensedStep s = b.step(up_c);
  EXPECT_GT(s.lambda[0], 0.0);
  EXPECT_LT((r.lambda - s.lambda).norm(), 1e-14 * s.lambda.norm());
  EXPECT_LT((r.local_q - s.local_q).norm(), 1e-14 * s.local_q.norm());
  const Vector u_c = up_c + Fz * s.reaction;
  EXPECT_LT((r.solution_c - u_c).norm(), 1e-14 * u_c.norm());
  EXPECT_LT((s.solution_c - u_c).norm(), 1e-14 * u_c.norm());
  EXPECT_EQ(r.solution_c[2], 0.01);
  EXPECT_EQ(r.solution_c[3], -0.02);
  EXPECT_THROW(a.step_condensed(vec({1.0, 2.0}), Vector::Zero(0)), std::invalid_argument);
}
