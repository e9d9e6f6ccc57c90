// Copyright flexcontact developers. MIT licence.

/// @file test_increment.cpp
/// @brief The incremental driver: a block pushed sideways past μN, path dependence after
/// unloading, input validation, and a failed increment leaving the history unchanged.

#include "contact_testing.hpp"
#include "flexcontact/increment.hpp"
#include "flexcontact/solvers.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

using namespace flexcontact;
using namespace flexcontact::testing;

namespace
{
// A block on springs: normal compliance 1/k, tangential 1/k_t. Pressed down by N = k δ,
// pushed sideways by T: without contact the tangential gap would be T/k_t.
constexpr double k = 1e3, kt = 1e2, N = 10.0, mu0 = 0.5;
} // namespace

TEST(Increment, BlockPushedSidewaysPastCoulombLimit)
{
  const Matrix W = (Matrix(2, 2) << 1.0 / k, 0.0, 0.0, 1.0 / kt).finished();
  IncrementalSolver inc(2, W, vec({mu0}));
  double slip_total = 0.0;
  for (double T : {1.0, 2.0, 3.0, 4.0, 4.9, 5.5, 6.0, 7.0, 8.0})
  {
    const SolveReport& r = inc.step(vec({-N / k, T / kt}));
    ASSERT_TRUE(r.converged) << "T = " << T;
    EXPECT_NEAR(inc.force()[0], N, 1e-10 * N) << "T = " << T;
    EXPECT_LE(std::abs(inc.force()[1]), mu0 * inc.force()[0] * (1.0 + 1e-12)) << "T = " << T;
    if (T < mu0 * N)
    {
      // stick: the force holds the load and the block has not moved sideways at all
      EXPECT_EQ(inc.states()[0], PairState::stick) << "T = " << T;
      EXPECT_NEAR(inc.force()[1], -T, 1e-10 * N) << "T = " << T;
      EXPECT_NEAR(inc.gap()[1], 0.0, 1e-14) << "T = " << T;
      EXPECT_NEAR(r.u[1], 0.0, 1e-14) << "T = " << T; // zero incremental slip
    }
    else
    {
      // slip: friction at the limit, opposing the push; the excess load is slip
      EXPECT_EQ(inc.states()[0], PairState::slip) << "T = " << T;
      EXPECT_NEAR(inc.force()[1], -mu0 * N, 1e-10 * N) << "T = " << T;
      const double x_t = (T - mu0 * N) / kt;
      EXPECT_NEAR(r.u[1], x_t - slip_total, 1e-14) << "T = " << T; // this increment's slip
      EXPECT_NEAR(inc.gap()[1], x_t, 1e-14) << "T = " << T;
      slip_total = x_t;
    }
  }
  // Unloading to T = 1 sticks at the slipped position (x_t = 3/k_t): friction is path
  // dependent. The displaced spring now pulls back, so friction reverses:
  // λ_t = −k_t (1/k_t − x_t) = −(1 − 3) = 2, inside the cone.
  inc.step(vec({-N / k, 1.0 / kt}));
  EXPECT_EQ(inc.states()[0], PairState::stick);
  EXPECT_NEAR(inc.gap()[1], slip_total, 1e-14);
  EXPECT_NEAR(inc.force()[1], 2.0, 1e-10 * N);
}

TEST(Increment, SeveralPairsUnderDifferentNormalLoads)
{
  // Three independent pairs with normal loads 10, 20, 40 and one tangential load 12 each:
  // the limits μN are 5, 10, 20, so pairs 0 and 1 slip and pair 2 sticks; in 3D the load
  // along (t1 + t2)/√2 gives friction exactly opposite.
  const int m = 3, d = 3;
  Matrix W = Matrix::Zero(m * d, m * d);
  Vector q(m * d);
  const double Ns[] = {10.0, 20.0, 40.0}, T = 12.0;
  for (int p = 0; p < m; ++p)
  {
    W(p * d, p * d) = 1.0 / k;
    W(p * d + 1, p * d + 1) = W(p * d + 2, p * d + 2) = 1.0 / kt;
    q.segment(p * d, d) = vec({-Ns[p] / k, T / kt / std::sqrt(2.0), T / kt / std::sqrt(2.0)});
  }
  IncrementalSolver inc(d, W, Vector::Constant(m, mu0));
  // Ramp in four increments so that the pairs go through stick first.
  for (int i = 1; i <= 4; ++i)
  {
    Vector qi = q;
    for (int p = 0; p < m; ++p)
      qi.segment(p * d + 1, 2) *= i / 4.0;
    inc.step(qi);
  }
  for (int p = 0; p < m; ++p)
  {
    const Vector l = inc.force().segment(p * d, d);
    EXPECT_NEAR(l[0], Ns[p], 1e-9 * Ns[p]) << p;
    const double limit = mu0 * Ns[p];
    const double expected_t = std::min(T, limit);
    EXPECT_NEAR(l.tail(2).norm(), expected_t, 1e-9 * Ns[p]) << p;
    EXPECT_NEAR(l[1], l[2], 1e-9 * Ns[p]) << p;
    EXPECT_LT(l[1], 0.0) << p;
    EXPECT_EQ(inc.states()[p], T > limit ? PairState::slip : PairState::stick) << p;
  }
}

