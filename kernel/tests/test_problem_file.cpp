// Copyright flexcontact developers. MIT licence.

/// @file test_problem_file.cpp
/// @brief A failing increment carries the local problem it was given; written and read back
/// it gives the same failure, bitwise (problem_file.hpp).

#include "flexcontact/increment.hpp"
#include "flexcontact/problem_file.hpp"
#include "flexcontact/solvers.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>

using namespace flexcontact;

namespace
{
/// @brief A 3D problem of 8 pairs with an SPD W that 50 projection sweeps do not solve.
IncrementalSolver failing_solver(Vector& q)
{
  std::mt19937 gen(7);
  std::normal_distribution<double> g;
  const int n = 24;
  Matrix A(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      A(i, j) = g(gen);
  Matrix W = A * A.transpose() / n + 0.1 * Matrix::Identity(n, n);
  q.resize(n);
  for (int i = 0; i < n; ++i)
    q(i) = i % 3 == 0 ? -1.0 - std::abs(g(gen)) : g(gen); // every pair pressed: all coupled
  SolverOptions opt;
  opt.chain = {"projection"};
  opt.max_iterations = 1; // 50 sweeps
  opt.tolerance = 1e-15;  // well beyond what 50 sweeps reach on this W
  return IncrementalSolver(3, W, Vector::Constant(8, 0.4), opt);
}
} // namespace

TEST(ProblemFile, AFailingIncrementCarriesWhatTheChainWasGiven)
{
  Vector q;
  IncrementalSolver s = failing_solver(q);
  try
  {
    s.step(q);
    FAIL() << "no ConvergenceError";
  }
  catch (const ConvergenceError& e)
  {
    ASSERT_TRUE(e.problem);
    const LocalProblem& p = *e.problem;
    EXPECT_EQ(p.dim, 3);
    EXPECT_EQ(p.q, q); // no previous slip yet: q as given
    EXPECT_EQ(p.W, s.W());
    EXPECT_EQ(p.options.chain, std::vector<std::string>{"projection"});

    const std::string path
        = (std::filesystem::temp_directory_path() / "flexcontact-test-problem.lp").string();
    write_local_problem(path, p);
    const LocalProblem back = read_local_problem(path);
    std::remove(path.c_str());
    EXPECT_EQ(back.W, p.W);
    EXPECT_EQ(back.q, p.q);
    EXPECT_EQ(back.mu, p.mu);
    const SolveReport again = solve(back);
    EXPECT_FALSE(again.converged);
    EXPECT_EQ(again.residual, e.report.residual);
    EXPECT_EQ(again.attempts, e.report.attempts);
  }
}

TEST(ProblemFile, ReadingABadFileNamesIt)
{
  const std::string path
      = (std::filesystem::temp_directory_path() / "flexcontact-test-bad.lp").string();
  {
    std::FILE* f = std::fopen(path.c_str(), "wb");
    std::fputs("flexcontact-local-problem 3\ndim 3\npairs 0\nbinary\n", f);
    std::fclose(f);
  }
  try
  {
    read_local_problem(path);
    FAIL() << "read a file with no pairs";
  }
  catch (const std::runtime_error& e)
  {
    EXPECT_NE(std::string(e.what()).find(path + ": bad header"), std::string::npos) << e.what();
  }
  std::remove(path.c_str());
}
