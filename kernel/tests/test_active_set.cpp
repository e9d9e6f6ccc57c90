// Copyright flexcontact developers. MIT licence.

/// @file test_active_set.cpp
/// @brief The Feng–Touzot active-set method on hand-derived problems, and the dispatcher's
/// fallback when the plain iteration cycles.

#include "contact_testing.hpp"
#include "flexcontact/residual.hpp"
#include "flexcontact/solvers.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

using namespace flexcontact;
using namespace flexcontact::testing;

namespace
{
/// @brief The active set from scratch: no initial λ and no initial states.
SolveReport solve_cold(const ProblemView& p)
{
  return solve_active_set(p, Vector(), {}, SolverOptions{});
}

/// @brief A spring (normal k, tangential k_t) with gap g0, pushed towards a wall by δ: it
/// touches when δ > g0 and then λ_n = k (δ − g0).
struct SpringAndWall
{
  static constexpr double k = 2e3, kt = 5e2, g0 = 0.01;
  Matrix W = (Matrix(2, 2) << 1.0 / k, 0.0, 0.0, 1.0 / kt).finished();
  Vector q;
  Vector mu = vec({0.3});
  explicit SpringAndWall(double delta) : q(vec({g0 - delta, 0.0})) {}
};

/// @brief W = I, q = (−1, −2). Stick gives λ = (1, 2), outside the cone for μ = 1/2; slip with
/// s = −1: λ = (1, 1/2), u_t = 1/2 − 2 = −3/2 along s.
struct SlidingPair
{
  Matrix W = Matrix::Identity(2, 2);
  Vector q = vec({-1.0, -2.0});
  Vector mu = vec({0.5});
};

/// @brief A single pair with strong normal–tangential coupling (W_nt = 0.8): the stick
/// answer pulls (λ_n < 0) and the open answer penetrates (u_n = −1), while the answer is
/// slip. The seed's rule (stick → open on λ_n < 0) cycles stick → open → stick here; trying
/// slip first does not. Hand solution, μ = 1/2: slip against s = −1, λ_t = μ λ_n, normal
/// row λ_n + 0.8 μ λ_n = 1 ⇒ λ = (5/7, 5/14), u_t = 0.8·5/7 + 5/14 − 2 = −15/14 (along s).
struct CoupledPair
{
  Matrix W = (Matrix(2, 2) << 1.0, 0.8, 0.8, 1.0).finished();
  Vector q = vec({-1.0, -2.0});
  Vector mu = vec({0.5});
};
} // namespace

TEST(ActiveSet, SpringPressedOntoWall)
{
  const double delta = 0.03, k = SpringAndWall::k, g0 = SpringAndWall::g0;
  const SpringAndWall c(delta);
  const ProblemView p{2, c.W, c.q, c.mu};
  const SolveReport r = solve_cold(p);
  ASSERT_TRUE(r.converged) << r.residual;
  EXPECT_NEAR(r.lambda[0], k * (delta - g0), 1e-12 * k * delta);
  EXPECT_EQ(r.lambda[1], 0.0);
  EXPECT_NEAR(r.u[0], 0.0, 1e-15);
  EXPECT_EQ(r.states[0], PairState::stick);
  EXPECT_EQ(r.iterations, 1);
  EXPECT_LE(r.residual, 1e-12);
  EXPECT_FALSE(r.cycled);
}

TEST(ActiveSet, SpringNotTouchingWall)
{
  const double delta = 0.004, g0 = SpringAndWall::g0;
  const SpringAndWall c(delta);
  const ProblemView p{2, c.W, c.q, c.mu};
  const SolveReport r = solve_cold(p);
  ASSERT_TRUE(r.converged) << r.residual;
  EXPECT_EQ(r.lambda.norm(), 0.0);
  EXPECT_NEAR(r.u[0], g0 - delta, 1e-15);
  EXPECT_EQ(r.states[0], PairState::open);
  EXPECT_EQ(r.iterations, 2); // stick pulls → open, then no change
  EXPECT_EQ(r.state_changes, 1);
}

