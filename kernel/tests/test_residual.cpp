// Copyright flexcontact developers. MIT licence.

#include "contact_testing.hpp"
#include "flexcontact/residual.hpp"

#include <gtest/gtest.h>
#include <cmath>

using namespace flexcontact;
using namespace flexcontact::testing;

namespace
{
/// @brief Single 2D pair with coupling: W = [[2, 0.5], [0.5, 1]].
Matrix W2()
{
  Matrix W(2, 2);
  W << 2.0, 0.5, 0.5, 1.0;
  return W;
}

/// @brief The coupled pair pressed in and pushed along t, with μ = 1/2 too small to stick:
/// it slips with λ = (4/7, −2/7) (see exact_cases in contact_testing.hpp).
struct SlippingPair
{
  Matrix W = W2();
  Vector q = vec({-1.0, 0.1});
  Vector mu = vec({0.5});
};
} // namespace

TEST(Cone, InsideUnchanged)
{
  double r[3] = {2.0, 0.3, -0.4}; // |λ_t| = 0.5 ≤ 0.5·2
  project_on_cone(r, 3, 0.5);
  EXPECT_DOUBLE_EQ(r[0], 2.0);
  EXPECT_DOUBLE_EQ(r[1], 0.3);
  EXPECT_DOUBLE_EQ(r[2], -0.4);
  double s[2] = {1.0, -0.25};
  project_on_cone(s, 2, 0.25);
  EXPECT_DOUBLE_EQ(s[0], 1.0);
  EXPECT_DOUBLE_EQ(s[1], -0.25);
}

TEST(Cone, PolarConeToApex)
{
  double r[3] = {-2.0, 0.3, 0.4}; // μ|λ_t| = 0.25 ≤ 2
  project_on_cone(r, 3, 0.5);
  EXPECT_EQ(r[0], 0.0);
  EXPECT_EQ(r[1], 0.0);
  EXPECT_EQ(r[2], 0.0);
  double s[2] = {-1.0, 0.0};
  project_on_cone(s, 2, 0.0);
  EXPECT_EQ(s[0], 0.0);
  EXPECT_EQ(s[1], 0.0);
}

TEST(Cone, BoundaryFormula3D)
{
  const double mu = 0.5;
  double r[3] = {1.0, 3.0, 4.0}; // |λ_t| = 5
  project_on_cone(r, 3, mu);
  const double n = (1.0 + mu * 5.0) / (1.0 + mu * mu); // 2.8
  EXPECT_NEAR(r[0], n, 1e-15);
  EXPECT_NEAR(r[1], mu * n * 3.0 / 5.0, 1e-15);
  EXPECT_NEAR(r[2], mu * n * 4.0 / 5.0, 1e-15);
  // On the boundary, and the correction λ − P(λ) lies on the polar cone's generator.
  EXPECT_NEAR(std::hypot(r[1], r[2]), mu * r[0], 1e-14);
}

TEST(Cone, BoundaryFormula2DNegativeNormal)
{
  const double mu = 2.0;
  double r[2] = {-1.0, -3.0}; // μ|λ_t| = 6 > 1: not polar
  project_on_cone(r, 2, mu);
  const double n = (-1.0 + mu * 3.0) / (1.0 + mu * mu); // 1
  EXPECT_NEAR(r[0], n, 1e-15);
  EXPECT_NEAR(r[1], -mu * n, 1e-15);
}

TEST(Cone, FrictionlessKeepsNormalPart)
{
  double r[3] = {1.5, 0.2, -0.1};
  project_on_cone(r, 3, 0.0);
  EXPECT_DOUBLE_EQ(r[0], 1.5);
  EXPECT_EQ(r[1], 0.0);
  EXPECT_EQ(r[2], 0.0);
}

TEST(Residual, ZeroOnExactStickSlipOpen2D)
{
  const Matrix W = W2();
  Vector mu(1);
  // stick: λ = −W⁻¹q = (0.6, −0.4), inside the cone for μ = 1
  Vector q(2), l(2);
  q << -1.0, 0.1;
  mu << 1.0;
  l << 0.6, -0.4;
  EXPECT_LT(natural_map_residual({2, W, q, mu}, l), 1e-15);
  // slip for μ = 0.5: λ = (4/7, −2/7), u = (0, 0.1)
  mu << 0.5;
  l << 4.0 / 7.0, -2.0 / 7.0;
  EXPECT_LT(natural_map_residual({2, W, q, mu}, l), 1e-15);
  // open: q_n > 0, λ = 0
  q << 1.0, 0.3;
  l.setZero();
  EXPECT_EQ(natural_map_residual({2, W, q, mu}, l), 0.0);
}