TEST(Increment, ValidationNamesWhatIsWrong)
{
  const Matrix W = Matrix::Identity(4, 4);
  EXPECT_NE(message_of([&] { IncrementalSolver(2, W, vec({0.3, -0.1})); })
                .find("friction coefficient of pair 1 is -0.1"),
            std::string::npos);
  EXPECT_NE(message_of([&] { IncrementalSolver(2, W, vec({0.3, NAN})); }).find("pair 1"),
            std::string::npos);
  EXPECT_NE(message_of([&] { IncrementalSolver(2, Matrix::Identity(4, 3), vec({0.3, 0.3})); })
                .find("square"),
            std::string::npos);
  EXPECT_THROW(IncrementalSolver(2, W, vec({0.3})), std::invalid_argument);
  EXPECT_THROW(IncrementalSolver(4, W, vec({0.3})), std::invalid_argument);
  Matrix Wn = W;
  Wn(2, 3) = INFINITY;
  EXPECT_NE(message_of([&] { IncrementalSolver(2, Wn, vec({0.3, 0.3})); }).find("W(2, 3)"),
            std::string::npos);
  EXPECT_THROW(IncrementalSolver(2, W, vec({0.3, 0.3}), chain_of({"simplex"})),
               std::invalid_argument);

  IncrementalSolver inc(2, W, vec({0.3, 0.3}));
  EXPECT_THROW(inc.step(vec({1.0, 0.0})), std::invalid_argument);
  EXPECT_NE(message_of([&] { inc.step(vec({1.0, 0.0, NAN, 0.0})); }).find("q[2]"),
            std::string::npos);
}

TEST(Increment, FailedIncrementLeavesHistoryUnchanged)
{
  const CyclingPairs c;
  IncrementalSolver inc(2, c.W, c.mu, chain_of({"active_set"}));
  inc.step(vec({1.0, 0.0, 1.0, 0.0})); // apart: open
  ASSERT_EQ(inc.states()[0], PairState::open);
  const Vector x = inc.gap(), l = inc.force();
  try
  {
    inc.step(c.q);
    FAIL() << "the cycling increment was accepted";
  }
  catch (const ConvergenceError& e)
  {
    const std::string what = e.what();
    EXPECT_NE(what.find("active_set"), std::string::npos) << what;
    EXPECT_NE(what.find("iterations"), std::string::npos) << what;
    EXPECT_NE(what.find("residual"), std::string::npos) << what;
    EXPECT_TRUE(e.report.cycled);
    EXPECT_FALSE(e.report.converged);
  }
  EXPECT_EQ(inc.gap(), x);
  EXPECT_EQ(inc.force(), l);
  EXPECT_EQ(inc.states()[0], PairState::open);

  // The default chain falls back and solves the same increment (hand solution at
  // CyclingPairs: λ = (1/15, −1/30, 53/150, 4/25)).
  IncrementalSolver robust(2, c.W, c.mu);
  robust.step(c.q);
  EXPECT_NEAR(robust.force()[0], 1.0 / 15.0, 1e-9);
  EXPECT_NEAR(robust.force()[2], 53.0 / 150.0, 1e-9);
}

// An initial tangential offset of a pair is geometry, not slip: with the initial gap set,
// a stick pair keeps it and the first increment shows no slip.
TEST(Increment, InitialGapIsNotSlip)
{
  IncrementalSolver s(2, Matrix::Identity(2, 2), vec({0.5}));
  s.set_initial_gap(vec({0.0, 0.3})); // touching, tangential offset 0.3
  const SolveReport& r = s.step(vec({-1.0, 0.3})); // pressed by 1, no tangential load
  ASSERT_TRUE(r.converged);
  EXPECT_NEAR(r.lambda[0], 1.0, 1e-12);
  EXPECT_NEAR(r.lambda[1], 0.0, 1e-12);
  EXPECT_EQ(r.states[0], PairState::stick);
  EXPECT_NEAR(s.gap()[1], 0.3, 1e-12);
  Vector bad(3);
  EXPECT_THROW(s.set_initial_gap(bad), std::invalid_argument);
}