TEST(ActiveSet, TwoDimensionalSlipOpposesTheForce)
{
  const SlidingPair c;
  const ProblemView p{2, c.W, c.q, c.mu};
  const SolveReport r = solve_cold(p);
  ASSERT_TRUE(r.converged) << r.residual;
  EXPECT_NEAR(r.lambda[0], 1.0, 1e-14);
  EXPECT_NEAR(r.lambda[1], 0.5, 1e-14);
  EXPECT_NEAR(r.u[1], -1.5, 1e-14);
  EXPECT_EQ(r.states[0], PairState::slip);
}

TEST(ActiveSet, ThreeDimensionalSlipAlongTheLoad)
{
  // W = I, q = (−1, −3, −4), μ = 1/2: λ_n = 1, λ_t = μ λ_n (3, 4)/5 = (0.3, 0.4),
  // u_t = λ_t + q_t = −4.5 (0.6, 0.8).
  const Matrix W = Matrix::Identity(3, 3);
  const Vector q = vec({-1.0, -3.0, -4.0}), mu = vec({0.5});
  const ProblemView p{3, W, q, mu};
  const SolveReport r = solve_cold(p);
  ASSERT_TRUE(r.converged) << r.residual;
  EXPECT_LT((r.lambda - vec({1.0, 0.3, 0.4})).norm(), 1e-14);
  EXPECT_LT((r.u - vec({0.0, -2.7, -3.6})).norm(), 1e-14);
  EXPECT_EQ(r.states[0], PairState::slip);
}

TEST(ActiveSet, ThreeDimensionalSlipDirectionFoundIteratively)
{
  // Anisotropic tangential compliance turns the slip away from the load, so the explicit
  // method must iterate on the direction. W_nt = 0 fixes λ_n = 1 and |λ_t| = μ = 0.3.
  const Matrix W = (Matrix(3, 3) << 1.0, 0.0, 0.0, 0.0, 2.0, 0.5, 0.0, 0.5, 1.0).finished();
  const Vector q = vec({-1.0, -3.0, -1.0}), mu = vec({0.3});
  const ProblemView p{3, W, q, mu};
  const SolveReport r = solve_cold(p);
  ASSERT_TRUE(r.converged) << r.residual << " after " << r.iterations;
  EXPECT_GT(r.iterations, 2);
  EXPECT_NEAR(r.lambda[0], 1.0, 1e-9);
  const Eigen::Vector2d lt = r.lambda.tail(2), ut = r.u.tail(2);
  EXPECT_NEAR(lt.norm(), 0.3, 1e-9);
  EXPECT_NEAR(lt.dot(ut) / (lt.norm() * ut.norm()), -1.0, 1e-9); // friction opposes slip
  EXPECT_NEAR(r.u[0], 0.0, 1e-9);
}

TEST(ActiveSet, TwoPairsOneOpens)
{
  // Normal rows coupled: W_nn = [[2, 1], [1, 2]], q_n = (−1, 1); tangential W_tt = I,
  // q_t0 = −0.1. Both stick: λ_n = (1, −1), so pair 1 pulls and opens. Then pair 0 alone:
  // λ_n0 = 1/2, λ_t0 = 0.1 (inside the cone, μ = 1/2), and the open pair's gap is
  // u_n1 = 1·(1/2) + 1 = 3/2 > 0.
  Matrix W = Matrix::Zero(4, 4);
  W(0, 0) = 2.0, W(0, 2) = 1.0, W(2, 0) = 1.0, W(2, 2) = 2.0, W(1, 1) = 1.0, W(3, 3) = 1.0;
  const Vector q = vec({-1.0, -0.1, 1.0, 0.0}), mu = vec({0.5, 0.5});
  const ProblemView p{2, W, q, mu};
  const SolveReport r = solve_cold(p);
  ASSERT_TRUE(r.converged) << r.residual;
  EXPECT_LT((r.lambda - vec({0.5, 0.1, 0.0, 0.0})).norm(), 1e-14);
  EXPECT_LT((r.u - vec({0.0, 0.0, 1.5, 0.0})).norm(), 1e-14);
  EXPECT_EQ(r.states, (std::vector<PairState>{PairState::stick, PairState::open}));
  EXPECT_EQ(r.iterations, 2);
  EXPECT_EQ(r.state_changes, 1);
}

