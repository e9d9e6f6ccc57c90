// Copyright flexcontact developers. MIT licence.

/// @file test_pairs.cpp
/// @brief Frames, the gap operator B, the initial gap and W = B F* Bᵀ against hand values.

#include "contact_testing.hpp"
#include "flexcontact/pairs.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace flexcontact;
using namespace flexcontact::testing;

TEST(Frame, OrthonormalRightHandedAndNormalFirst)
{
  for (const Vector& n : {vec({0.6, 0.8}), vec({-3.0, 0.0}), vec({0.0, 1.0}),
                          vec({1.0, 2.0, 2.0}), vec({0.0, 0.0, -5.0}), vec({1.0, 1.0, 1.0}),
                          vec({-0.2, 0.9, 0.1})})
  {
    const Matrix T = frame_from_normal(n);
    const auto d = n.size();
    EXPECT_LT((T * T.transpose() - Matrix::Identity(d, d)).norm(), 1e-14) << n.transpose();
    EXPECT_NEAR(T.determinant(), 1.0, 1e-14) << n.transpose();
    EXPECT_LT((T.row(0).transpose() - n / n.norm()).norm(), 1e-15) << n.transpose();
  }
}

TEST(Frame, TwoDimensionalTangentIsNormalRotatedAnticlockwise)
{
  const Matrix T = frame_from_normal(vec({0.6, 0.8}));
  EXPECT_DOUBLE_EQ(T(1, 0), -0.8);
  EXPECT_DOUBLE_EQ(T(1, 1), 0.6);
}

TEST(Frame, ThreeDimensionalTangentsAreContinuousUnderSmallRotation)
{
  // n away from the cones where the least aligned axis switches; a rotation by ε about an
  // axis must move every row of T by O(ε).
  const Eigen::Vector3d n = Eigen::Vector3d(0.3, 0.5, 0.8).normalized();
  const double eps = 1e-6;
  for (const Eigen::Vector3d& axis : {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0),
                                      Eigen::Vector3d(0.2, -0.7, 0.4).normalized()})
  {
    const Eigen::Vector3d n2 = Eigen::AngleAxisd(eps, axis) * n;
    const Matrix dT = frame_from_normal(n2) - frame_from_normal(n);
    EXPECT_LT(dT.norm(), 5.0 * eps) << axis.transpose();
    EXPECT_GT(dT.norm(), 0.1 * eps) << axis.transpose(); // the frame did follow n
  }
}

TEST(Frame, RejectsZeroNonFiniteAndWrongSize)
{
  EXPECT_THROW(frame_from_normal(vec({0.0, 0.0})), std::invalid_argument);
  EXPECT_THROW(frame_from_normal(vec({NAN, 1.0, 0.0})), std::invalid_argument);
  EXPECT_THROW(frame_from_normal(vec({1.0})), std::invalid_argument);
}

TEST(GapOperator, NodeToSegmentPairMatchesHandBuiltB)
{
  // Slave node 2 against the point 0.25 X_0 + 0.75 X_1; n = (0, 1) so t = (−1, 0).
  const std::vector<ContactPair> pairs{make_pair(2, {0, 1}, {0.25, 0.75}, vec({0.0, 1.0}))};
  const Matrix B = Matrix(gap_operator(2, 3, pairs));
  Matrix expected = Matrix::Zero(2, 6);
  // normal row: +e_{s,y} − 0.25 e_{0,y} − 0.75 e_{1,y}
  expected(0, 5) = 1.0;
  expected(0, 1) = -0.25;
  expected(0, 3) = -0.75;
  // tangential row: −e_{s,x} + 0.25 e_{0,x} + 0.75 e_{1,x}
  expected(1, 4) = -1.0;
  expected(1, 0) = 0.25;
  expected(1, 2) = 0.75;
  EXPECT_LT((B - expected).norm(), 1e-15) << B;
}

TEST(GapOperator, TwoPairsThreeDimensionsOccupyTheirOwnRowBlocks)
{
  const std::vector<ContactPair> pairs{make_pair(0, {2}, {1.0}, vec({0.0, 0.0, 1.0})),
                                       make_pair(1, {}, {}, vec({1.0, 0.0, 0.0}))};
  const Matrix B = Matrix(gap_operator(3, 3, pairs));
  ASSERT_EQ(B.rows(), 6);
  ASSERT_EQ(B.cols(), 9);
  const Matrix T0 = pairs[0].frame, T1 = pairs[1].frame;
  EXPECT_LT((B.block(0, 0, 3, 3) - T0).norm(), 1e-15);
  EXPECT_LT((B.block(0, 6, 3, 3) + T0).norm(), 1e-15);
  EXPECT_LT(B.block(0, 3, 3, 3).norm(), 1e-15);
  // A rigid target has no master columns.
  EXPECT_LT((B.block(3, 3, 3, 3) - T1).norm(), 1e-15);
  EXPECT_LT(B.block(3, 0, 3, 3).norm() + B.block(3, 6, 3, 3).norm(), 1e-15);
}

