// Copyright flexcontact developers. MIT licence.

/// Property tests: on random SPD problems every solver either certifies its answer (residual
/// and the contact laws checked independently) or says it did not converge; it never returns
/// NaN and never runs past its iteration cap.

#include "contact_testing.hpp"
#include "flexcontact/solvers.hpp"

#include <gtest/gtest.h>
#include <chrono>
#include <cstdio>
#include <functional>

using namespace flexcontact;
using namespace flexcontact::testing;

namespace
{
struct RandomProblem
{
  int dim;
  Matrix W;
  Vector q, mu;
  ProblemView view() const { return {dim, W, q, mu}; }
};

/// @brief m pairs in dim d, W SPD with condition number cond, q ~ N(0,1)·qscale (about half
/// the pairs pushed into contact), μ uniform in [0.1, 1].
RandomProblem make_problem(int dim, int m, double cond, unsigned seed, double wscale = 1.0,
                           double qscale = 1.0)
{
  RandomProblem r{dim, random_spd(m * dim, cond, seed, wscale), Vector(m * dim), Vector(m)};
  std::mt19937 gen(seed + 7919);
  std::normal_distribution<double> N(0.0, qscale);
  std::uniform_real_distribution<double> U(0.1, 1.0);
  for (int i = 0; i < m * dim; ++i)
    r.q[i] = N(gen);
  for (int k = 0; k < m; ++k)
    r.mu[k] = U(gen);
  return r;
}

using Solver = std::function<SolveReport(const ProblemView&, const SolverOptions&)>;

struct Outcome
{
  int converged = 0, total = 0, max_iterations = 0;
};

/// @brief Runs one solver and checks the property; returns whether it converged.
void check_property(const RandomProblem& rp, const Solver& solve, const SolverOptions& opt,
                    int iteration_cap, const std::string& what, Outcome& out)
{
  const ProblemView p = rp.view();
  const SolveReport r = solve(p, opt);
  ++out.total;
  out.max_iterations = std::max(out.max_iterations, r.iterations);
  ASSERT_EQ(r.lambda.size(), p.q.size()) << what;
  EXPECT_TRUE(r.lambda.allFinite()) << what;
  EXPECT_TRUE(r.u.allFinite()) << what;
  EXPECT_FALSE(std::isnan(r.residual)) << what;
  EXPECT_LE(r.iterations, iteration_cap) << what;
  // The report's residual is the certified one, not the solver's own stopping test.
  const double res = natural_map_residual(p, r.lambda);
  if (std::isfinite(res))
  {
    EXPECT_NEAR(r.residual, res, 1e-12 + 1e-6 * res) << what;
  }
  if (r.converged)
  {
    ++out.converged;
    EXPECT_LE(res, opt.tolerance) << what;
    EXPECT_EQ(check_laws(p, r.lambda, 1e-7), "") << what;
  }
}

void run_family(int dim, int m, const std::vector<double>& conds, unsigned seeds, bool newton,
                bool projection, int max_iterations = 100)
{
  SolverOptions opt;
  opt.tolerance = 1e-10;
  opt.max_iterations = max_iterations;
  Outcome on, op, oa;
  for (double cond : conds)
    for (unsigned s = 1; s <= seeds; ++s)
    {
      const RandomProblem rp = make_problem(dim, m, cond, 1000 * m + 31 * s + dim);
      const std::string what = "dim " + std::to_string(dim) + " pairs " + std::to_string(m)
                               + " cond " + std::to_string(cond) + " seed " + std::to_string(s);
      if (newton)
        check_property(
            rp, [](const ProblemView& p, const SolverOptions& o)
            { return solve_newton_ac(p, Vector(), o); },
            opt, opt.max_iterations, "newton_ac " + what, on);
      if (projection)
        check_property(
            rp, [](const ProblemView& p, const SolverOptions& o)
            { return solve_projection(p, Vector(), o); },
            opt, 50 * opt.max_iterations, "projection " + what, op);
      // The plain active set may cycle or stop (that is why it is not first in the chain),
      // but whatever it returns must be certified or flagged, never NaN, never endless.
      check_property(
          rp, [](const ProblemView& p, const SolverOptions& o)
          { return solve_active_set(p, Vector(), {}, o); },
          opt, opt.max_iterations, "active_set " + what, oa);
    }
  // Recorded so that a regression in robustness shows up in the log, not just in failures.
  if (newton)
    ::testing::Test::RecordProperty("newton_converged", std::to_string(on.converged) + "/" + std::to_string(on.total));
  if (projection)
    ::testing::Test::RecordProperty("projection_converged",
                   std::to_string(op.converged) + "/" + std::to_string(op.total));
  std::printf("[   info   ] dim %d pairs %d: newton_ac %d/%d converged (max %d it), "
              "projection %d/%d (max %d sweeps), active_set %d/%d (max %d it)\n",
              dim, m, on.converged, on.total, on.max_iterations, op.converged, op.total,
              op.max_iterations, oa.converged, oa.total, oa.max_iterations);
}
} // namespace