TEST(Residual, PositiveOnPerturbed)
{
  const SlippingPair c;
  const ProblemView p{2, c.W, c.q, c.mu};
  const Vector l = vec({4.0 / 7.0, -2.0 / 7.0});
  for (int i = 0; i < 2; ++i)
  {
    Vector lp = l;
    lp[i] += 1e-4;
    const double r = natural_map_residual(p, lp);
    EXPECT_GT(r, 1e-6) << "component " << i;
  }
  // Stick answer is wrong when μ is too small for it.
  EXPECT_GT(natural_map_residual(p, vec({0.6, -0.4})), 1e-3);
  // Open answer where contact is needed.
  EXPECT_GT(natural_map_residual(p, Vector::Zero(2)), 0.1);
}

TEST(Residual, ScaleInvariant)
{
  Matrix W(6, 6);
  W.setRandom();
  W = W * W.transpose() + 6.0 * Matrix::Identity(6, 6);
  Vector q(6), l(6), mu(2);
  q << -1.0, 0.2, 0.1, 0.5, -0.3, 0.2;
  l << 0.3, 0.1, -0.05, 0.2, 0.0, 0.1;
  mu << 0.3, 0.7;
  const double r0 = natural_map_residual({3, W, q, mu}, l);
  ASSERT_GT(r0, 0.0);
  // W in other units (compliance ×s, force ×1/s): the same physical state.
  for (double s : {1e-9, 1e-3, 1e4, 1e12})
  {
    const Matrix Ws = s * W;
    const Vector ls = l / s;
    EXPECT_NEAR(natural_map_residual({3, Ws, q, mu}, ls), r0, 1e-12 * r0) << "s = " << s;
  }
  // Loads ×a, forces ×a: linear problem, same relative residual.
  for (double a : {1e-8, 1e6})
  {
    const Vector qa = a * q, la = a * l;
    EXPECT_NEAR(natural_map_residual({3, W, qa, mu}, la), r0, 1e-12 * r0) << "a = " << a;
  }
}

TEST(Residual, ZeroDiagonalNeverNaN)
{
  // Pair 0 has a zero block (all its DOFs constrained); pair 1 a normal one.
  Matrix W = Matrix::Zero(4, 4);
  W(2, 2) = 3.0;
  W(3, 3) = 1.0;
  Vector q(4), l(4), mu(2);
  q << -1.0, 0.5, -2.0, 0.1;
  l << 1.0, 0.0, 0.5, 0.0;
  mu << 0.5, 0.5;
  const ProblemView p{2, W, q, mu};
  const Vector rho = pair_rho(p);
  EXPECT_DOUBLE_EQ(rho[0], 1.0 / 3.0);
  EXPECT_DOUBLE_EQ(rho[1], 1.0 / 3.0);
  const double r = natural_map_residual(p, l);
  EXPECT_TRUE(std::isfinite(r));
  EXPECT_GT(r, 0.0);
  // All-zero W: ρ = 1, still finite.
  const Matrix Z = Matrix::Zero(4, 4);
  EXPECT_TRUE(std::isfinite(natural_map_residual({2, Z, q, mu}, l)));
  // All zero: residual 0, not 0/0.
  const Vector z4 = Vector::Zero(4);
  EXPECT_EQ(natural_map_residual({2, Z, z4, mu}, z4), 0.0);
}

TEST(Residual, NonFiniteLambdaGivesInfinityNotNaN)
{
  const SlippingPair c;
  const Vector l = vec({std::nan(""), 0.0});
  EXPECT_TRUE(std::isinf(natural_map_residual({2, c.W, c.q, c.mu}, l)));
}

TEST(Residual, RejectsWrongSizes)
{
  const SlippingPair c;
  EXPECT_THROW(natural_map_residual({2, c.W, c.q, c.mu}, Vector::Zero(3)),
               std::invalid_argument);
  EXPECT_THROW(natural_map_residual({3, c.W, c.q, c.mu}, Vector::Zero(2)),
               std::invalid_argument);
}

TEST(ClassifyStates, OpenStickSlip)
{
  const OpenStickSlipPairs c;
  const ProblemView p{3, c.W, c.q, c.mu};
  EXPECT_LT(natural_map_residual(p, c.lambda), 1e-15);
  const Vector u = c.W * c.lambda + c.q;
  const auto s = classify_states(p, c.lambda, u);
  ASSERT_EQ(s.size(), 3u);
  EXPECT_EQ(s[0], PairState::open);
  EXPECT_EQ(s[1], PairState::stick);
  EXPECT_EQ(s[2], PairState::slip);
}
