// Copyright flexcontact developers. MIT licence.

/// @file test_crushing.cpp
/// @brief The crushing law (problem.hpp, docs/crushing.md): the truncated cone's projection,
/// every solver of the chain on capped problems, and the crush depth of the incremental
/// driver against answers worked by hand.

#include "contact_testing.hpp"
#include "flexcontact/increment.hpp"
#include "flexcontact/residual.hpp"
#include "flexcontact/solvers.hpp"

#include <gtest/gtest.h>
#include <cmath>
#include <limits>
#include <random>

using namespace flexcontact;
using namespace flexcontact::testing;

namespace
{
constexpr double inf = std::numeric_limits<double>::infinity();

/// @brief True if r lies in the Coulomb cone truncated at cap, to tol.
bool in_truncated_cone(const double* r, int d, double mu, double cap, double tol)
{
  const double rt = d == 2 ? std::abs(r[1]) : std::hypot(r[1], r[2]);
  return r[0] >= -tol && r[0] <= cap + tol && rt <= mu * r[0] + tol;
}

/// @brief A random capped problem: m pairs pressed in, caps at a fraction of the uncapped
/// forces' scale so that some pairs crush and some do not.
struct CappedProblem
{
  int dim;
  Matrix W;
  Vector q, mu, cap;
  ProblemView view() const { return ProblemView{dim, W, q, mu, cap.data()}; }
};

CappedProblem capped_problem(int dim, int m, double cond, unsigned seed)
{
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  CappedProblem c{dim, random_spd(m * dim, cond, seed), Vector(m * dim), Vector(m), Vector(m)};
  for (int k = 0; k < m; ++k)
  {
    c.q[k * dim] = -0.2 - U(gen);
    for (int j = 1; j < dim; ++j)
      c.q[k * dim + j] = 0.6 * (U(gen) - 0.5);
    c.mu[k] = 0.6 * U(gen);
    c.cap[k] = (k % 3 == 2) ? inf : 0.2 + 0.8 * U(gen);
  }
  return c;
}
} // namespace

TEST(TruncatedCone, ProjectionIsTheNearestPoint)
{
  // The projection p of z onto a closed convex set K is in K and (z − p)·(y − p) ≤ 0 for
  // every y in K: checked against the cap's rim, the apex and random points of K.
  std::mt19937 gen(7);
  std::uniform_real_distribution<double> U(-3.0, 3.0), A(0.0, 6.283185307179586);
  for (int d : {2, 3})
    for (int trial = 0; trial < 2000; ++trial)
    {
      const double mu = trial % 5 == 0 ? 0.0 : 0.1 + 0.2 * std::abs(U(gen));
      const double cap = 0.2 + std::abs(U(gen));
      double z[3] = {U(gen), U(gen), d == 3 ? U(gen) : 0.0};
      double p[3] = {z[0], z[1], z[2]};
      project_on_truncated_cone(p, d, mu, cap);
      ASSERT_TRUE(in_truncated_cone(p, d, mu, cap, 1e-12)) << "trial " << trial;
      for (int s = 0; s < 50; ++s)
      {
        const double yn = s == 0 ? 0.0 : (s < 10 ? cap : cap * std::abs(U(gen)) / 3.0);
        const double rad = (s < 10 ? 1.0 : std::abs(U(gen)) / 3.0) * mu * yn;
        const double a = A(gen);
        const double y[3] = {yn, rad * std::cos(a), d == 3 ? rad * std::sin(a) : 0.0};
        double dot = 0.0;
        for (int i = 0; i < d; ++i)
          dot += (z[i] - p[i]) * (y[i] - p[i]);
        ASSERT_LE(dot, 1e-12) << "d " << d << " trial " << trial << " sample " << s;
      }
    }
}

TEST(TruncatedCone, InfiniteCapIsTheCone)
{
  std::mt19937 gen(3);
  std::uniform_real_distribution<double> U(-3.0, 3.0);
  for (int trial = 0; trial < 500; ++trial)
  {
    double a[3] = {U(gen), U(gen), U(gen)}, b[3] = {a[0], a[1], a[2]};
    project_on_cone(a, 3, 0.4);
    project_on_truncated_cone(b, 3, 0.4, inf);
    for (int i = 0; i < 3; ++i)
      ASSERT_EQ(a[i], b[i]);
  }
}