TEST(Property, SinglePair)
{
  run_family(2, 1, {1.0, 1e4, 1e8}, 20, true, true);
  run_family(3, 1, {1.0, 1e4, 1e8}, 20, true, true);
}

TEST(Property, SmallDense)
{
  run_family(2, 5, {1.0, 1e2, 1e4, 1e6, 1e8}, 10, true, true);
  run_family(3, 10, {1.0, 1e2, 1e4, 1e6, 1e8}, 10, true, true);
}

TEST(Property, Medium)
{
  run_family(2, 100, {1e2, 1e8}, 3, true, true, 50);
  run_family(3, 200, {1e2, 1e8}, 2, true, true, 50);
}

TEST(Property, NewtonRobustSmallDense)
{
  // The default solver of the chain must actually converge on well-posed problems.
  int conv = 0, total = 0;
  for (int dim : {2, 3})
    for (double cond : {1.0, 1e3, 1e6})
      for (unsigned s = 1; s <= 10; ++s)
      {
        const RandomProblem rp = make_problem(dim, 8, cond, 77 * s + dim);
        const SolveReport r = solve_newton_ac(rp.view(), Vector(), {});
        conv += r.converged;
        ++total;
      }
  EXPECT_GE(conv, total * 9 / 10) << conv << "/" << total;
}

namespace
{
/// @brief Newton on one large random 3D problem, timed; prints the iteration count and time.
void large_newton(int pairs, double cond)
{
  const auto t0 = std::chrono::steady_clock::now();
  const RandomProblem rp = make_problem(3, pairs, cond, 4242 + pairs);
  const auto t1 = std::chrono::steady_clock::now();
  SolverOptions opt;
  opt.tolerance = 1e-10;
  opt.max_iterations = 50;
  Outcome o;
  check_property(
      rp, [](const ProblemView& p, const SolverOptions& s)
      { return solve_newton_ac(p, Vector(), s); },
      opt, opt.max_iterations, "newton_ac " + std::to_string(3 * pairs), o);
  const auto t2 = std::chrono::steady_clock::now();
  std::printf("[   info   ] %d unknowns: setup %.2f s, newton_ac %s in %d iterations, %.2f s\n",
              3 * pairs, std::chrono::duration<double>(t1 - t0).count(),
              o.converged ? "converged" : "failed", o.max_iterations,
              std::chrono::duration<double>(t2 - t1).count());
  EXPECT_EQ(o.converged, 1);
}
} // namespace

TEST(Property, LargeNewton900) { large_newton(300, 1e6); }

// About 2 s (11 Newton iterations, a dense LU of the contact zone each). At condition 1e8
// this generator's 3000-unknown problem is not solved by Newton alone within 50 iterations;
// that size and conditioning is measured in bench/, not asserted here.
TEST(Property, LargeNewton3000) { large_newton(1000, 1e6); }
