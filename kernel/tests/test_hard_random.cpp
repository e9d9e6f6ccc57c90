// Copyright flexcontact developers. MIT licence.

/// @file test_hard_random.cpp
/// @brief The default chain on random problems it once lost (tests/data/random/*.rp).
///
/// bench/campaign.py draws 10,000 random local problems with a constructed solution
/// (tests/random_problems.py). With seed 1 the chain used to fail on 122 ill-conditioned or
/// rank-deficient 3D ones that Siconos' NSN_AC solved to 1e-14; Newton needed hundreds of
/// damped steps and, on some, each pair's ρ from its whole diagonal block. After that, 19
/// were still lost (17 ill-conditioned, 2 rank-deficient); Newton with Siconos' full steps
/// where the line search fails solves them. A few are stored here (write_problem() in
/// random_problems.py): from a zero start the chain must reach the default tolerance, its
/// residual recomputed here, and satisfy the contact laws checked one by one.

#include "contact_testing.hpp"
#include "flexcontact/residual.hpp"
#include "flexcontact/solvers.hpp"
#include "stored_problems.hpp"

#include <gtest/gtest.h>

#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#ifndef FLEXCONTACT_TEST_DATA
#error "FLEXCONTACT_TEST_DATA (the folder of the stored problems) must be defined by CMake"
#endif

using namespace flexcontact;
using namespace flexcontact::testing;

namespace
{
/// @brief One stored problem and its constructed solution λ*.
struct Stored
{
  std::string name;
  int dim = 0;
  Matrix W;
  Vector mu, q, lambda_star;
};

Stored read_stored(const std::string& name)
{
  const std::string path = std::string(FLEXCONTACT_TEST_DATA) + "/random/" + name + ".rp";
  Stored s;
  int m = -1;
  auto on_line = [&](const std::string& key, std::istringstream& in)
  {
    if (key == "name")
      in >> s.name;
    else if (key == "dim")
      in >> s.dim;
    else if (key == "pairs")
      in >> m;
    else
      return false;
    return true;
  };
  auto count = [&]
  {
    if ((s.dim != 2 && s.dim != 3) || m < 1)
      throw std::runtime_error(path + ": bad header (dim or pairs)");
    const std::size_t n = static_cast<std::size_t>(m) * s.dim;
    return static_cast<std::size_t>(m) + n * (n + 1) / 2 + 2 * n;
  };
  StoredValues v = read_stored_values(path, "flexcontact-random-problem 1", "", on_line, count);
  const Eigen::Index n = static_cast<Eigen::Index>(m) * s.dim;
  s.mu = v.take(m);
  s.W = v.take_symmetric(n);
  s.q = v.take(n);
  s.lambda_star = v.take(n);
  return s;
}

class HardRandom : public ::testing::TestWithParam<std::string>
{
};

TEST_P(HardRandom, DefaultChainSolvesItFromZero)
{
  const Stored s = read_stored(GetParam());
  const ProblemView p{s.dim, s.W, s.q, s.mu};
  // The stored solution certifies the problem: it has one, so failing is the solver's fault.
  ASSERT_LE(natural_map_residual(p, s.lambda_star), 1e-12) << s.name;

  const SolverOptions opt; // default chain, tolerance 1e-10
  const SolveReport r = solve(p, Vector(), {}, opt);
  std::string tried;
  for (const auto& a : r.attempts)
    tried += "\n  " + a;
  EXPECT_TRUE(r.converged) << s.name << tried;
  EXPECT_LE(natural_map_residual(p, r.lambda), opt.tolerance) << s.name << tried;
  // The laws one by one, to 10× the residual tolerance (the residual mixes them).
  EXPECT_EQ(check_laws(p, r.lambda, 10.0 * opt.tolerance), "") << s.name;
}

INSTANTIATE_TEST_SUITE_P(LostBefore, HardRandom,
                         ::testing::Values("ill_conditioned-3d-m6-3575",
                                           "ill_conditioned-3d-m12-5591",
                                           "rank_deficient-3d-m19-9582",
                                           // Solved only with full Newton steps:
                                           "rank_deficient-3d-m14-2862",
                                           "rank_deficient-3d-m54-7190",
                                           "ill_conditioned-3d-m22-9223",
                                           "ill_conditioned-3d-m36-3407",
                                           // Solved only by Newton from the projection's
                                           // last iterate:
                                           "ill_conditioned-3d-m49-7335"),
                         [](const auto& info)
                         {
                           std::string n = info.param;
                           for (char& c : n)
                             if (c == '-')
                               c = '_';
                           return n;
                         });

TEST(ChainBudget, StopsOnceTheWorkBudgetIsSpentAndSaysSo)
{
  // A budget spent by the first step: the chain must not try on, and must return an honest
  // unconverged report (finite λ, its true residual) rather than throw or hang.
  const Stored s = read_stored("ill_conditioned-3d-m12-5591");
  const ProblemView p{s.dim, s.W, s.q, s.mu};
  SolverOptions opt;
  opt.work_budget_gflop = 1e-9;
  const SolveReport r = solve(p, Vector(), {}, opt);
  EXPECT_FALSE(r.converged);
  ASSERT_EQ(r.lambda.size(), s.q.size());
  EXPECT_TRUE(r.lambda.allFinite());
  EXPECT_DOUBLE_EQ(r.residual, natural_map_residual(p, r.lambda));
  EXPECT_GT(r.residual, opt.tolerance);
  ASSERT_FALSE(r.attempts.empty());
  EXPECT_NE(r.attempts.back().find("work budget"), std::string::npos) << r.attempts.back();
}

TEST(ChainBudget, ABudgetCutsTheChainAtTheSameIterateEveryTime)
{
  // Work depends on the path only: cut half way, two runs end on the same λ, bitwise, with
  // the same attempts. (tests/test_bad_input.py repeats this beside a CPU hog.)
  const Stored s = read_stored("ill_conditioned-3d-m36-3407");
  const ProblemView p{s.dim, s.W, s.q, s.mu};
  const SolveReport full = solve(p, Vector(), {}, SolverOptions{});
  ASSERT_TRUE(full.converged);
  SolverOptions opt;
  opt.work_budget_gflop = 0.5 * full.work_gflop;
  const SolveReport a = solve(p, Vector(), {}, opt);
  const SolveReport b = solve(p, Vector(), {}, opt);
  EXPECT_EQ(a.attempts, b.attempts);
  EXPECT_EQ(a.work_gflop, b.work_gflop);
  ASSERT_EQ(a.lambda.size(), b.lambda.size());
  for (Eigen::Index i = 0; i < a.lambda.size(); ++i)
    ASSERT_EQ(a.lambda(i), b.lambda(i)) << "component " << i;
  // The cut run spent its budget (within one iteration's work) and did not go on.
  EXPECT_GE(a.work_gflop, opt.work_budget_gflop);
  EXPECT_LT(a.work_gflop, full.work_gflop);
}

TEST(ChainBudget, AutomaticBudgetGrowsWithTheCubeOfTheSize)
{
  // 50 Gflop + 200 Gflop·(n/1000)³, as documented in problem.hpp.
  EXPECT_DOUBLE_EQ(chain_work_budget_gflop(0), 50.0);
  EXPECT_DOUBLE_EQ(chain_work_budget_gflop(1000), 250.0);
  EXPECT_DOUBLE_EQ(chain_work_budget_gflop(3000), 5450.0);
}
} // namespace