TEST(ActiveSet, FrictionlessPairSlipsFreely)
{
  SlidingPair c;
  c.mu[0] = 0.0;
  const ProblemView p{2, c.W, c.q, c.mu};
  const SolveReport r = solve_cold(p);
  ASSERT_TRUE(r.converged) << r.residual;
  EXPECT_LT((r.lambda - vec({1.0, 0.0})).norm(), 1e-14);
  EXPECT_EQ(r.states[0], PairState::slip);
}

TEST(ActiveSet, SemidefiniteWGivesFiniteAnswers)
{
  // Two pairs on one node: identical rows, W singular. Stick solves a consistent singular
  // system; any split of λ_n0 + λ_n1 = 1 is a solution.
  Matrix W(4, 4);
  W << 1, 0, 1, 0, 0, 1, 0, 1, 1, 0, 1, 0, 0, 1, 0, 1;
  const Vector q = vec({-1.0, 0.0, -1.0, 0.0}), mu = vec({0.4, 0.4});
  const ProblemView p{2, W, q, mu};
  const SolveReport r = solve_cold(p);
  ASSERT_TRUE(r.lambda.allFinite());
  EXPECT_TRUE(r.converged) << r.residual;
  EXPECT_NEAR(r.lambda[0] + r.lambda[2], 1.0, 1e-12);

  // A pair on constrained DOFs: zero rows and columns. It cannot close; with a positive gap
  // it must come out open with λ = 0, and the other pair is unaffected.
  Matrix W2 = Matrix::Zero(4, 4);
  W2(0, 0) = 1.0, W2(1, 1) = 1.0;
  const Vector q2 = vec({-1.0, 0.0, 0.5, 0.0});
  const ProblemView p2{2, W2, q2, mu};
  const SolveReport r2 = solve_cold(p2);
  ASSERT_TRUE(r2.lambda.allFinite());
  EXPECT_TRUE(r2.converged) << r2.residual;
  EXPECT_LT((r2.lambda - vec({1.0, 0.0, 0.0, 0.0})).norm(), 1e-14);
  EXPECT_EQ(r2.states[1], PairState::open);
}

TEST(ActiveSet, StartsFromGivenStates)
{
  // Starting in the answer's states, one solve confirms it.
  const SlidingPair c;
  const ProblemView p{2, c.W, c.q, c.mu};
  const SolveReport r
      = solve_active_set(p, vec({1.0, 0.5}), {PairState::slip}, SolverOptions{});
  ASSERT_TRUE(r.converged);
  EXPECT_EQ(r.iterations, 1);
  EXPECT_EQ(r.state_changes, 0);
}

TEST(ActiveSet, RejectsInconsistentInputs)
{
  const SlidingPair c;
  const ProblemView p{2, c.W, c.q, c.mu};
  EXPECT_THROW(solve_active_set(p, vec({1.0}), {}, SolverOptions{}), std::invalid_argument);
  EXPECT_THROW(solve_active_set(p, Vector(), {PairState::stick, PairState::stick},
                                SolverOptions{}),
               std::invalid_argument);
}

