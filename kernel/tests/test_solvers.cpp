// Copyright flexcontact developers. MIT licence.

/// @file test_solvers.cpp
/// @brief The projection and Alart–Curnier Newton solvers on the same hand-derived problems,
/// and against each other on random ones.

#include "contact_testing.hpp"
#include "flexcontact/solvers.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <ostream>

using namespace flexcontact;
using namespace flexcontact::testing;

namespace
{
/// @brief One solver and the bounds on its iteration count, which differ by method.
struct SolverCase
{
  std::string name; ///< also the name the solver reports
  SolveReport (*solve)(const ProblemView&, const Eigen::Ref<const Vector>&,
                       const SolverOptions&);
  /// On a single exact case: Newton's local convergence, or one projection sweep (exact
  /// local solve) plus the sweep that confirms it.
  int single_pair_iterations;
  /// What SolverOptions::max_iterations allows: the projection solver counts sweeps, 50 per
  /// iteration.
  int iterations_per_max_iteration;
};

void PrintTo(const SolverCase& s, std::ostream* os) { *os << s.name; }

class EachSolver : public ::testing::TestWithParam<SolverCase>
{
};

TEST_P(EachSolver, SinglePairExact)
{
  const SolverCase& s = GetParam();
  for (const auto& c : exact_cases())
  {
    const ProblemView p{c.dim, c.W, c.q, c.mu};
    ASSERT_LT(natural_map_residual(p, c.lambda), 1e-14) << c.name << ": expected answer wrong";
    const SolveReport r = s.solve(p, Vector(), {});
    EXPECT_TRUE(r.converged) << c.name << " residual " << r.residual;
    EXPECT_LT((r.lambda - c.lambda).norm(), 1e-10) << c.name;
    EXPECT_LE(r.iterations, s.single_pair_iterations) << c.name;
    EXPECT_EQ(r.solver, s.name);
    EXPECT_EQ(check_laws(p, r.lambda, 1e-9), "") << c.name;
  }
}

TEST_P(EachSolver, ExactStartConvergesInZeroIterations)
{
  const auto c = exact_cases()[2];
  const ProblemView p{c.dim, c.W, c.q, c.mu};
  const SolveReport r = GetParam().solve(p, c.lambda, {});
  EXPECT_TRUE(r.converged);
  EXPECT_EQ(r.iterations, 0);
}

TEST_P(EachSolver, StatesReported)
{
  const OpenStickSlipPairs c;
  const SolveReport r = GetParam().solve({3, c.W, c.q, c.mu}, Vector(), {});
  ASSERT_TRUE(r.converged);
  ASSERT_EQ(r.states.size(), 3u);
  EXPECT_EQ(r.states[0], PairState::open);
  EXPECT_EQ(r.states[1], PairState::stick);
  EXPECT_EQ(r.states[2], PairState::slip);
  EXPECT_LT((r.u - (c.W * r.lambda + c.q)).norm(), 1e-14);
}

TEST_P(EachSolver, SingularPairBlock)
{
  // Pair 1 is fully constrained (zero rows/columns of W) and opens (q_n > 0); pair 0 sticks.
  Matrix W = Matrix::Zero(4, 4);
  W.topLeftCorner(2, 2) << 2.0, 0.5, 0.5, 1.0;
  const Vector q = vec({-1.0, 0.1, 0.3, 0.2}), mu = vec({1.0, 1.0});
  const SolveReport r = GetParam().solve({2, W, q, mu}, Vector(), {});
  EXPECT_TRUE(r.converged) << r.residual;
  EXPECT_NEAR(r.lambda[0], 0.6, 1e-10);
  EXPECT_NEAR(r.lambda[1], -0.4, 1e-10);
  EXPECT_EQ(r.lambda.tail(2).norm(), 0.0);
}

TEST_P(EachSolver, UnsolvableReportsNotConverged)
{
  // Zero compliance with a penetrating gap: no finite force closes it.
  const SolverCase& s = GetParam();
  const Matrix W = Matrix::Zero(2, 2);
  const Vector q = vec({-1.0, 0.0}), mu = vec({0.3});
  SolverOptions opt;
  opt.max_iterations = 20;
  const SolveReport r = s.solve({2, W, q, mu}, Vector(), opt);
  EXPECT_FALSE(r.converged);
  EXPECT_TRUE(r.lambda.allFinite());
  EXPECT_FALSE(std::isnan(r.residual));
  EXPECT_LE(r.iterations, s.iterations_per_max_iteration * 20);
  ASSERT_EQ(r.attempts.size(), 1u);
}

TEST_P(EachSolver, RejectsBadInput)
{
  const SolverCase& s = GetParam();
  const Matrix W = Matrix::Identity(2, 2);
  Vector q = vec({-1.0, 0.0}), mu = vec({-0.1});
  EXPECT_THROW(s.solve({2, W, q, mu}, Vector(), {}), std::invalid_argument);
  mu << 0.1;
  q[1] = std::nan("");
  EXPECT_THROW(s.solve({2, W, q, mu}, Vector(), {}), std::invalid_argument);
  q[1] = 0.0;
  EXPECT_THROW(s.solve({2, W, q, mu}, Vector::Zero(3), {}), std::invalid_argument);
}

INSTANTIATE_TEST_SUITE_P(, EachSolver,
                         ::testing::Values(SolverCase{"newton_ac", solve_newton_ac, 10, 1},
                                           SolverCase{"projection", solve_projection, 2, 50}),
                         [](const auto& info) { return info.param.name; });
} // namespace

TEST(NewtonAC, AgreesWithProjectionMultiPair)
{
  // Small friction and a well-conditioned W: the solution is unique, so both must find it.
  for (int dim : {2, 3})
    for (unsigned seed = 1; seed <= 10; ++seed)
    {
      const int m = 6, n = m * dim;
      const Matrix W = random_spd(n, 10.0, seed);
      std::mt19937 gen(100 + seed);
      std::normal_distribution<double> N(0.0, 1.0);
      std::uniform_real_distribution<double> U(0.1, 0.3);
      Vector q(n), mu(m);
      for (int i = 0; i < n; ++i)
        q[i] = N(gen);
      for (int k = 0; k < m; ++k)
        mu[k] = U(gen);
      const ProblemView p{dim, W, q, mu};
      SolverOptions opt;
      opt.tolerance = 1e-12;
      const SolveReport a = solve_newton_ac(p, Vector(), opt);
      const SolveReport b = solve_projection(p, Vector(), opt);
      ASSERT_TRUE(a.converged) << "dim " << dim << " seed " << seed << " " << a.attempts[0];
      ASSERT_TRUE(b.converged) << "dim " << dim << " seed " << seed << " " << b.attempts[0];
      EXPECT_LT((a.lambda - b.lambda).norm(), 1e-8 * std::max(1.0, a.lambda.norm()))
          << "dim " << dim << " seed " << seed;
      EXPECT_EQ(check_laws(p, a.lambda, 1e-9), "");
    }
}