TEST(GapOperator, RejectsBadPairs)
{
  auto bad_node = make_pair(3, {0}, {1.0}, vec({0.0, 1.0}));
  EXPECT_THROW(gap_operator(2, 3, {bad_node}), std::invalid_argument);
  auto bad_weights = make_pair(0, {1, 2}, {1.0}, vec({0.0, 1.0}));
  EXPECT_THROW(gap_operator(2, 3, {bad_weights}), std::invalid_argument);
  auto bad_frame = make_pair(0, {1}, {1.0}, vec({0.0, 0.0, 1.0}));
  EXPECT_THROW(gap_operator(2, 3, {bad_frame}), std::invalid_argument);
}

TEST(InitialGap, SlaveAboveSegment)
{
  // Master point 0.75 (0,0) + 0.25 (2,0) = (0.5, 0); slave at (0.7, 0.3).
  // n = (0, 1), t = (−1, 0): x0 = (0.3, −0.2).
  Matrix X(3, 2);
  X << 0.0, 0.0, 2.0, 0.0, 0.7, 0.3;
  const std::vector<ContactPair> pairs{make_pair(2, {0, 1}, {0.75, 0.25}, vec({0.0, 1.0}))};
  const Vector x0 = initial_gap(pairs, X);
  ASSERT_EQ(x0.size(), 2);
  EXPECT_NEAR(x0[0], 0.3, 1e-15);
  EXPECT_NEAR(x0[1], -0.2, 1e-15);
  // Consistent with B: x0 = B X (coordinates stacked node-major).
  const Vector Xs = Eigen::Map<const Vector>(Matrix(X.transpose()).data(), 6);
  EXPECT_LT((Matrix(gap_operator(2, 3, pairs)) * Xs - x0).norm(), 1e-15);
}

TEST(InitialGap, OffsetOfARigidCircle)
{
  // Slave at (3, 4) against a circle of radius 2 centred at the origin (node 0): the radial
  // normal (0.6, 0.8) gives the normal gap |X_s| − R = 5 − 2 = 3 and no tangential gap.
  Matrix X(2, 2);
  X << 0.0, 0.0, 3.0, 4.0;
  auto pair = make_pair(1, {0}, {1.0}, vec({0.6, 0.8}));
  pair.offset = 2.0;
  const Vector x0 = initial_gap({pair}, X);
  EXPECT_NEAR(x0[0], 3.0, 1e-14);
  EXPECT_NEAR(x0[1], 0.0, 1e-14);
  pair.offset = std::nan("");
  EXPECT_THROW(initial_gap({pair}, X), std::invalid_argument);
}

TEST(Delassus, RigidTargetRotatesFlexibilityIntoFrame)
{
  // One node against a rigid wall with normal (0, 1): W = T F Tᵀ swaps the axes.
  const std::vector<ContactPair> pairs{make_pair(0, {}, {}, vec({0.0, 1.0}))};
  Matrix F(2, 2);
  F << 2.0, 0.0, 0.0, 5.0;
  const Matrix W = delassus(gap_operator(2, 1, pairs), F);
  Matrix expected(2, 2);
  expected << 5.0, 0.0, 0.0, 2.0;
  EXPECT_LT((W - expected).norm(), 1e-15) << W;
}

TEST(Delassus, SymmetricAndEqualToBFBt)
{
  const std::vector<ContactPair> pairs{make_pair(2, {0, 1}, {0.25, 0.75}, vec({0.3, 1.0})),
                                       make_pair(3, {1}, {1.0}, vec({-1.0, 0.2}))};
  const auto B = gap_operator(2, 4, pairs);
  Matrix L(8, 8);
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 8; ++j)
      L(i, j) = std::sin(1.0 + i * 8 + j);
  const Matrix F = L * L.transpose() + Matrix::Identity(8, 8);
  const Matrix W = delassus(B, F);
  const Matrix Bd = Matrix(B);
  EXPECT_EQ((W - W.transpose()).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_LT((W - Bd * F * Bd.transpose()).norm(), 1e-12 * W.norm());
  // A slightly unsymmetric F* (rounding in its computation) still gives a symmetric W.
  Matrix Fu = F;
  Fu(0, 1) += 1e-9;
  const Matrix Wu = delassus(B, Fu);
  EXPECT_EQ((Wu - Wu.transpose()).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_THROW(delassus(B, Matrix::Identity(6, 6)), std::invalid_argument);
}
