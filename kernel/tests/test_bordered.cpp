// Copyright flexcontact developers. MIT licence.

/// @file test_bordered.cpp
/// @brief The bordered local problem of a body held only by contact, against hand solutions:
/// a rigid block on two springy contact points (2D), translations along x (tangential) and
/// y (normal) free. Pair k has normal and tangential compliances (c_n, c_t,k), so
/// W = diag(c_n, c_t,1, c_n, c_t,2); G carries the translations: x moves the tangential
/// rows, y the normal rows; e = (Q, N) the load the contact forces must balance.

#include "flexcontact/condensed.hpp"
#include "flexcontact/increment.hpp"
#include "flexcontact/solvers.hpp"

#include <gtest/gtest.h>

using namespace flexcontact;

namespace
{
constexpr double cn = 1.0, N = 2.0, mu = 0.5;

Matrix flexibility(double ct1, double ct2)
{
  Vector w(4);
  w << cn, ct1, cn, ct2;
  return w.asDiagonal();
}

Matrix border()
{
  Matrix G = Matrix::Zero(4, 2);
  G(1, 0) = G(3, 0) = 1.0; // translation along x: the tangential rows
  G(0, 1) = G(2, 1) = 1.0; // translation along y: the normal rows
  return G;
}

SolveReport bordered(double ct1, double ct2, double Q, double mu_)
{
  const Matrix W = flexibility(ct1, ct2);
  const Vector q = Vector::Zero(4);
  const Vector m = Vector::Constant(2, mu_);
  const ProblemView p{2, W, q, m};
  const Vector e = (Vector(2) << Q, N).finished();
  return solve(p, border(), e, Vector(), Vector(), SolverOptions{});
}
} // namespace

TEST(Bordered, SymmetricStickSharesTheLoadAndTheBodyMovesToCloseTheGap)
{
  // Both pairs stick: λ = (N/2, Q/2) each; the gap closes, c λ + α = 0 on every row.
  const double Q = 0.6;
  const SolveReport r = bordered(1.0, 1.0, Q, mu);
  ASSERT_TRUE(r.converged) << r.attempts.front();
  const Vector lam = (Vector(4) << N / 2, Q / 2, N / 2, Q / 2).finished();
  EXPECT_LT((r.lambda - lam).norm(), 1e-10) << r.lambda.transpose();
  EXPECT_NEAR(r.alpha[0], -Q / 2, 1e-10);
  EXPECT_NEAR(r.alpha[1], -cn * N / 2, 1e-10);
  EXPECT_EQ(r.states[0], PairState::stick);
  EXPECT_EQ(r.undetermined.cols(), 0);
}

TEST(Bordered, PartialSlipTheStifferPairSlipsFirst)
{
  // Tangential compliances 1 and 3: in stick pair 1 would carry 3Q/4 = 0.6 > μN/2 = 0.5,
  // so it slips at μN/2 and pair 2 sticks with the rest; α_x = −c_t,2 λ_t,2.
  const double Q = 0.8;
  const SolveReport r = bordered(1.0, 3.0, Q, mu);
  ASSERT_TRUE(r.converged) << r.attempts.front();
  EXPECT_NEAR(r.lambda[1], mu * N / 2, 1e-10);
  EXPECT_NEAR(r.lambda[3], Q - mu * N / 2, 1e-10);
  EXPECT_NEAR(r.lambda[0] + r.lambda[2], N, 1e-10);
  EXPECT_NEAR(r.alpha[0], -3.0 * (Q - mu * N / 2), 1e-10);
  EXPECT_EQ(r.states[0], PairState::slip);
  EXPECT_EQ(r.states[1], PairState::stick);
}

TEST(Bordered, PushPastMuNHasNoEquilibrium)
{
  const SolveReport r = bordered(1.0, 3.0, 1.01 * mu * N, mu);
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.alpha.size(), 2);
}

TEST(Bordered, FrictionlessSlideWithNoLoadTakesTheMinimumNorm)
{
  // μ = 0, Q = 0: any α_x solves the problem; the answer is α_x = 0, reported undetermined.
  const SolveReport r = bordered(1.0, 3.0, 0.0, 0.0);
  ASSERT_TRUE(r.converged) << r.attempts.front();
  EXPECT_NEAR(r.alpha[0], 0.0, 1e-14);
  EXPECT_NEAR(r.alpha[1], -cn * N / 2, 1e-10);
  ASSERT_EQ(r.undetermined.cols(), 1);
  EXPECT_NEAR(std::abs(r.undetermined(0, 0)), 1.0, 1e-12);
  EXPECT_NEAR(r.undetermined(1, 0), 0.0, 1e-12);
}

TEST(Bordered, OtherSolversOfTheChainAreSkipped)
{
  SolverOptions opt;
  opt.chain = {"active_set", "projection"};
  const Matrix W = flexibility(1.0, 1.0);
  const Vector q = Vector::Zero(4), m = Vector::Constant(2, mu);
  const ProblemView p{2, W, q, m};
  const SolveReport r = solve(p, border(), Vector::Constant(2, 0.5), Vector(), Vector(), opt);
  EXPECT_FALSE(r.converged);
  ASSERT_EQ(r.attempts.size(), 2u);
  EXPECT_NE(r.attempts[0].find("skipped"), std::string::npos) << r.attempts[0];
}

TEST(Bordered, CondensedContactCarriesTheRigidModesThroughIncrements)
{
  // Two slave nodes on two held master nodes, n = (0, 1) (t = (−1, 0)); the slaves hang on
  // springs (F* diagonal) and belong to one block whose translations R_c are free. The
  // block is pressed by N and pushed by Q along −x: p = (−Q/2, −N/2) on each slave, so
  // e = −Rᵀp = (Q, N); G's x column is −1 on the tangential rows (t = (−1, 0)), so the
  // friction on the block, −Σλ_t along x, is +Q.
  const Matrix X = (Matrix(4, 2) << 0, 0, 1, 0, 0, 0, 1, 0).finished();
  std::vector<ContactPair> pairs(2);
  for (int k = 0; k < 2; ++k)
  {
    pairs[k].slave = k;
    pairs[k].masters = {k + 2};
    pairs[k].weights = {1.0};
    pairs[k].frame = (Matrix(2, 2) << 0, 1, -1, 0).finished();
  }
  Matrix F = Matrix::Zero(8, 8);
  F.topLeftCorner(4, 4) = Matrix::Identity(4, 4);
  Matrix Rc = Matrix::Zero(8, 2);
  Rc(0, 0) = Rc(2, 0) = 1.0; // x of the two slave nodes
  Rc(1, 1) = Rc(3, 1) = 1.0; // y
  CondensedContact c(2, F, X, pairs, Vector::Constant(2, mu),
                     {false, false, false, false, true, true, true, true});
  c.set_rigid_modes(Rc);
  const Vector up = Vector::Zero(8);
  for (double Q : {0.2, 0.6})
  {
    const Vector e = (Vector(2) << Q, N).finished();
    const CondensedStep s = c.step(up, e);
    EXPECT_NEAR(s.normal_force, N, 1e-10);
    EXPECT_NEAR(s.tangential_force[0], Q, 1e-10);
    EXPECT_NEAR(s.alpha[1], -N / 2, 1e-10);  // each spring compressed by N/2
    EXPECT_NEAR(s.alpha[0], -Q / 2, 1e-10);  // and sheared by Q/2 (both stick)
  }
  EXPECT_THROW(c.step(up, Vector::Zero(3)), std::invalid_argument);
}