TEST(CrushingSolvers, HandWorkedPair)
{
  // W = [[2, .5], [.5, 1]], q = (−1, .1), μ = .5 slips with λ = (4/7, −2/7) uncapped. With
  // the cap .3 it crushes and slips: λ = (.3, −.15), u_n = .6 − .075 − 1 = −.475 ≤ 0,
  // u_t = .15 − .15 + .1 = .1 > 0 against λ_t.
  Matrix W(2, 2);
  W << 2.0, 0.5, 0.5, 1.0;
  const Vector q = vec({-1.0, 0.1}), mu = vec({0.5}), cap = vec({0.3});
  const ProblemView p{2, W, q, mu, cap.data()};
  for (const auto& chain : {std::vector<std::string>{"newton_ac"},
                            std::vector<std::string>{"projection"},
                            std::vector<std::string>{"active_set"},
                            std::vector<std::string>{}})
  {
    const SolveReport r = solve(p, Vector(), {}, chain_of(chain));
    ASSERT_TRUE(r.converged) << r.attempts.back();
    EXPECT_NEAR(r.lambda[0], 0.3, 1e-14);
    EXPECT_NEAR(r.lambda[1], -0.15, 1e-14);
    EXPECT_EQ(r.states[0], PairState::crush);
    EXPECT_NEAR(r.u[0], -0.475, 1e-14);
  }
}

TEST(CrushingSolvers, EverySolverCertifiedOnRandomProblems)
{
  int crushed = 0, total = 0, as_capped = 0, as_plain = 0;
  for (int dim : {2, 3})
    for (unsigned seed = 1; seed <= 20; ++seed)
    {
      const CappedProblem c = capped_problem(dim, 6, seed % 2 ? 1e2 : 1e4, seed);
      const ProblemView p = c.view();
      // The active set alone cycles on some of these strongly coupled problems, capped or
      // not: it must do no worse with the caps than without, and be right where it ends.
      const ProblemView plain{dim, c.W, c.q, c.mu};
      const SolveReport as = solve(p, Vector(), {}, chain_of({"active_set"}));
      as_capped += as.converged;
      as_plain += solve(plain, Vector(), {}, chain_of({"active_set"})).converged;
      if (as.converged)
        EXPECT_EQ(check_laws(p, as.lambda, 1e-8), "") << "dim " << dim << " seed " << seed;
      for (const auto& chain : {std::vector<std::string>{"newton_ac"},
                                std::vector<std::string>{"projection"},
                                std::vector<std::string>{}})
      {
        const SolveReport r = solve(p, Vector(), {}, chain_of(chain));
        ASSERT_TRUE(r.converged) << "dim " << dim << " seed " << seed << " "
                                 << r.attempts.back();
        EXPECT_LE(r.residual, 1e-10);
        EXPECT_EQ(check_laws(p, r.lambda, 1e-8), "") << "dim " << dim << " seed " << seed;
        for (int k = 0; k < p.pairs(); ++k)
        {
          crushed += r.states[k] == PairState::crush;
          ++total;
        }
      }
    }
  // The problems do exercise the cap: a fair share of the pairs crush.
  EXPECT_GT(crushed, total / 5);
  EXPECT_GE(as_capped, as_plain);
  EXPECT_GE(as_capped, 30); // of 40 (368 of 400 on 200 seeds per dimension)
}

TEST(CrushingSolvers, InfiniteCapsAreBitwiseNoCaps)
{
  for (int dim : {2, 3})
    for (unsigned seed = 1; seed <= 6; ++seed)
    {
      CappedProblem c = capped_problem(dim, 8, 1e3, seed);
      c.cap.setConstant(inf);
      const ProblemView capped = c.view();
      const ProblemView plain{dim, c.W, c.q, c.mu};
      for (const auto& chain : {std::vector<std::string>{"newton_ac"},
                                std::vector<std::string>{"projection"},
                                std::vector<std::string>{"active_set"},
                                std::vector<std::string>{}})
      {
        const SolveReport a = solve(plain, Vector(), {}, chain_of(chain));
        const SolveReport b = solve(capped, Vector(), {}, chain_of(chain));
        ASSERT_EQ(a.lambda.size(), b.lambda.size());
        for (Eigen::Index i = 0; i < a.lambda.size(); ++i)
          ASSERT_EQ(a.lambda[i], b.lambda[i]) << "dim " << dim << " seed " << seed;
        EXPECT_EQ(a.iterations, b.iterations);
      }
    }
}

