// Copyright flexcontact developers. MIT licence.

#include "contact_testing.hpp"
#include "flexcontact/solvers.hpp"

#include <gtest/gtest.h>

using namespace flexcontact;
using namespace flexcontact::testing;

TEST(Projection, SinglePairExact)
{
  for (const auto& c : exact_cases())
  {
    const ProblemView p{c.dim, c.W, c.q, c.mu};
    ASSERT_LT(natural_map_residual(p, c.lambda), 1e-14) << c.name << ": expected answer wrong";
    const SolveReport r = solve_projection(p, Vector(), {});
    EXPECT_TRUE(r.converged) << c.name << " residual " << r.residual;
    EXPECT_LT((r.lambda - c.lambda).norm(), 1e-10) << c.name;
    EXPECT_LE(r.iterations, 2) << c.name; // exact local solve: one sweep
    EXPECT_EQ(r.solver, "projection");
    EXPECT_EQ(check_laws(p, r.lambda, 1e-9), "") << c.name;
  }
}

TEST(Projection, ExactStartConvergesInZeroIterations)
{
  const auto c = exact_cases()[2];
  const ProblemView p{c.dim, c.W, c.q, c.mu};
  const SolveReport r = solve_projection(p, c.lambda, {});
  EXPECT_TRUE(r.converged);
  EXPECT_EQ(r.iterations, 0);
}

TEST(Projection, StatesReported)
{
  // Three decoupled 3D pairs: open, stick, slip.
  const Matrix W = 2.0 * Matrix::Identity(9, 9);
  Vector q(9), mu(3);
  q << 1.0, 0.2, 0.0, -1.0, 0.1, 0.1, -1.0, 0.3, 0.4;
  mu << 0.4, 0.4, 0.4;
  const SolveReport r = solve_projection({3, W, q, mu}, Vector(), {});
  ASSERT_TRUE(r.converged);
  ASSERT_EQ(r.states.size(), 3u);
  EXPECT_EQ(r.states[0], PairState::open);
  EXPECT_EQ(r.states[1], PairState::stick);
  EXPECT_EQ(r.states[2], PairState::slip);
  EXPECT_LT((r.u - (W * r.lambda + q)).norm(), 1e-14);
}

TEST(Projection, SingularPairBlock)
{
  // Pair 1 is fully constrained (zero rows/columns of W) and opens (q_n > 0); pair 0 sticks.
  Matrix W = Matrix::Zero(4, 4);
  W.topLeftCorner(2, 2) << 2.0, 0.5, 0.5, 1.0;
  Vector q(4), mu(2);
  q << -1.0, 0.1, 0.3, 0.2;
  mu << 1.0, 1.0;
  const ProblemView p{2, W, q, mu};
  const SolveReport r = solve_projection(p, Vector(), {});
  EXPECT_TRUE(r.converged) << r.residual;
  EXPECT_NEAR(r.lambda[0], 0.6, 1e-10);
  EXPECT_NEAR(r.lambda[1], -0.4, 1e-10);
  EXPECT_EQ(r.lambda.tail(2).norm(), 0.0);
}

TEST(Projection, UnsolvableReportsNotConverged)
{
  // Zero compliance with a penetrating gap: no finite force closes it.
  const Matrix W = Matrix::Zero(2, 2);
  Vector q(2), mu(1);
  q << -1.0, 0.0;
  mu << 0.3;
  SolverOptions opt;
  opt.max_iterations = 20;
  const SolveReport r = solve_projection({2, W, q, mu}, Vector(), opt);
  EXPECT_FALSE(r.converged);
  EXPECT_TRUE(r.lambda.allFinite());
  EXPECT_FALSE(std::isnan(r.residual));
  EXPECT_LE(r.iterations, 50 * 20); // sweeps
  ASSERT_EQ(r.attempts.size(), 1u);
}

TEST(Projection, RejectsBadInput)
{
  const Matrix W = Matrix::Identity(2, 2);
  Vector q(2), mu(1);
  q << -1.0, 0.0;
  mu << -0.1;
  EXPECT_THROW(solve_projection({2, W, q, mu}, Vector(), {}), std::invalid_argument);
  mu << 0.1;
  q[1] = std::nan("");
  EXPECT_THROW(solve_projection({2, W, q, mu}, Vector(), {}), std::invalid_argument);
  q[1] = 0.0;
  EXPECT_THROW(solve_projection({2, W, q, mu}, Vector::Zero(3), {}), std::invalid_argument);
}