TEST(ActiveSet, SlipBeforeOpenSolvesTheCoupledPair)
{
  const CoupledPair c;
  const ProblemView p{2, c.W, c.q, c.mu};
  // Stick: λ = −W⁻¹ q = (−5/3, 10/3) pulls and is sheared beyond the cone → slip, not open.
  const SolveReport r = solve_cold(p);
  ASSERT_TRUE(r.converged) << r.residual;
  EXPECT_FALSE(r.cycled);
  EXPECT_NEAR(r.lambda[0], 5.0 / 7.0, 1e-12);
  EXPECT_NEAR(r.lambda[1], 5.0 / 14.0, 1e-12);
  EXPECT_NEAR(r.u[1], -15.0 / 14.0, 1e-12);
  EXPECT_EQ(r.states[0], PairState::slip);
}

TEST(ActiveSet, PlainIterationCyclesOnStrongCoupling)
{
  const CyclingPairs c;
  const ProblemView p{2, c.W, c.q, c.mu};
  const SolveReport r = solve_cold(p);
  EXPECT_TRUE(r.cycled);
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.iterations, 3);
  EXPECT_TRUE(r.lambda.allFinite());
  EXPECT_GT(r.residual, 1e-3);
}

TEST(Dispatcher, FallsBackWhenTheActiveSetCycles)
{
  const CyclingPairs c;
  const ProblemView p{2, c.W, c.q, c.mu};
  const SolveReport r = solve(p, Vector(), {}, chain_of({"active_set", "newton_ac"}));
  ASSERT_TRUE(r.converged) << r.residual;
  EXPECT_EQ(r.solver, "newton_ac");
  ASSERT_EQ(r.attempts.size(), 2u);
  EXPECT_NE(r.attempts[0].find("active_set"), std::string::npos);
  EXPECT_NE(r.attempts[0].find("cycled"), std::string::npos);
  EXPECT_NE(r.attempts[1].find("converged"), std::string::npos);
  EXPECT_LE(r.residual, 1e-10);
  EXPECT_LE(natural_map_residual(p, r.lambda), 1e-10); // certified independently
  EXPECT_NEAR(r.lambda[0], 1.0 / 15.0, 1e-9);
  EXPECT_NEAR(r.lambda[1], -1.0 / 30.0, 1e-9);
  EXPECT_NEAR(r.lambda[2], 53.0 / 150.0, 1e-9);
  EXPECT_NEAR(r.lambda[3], 4.0 / 25.0, 1e-9);
  EXPECT_NEAR(r.u[1], 106.0 / 25.0, 1e-9);
  EXPECT_EQ(r.states[0], PairState::slip);
  EXPECT_EQ(r.states[1], PairState::stick);
}

TEST(Dispatcher, DefaultChainAndNames)
{
  EXPECT_EQ(default_chain(), (std::vector<std::string>{"newton_ac", "active_set", "projection"}));
  const auto names = solver_names();
  for (const auto& n : default_chain())
    EXPECT_NE(std::find(names.begin(), names.end(), n), names.end()) << n;
  const CyclingPairs c;
  const ProblemView p{2, c.W, c.q, c.mu};
  const SolveReport r = solve(p, Vector(), {}, SolverOptions{});
  EXPECT_TRUE(r.converged);
  EXPECT_GE(r.attempts.size(), 1u);
  EXPECT_THROW(solve(p, Vector(), {}, chain_of({"simplex"})), std::invalid_argument);
}

TEST(Dispatcher, StopsAtTheFirstSolverThatConverges)
{
  const SlidingPair c;
  const ProblemView p{2, c.W, c.q, c.mu};
  const SolveReport r = solve(p, Vector(), {}, chain_of({"active_set", "newton_ac"}));
  ASSERT_TRUE(r.converged);
  EXPECT_EQ(r.solver, "active_set");
  EXPECT_EQ(r.attempts.size(), 1u);
}