TEST(CrushDepth, PressUnloadReload)
{
  // One frictionless pair of compliance 2 m/N and cap 1 N, driven by the total approach a
  // (q_n = −a). Elastic up to a = 2; at a = 4 the force stays 1 N and the surface crushes
  // by 4 − 2 = 2 m; unloading to a = 3 is elastic from the crushed shape (λ = (3 − 2)/2);
  // at a = 1 the crushed surface is open; re-loading crushes again only past a = 4
  // (a = 4.5: δ = 2.5, work 1 N × 0.5 m).
  Matrix W = Matrix::Identity(2, 2) * 2.0;
  IncrementalSolver s(2, W, vec({0.0}));
  s.set_crushing(vec({1.0}), vec({0.0}));
  auto at = [&](double a) { return s.step(vec({-a, 0.0})); };
  SolveReport r = at(1.0);
  EXPECT_NEAR(r.lambda[0], 0.5, 1e-14);
  EXPECT_EQ(s.crush_depth()[0], 0.0);
  r = at(4.0);
  EXPECT_NEAR(r.lambda[0], 1.0, 1e-14);
  EXPECT_EQ(r.states[0], PairState::crush);
  EXPECT_NEAR(s.crush_depth()[0], 2.0, 1e-14);
  EXPECT_NEAR(s.crush_work(), 2.0, 1e-14);
  r = at(3.0);
  EXPECT_NEAR(r.lambda[0], 0.5, 1e-14);
  EXPECT_EQ(r.states[0], PairState::stick);
  EXPECT_NEAR(s.crush_depth()[0], 2.0, 1e-14);
  EXPECT_EQ(s.crush_work(), 0.0);
  r = at(1.0);
  EXPECT_EQ(r.lambda[0], 0.0);
  EXPECT_EQ(r.states[0], PairState::open);
  r = at(3.9);
  EXPECT_NEAR(r.lambda[0], 0.95, 1e-14);
  EXPECT_NEAR(s.crush_depth()[0], 2.0, 1e-14);
  r = at(4.5);
  EXPECT_NEAR(r.lambda[0], 1.0, 1e-14);
  EXPECT_NEAR(s.crush_depth()[0], 2.5, 1e-14);
  EXPECT_NEAR(s.crush_work(), 0.5, 1e-14);
}

TEST(CrushDepth, BadCapsNamed)
{
  IncrementalSolver s(2, Matrix::Identity(2, 2), vec({0.0}));
  EXPECT_NE(message_of([&] { s.set_crushing(vec({0.0}), vec({0.0})); }).find("cap of pair 0"),
            std::string::npos);
  EXPECT_NE(message_of([&] { s.set_crushing(vec({std::nan("")}), vec({0.0})); })
                .find("must be > 0"),
            std::string::npos);
  EXPECT_NE(message_of([&] { s.set_crushing(vec({1.0}), vec({-1.0})); }).find("crush depth"),
            std::string::npos);
}

TEST(CrushingSolvers, NewtonFactorisesOnlyTheRowsNotHeldAtTheirCap)
{
  // Every pair at its cap and sticking: the normal rows of ∂P/∂z are zero, so a Newton step
  // fixes the normals and solves the tangential rows alone, 2m of the 3m, exactly (they are
  // linear there). From the answer with its tangents moved, one step lands on it. The work
  // charged is the LU of order 2m for a block of 300 rows or more (3m = 330 here), and of
  // the whole block below (3m = 36), which keeps its LU (newton_step.cpp).
  const int d = 3;
  for (const int m : {110, 12})
  {
    const int n = m * d;
    const Matrix W = random_spd(n, 1e2, 7);
    Vector lam(n), u = Vector::Zero(n), mu = Vector::Constant(m, 0.5), cap(m);
    for (int k = 0; k < m; ++k)
    {
      cap[k] = 0.5 + 0.05 * k;
      lam[k * d] = cap[k];
      lam[k * d + 1] = 0.1 * cap[k] * std::cos(k);
      lam[k * d + 2] = 0.1 * cap[k] * std::sin(k);
      u[k * d] = -0.1; // pressed past the cap: it crushes
    }
    const Vector q = u - W * lam;
    const ProblemView p{d, W, q, mu, cap.data()};
    Vector start = lam;
    for (int k = 0; k < m; ++k)
      start[k * d + 1] += 0.01 * cap[k];
    const SolveReport r = solve_newton_ac(p, start, SolverOptions{});
    ASSERT_TRUE(r.converged) << m << " pairs: " << r.attempts.back();
    EXPECT_EQ(r.iterations, 1) << m << " pairs";
    EXPECT_LE((r.lambda - lam).cwiseAbs().maxCoeff(), 1e-12) << m << " pairs";
    for (int k = 0; k < m; ++k)
      EXPECT_EQ(r.states[k], PairState::crush) << m << " pairs, pair " << k;
    const double s = n, lu = n >= 300 ? 2.0 * m : n;
    const double flops = 2.0 * 2.0 * s * s + 2.0 * d * s * s + 2.0 / 3.0 * lu * lu * lu;
    EXPECT_NEAR(r.work_gflop, flops * 1e-9, 1e-12 * flops * 1e-9) << m << " pairs";
  }
}