// The default chain starts with a few projection sweeps and records them; the answer is
// still certified by the natural map, and a named chain gets no warm start.
TEST(Dispatcher, DefaultChainWarmStartIsRecordedOnLargeProblems)
{
  // Small: Newton directly (a dense step costs less than the sweeps would save).
  const CyclingPairs c;
  const ProblemView p{2, c.W, c.q, c.mu};
  const SolveReport r = solve(p, Vector(), {}, SolverOptions{});
  ASSERT_TRUE(r.converged);
  ASSERT_GE(r.attempts.size(), 1u);
  EXPECT_EQ(r.attempts[0].find("warm start"), std::string::npos) << r.attempts[0];
  EXPECT_LE(natural_map_residual(p, r.lambda), 1e-10);
  EXPECT_NEAR(r.lambda[2], 53.0 / 150.0, 1e-9);

  // 400 unknowns: 50 projection sweeps first, recorded as the first attempt.
  const int m = 200;
  const Matrix A = Matrix::Random(2 * m, 2 * m);
  const Matrix W = A * A.transpose() / (2.0 * m) + Matrix::Identity(2 * m, 2 * m);
  Vector q = Vector::Constant(2 * m, -1.0);
  const Vector mu = Vector::Constant(m, 0.3);
  const ProblemView big{2, W, q, mu};
  const SolveReport rb = solve(big, Vector(), {}, SolverOptions{});
  ASSERT_TRUE(rb.converged);
  EXPECT_NE(rb.attempts[0].find("projection"), std::string::npos) << rb.attempts[0];
  EXPECT_NE(rb.attempts[0].find("warm start"), std::string::npos) << rb.attempts[0];
  EXPECT_LE(natural_map_residual(big, rb.lambda), 1e-10);
  const SolveReport named = solve(big, Vector(), {}, chain_of({"newton_ac"}));
  ASSERT_GE(named.attempts.size(), 1u);
  EXPECT_EQ(named.attempts[0].find("warm start"), std::string::npos);
}

// A tangent along which both nodes are held (zero row and column of W, no prescribed slip)
// leaves that friction component undetermined by the contact laws; every chain reports the
// admissible value that moves nothing and is carried by the supports: zero. With a
// prescribed slip along that tangent (q_t ≠ 0) the friction is determined and kept.
TEST(Dispatcher, FrictionAlongAHeldTangentIsZero)
{
  const Matrix W = vec({1.0, 0.0, 1.0}).asDiagonal();
  const Vector mu = vec({0.3});
  struct Case
  {
    Vector q, expected;
    PairState state;
  };
  const std::vector<Case> cases{
      {vec({-1.0, 0.0, 0.1}), vec({1.0, 0.0, -0.1}), PairState::stick},  // sticks along t2
      {vec({-1.0, 0.0, 1.0}), vec({1.0, 0.0, -0.3}), PairState::slip},   // slips along t2
      {vec({-1.0, 0.5, 0.0}), vec({1.0, -0.3, 0.0}), PairState::slip}};  // prescribed slip
  for (const auto& c : cases)
    for (const auto& chain : std::vector<std::vector<std::string>>{
             {}, {"projection"}, {"newton_ac"}, {"active_set"}})
    {
      const ProblemView p{3, W, c.q, mu};
      const SolveReport r = solve(p, Vector(), {}, chain_of(chain));
      // The seed's active set starts in stick, where the held tangent's row 0·λ_t = −q_t has
      // no solution; λ_t stays 0, inside the cone, so its stick → slip rule never fires. It
      // reports failure (residual 0.26), and the default chain answers instead.
      if (chain == std::vector<std::string>{"active_set"} && c.q[1] != 0.0)
      {
        EXPECT_FALSE(r.converged) << r.lambda;
        continue;
      }
      const std::string what = (chain.empty() ? "default" : chain[0]) + ", q = ("
                               + std::to_string(c.q[1]) + ", " + std::to_string(c.q[2]) + ")";
      ASSERT_TRUE(r.converged) << what;
      EXPECT_LE((r.lambda - c.expected).cwiseAbs().maxCoeff(), 1e-9) << what << "\n" << r.lambda;
      EXPECT_EQ(r.states[0], c.state) << what;
    }
}
