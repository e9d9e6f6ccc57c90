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

namespace
{
/// @brief F* of two bodies in 3D: SPD blocks on the nodes of each body (body[a] per contact
/// node), exact zeros between bodies and on the rows and columns of the held DOFs.
Matrix two_body_flexibility(const std::vector<int>& body, const std::vector<int>& held)
{
  const auto n = static_cast<Eigen::Index>(body.size()) * 3;
  Matrix L(n, n);
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = 0; j < n; ++j)
      L(i, j) = std::sin(0.7 + 1.3 * i + 0.11 * j * j);
  Matrix F = L * L.transpose() + Matrix::Identity(n, n);
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = 0; j < n; ++j)
      if (body[i / 3] != body[j / 3])
        F(i, j) = 0.0;
  for (const int h : held)
  {
    F.row(h).setZero();
    F.col(h).setZero();
  }
  return F;
}
} // namespace

TEST(Delassus, BlockDiagonalFlexibilityEqualsDenseProduct)
{
  // Slaves 0..3 on one body, masters 4..9 on the other: contiguous bodies (as the contact
  // numbering gives), then the same with the bodies' nodes interleaved; some pairs with
  // three master nodes, a held DOF inside each body.
  for (const bool interleaved : {false, true})
  {
    std::vector<int> body(10), slave(4), master(6);
    for (int a = 0; a < 10; ++a)
      body[a] = interleaved ? a % 2 : (a < 4 ? 0 : 1);
    for (int a = 0, s = 0, mm = 0; a < 10; ++a)
      (body[a] == 0 && s < 4 ? slave[s++] : master[mm++]) = a;
    const std::vector<ContactPair> pairs{
        make_pair(slave[0], {master[0]}, {1.0}, vec({0.1, 0.2, 1.0})),
        make_pair(slave[1], {master[1], master[2], master[3]}, {0.2, 0.3, 0.5},
                  vec({0.0, -0.4, 1.0})),
        make_pair(slave[2], {master[3], master[4], master[5]}, {0.6, 0.1, 0.3},
                  vec({1.0, 0.3, 0.2})),
        make_pair(slave[3], {master[5]}, {1.0}, vec({-0.5, 0.5, 0.7}))};
    const Matrix F = two_body_flexibility(body, {slave[1] * 3 + 2, master[4] * 3});
    const auto B = gap_operator(3, 10, pairs);
    const Matrix W = delassus(B, F);
    const Matrix Bd = Matrix(B);
    const Matrix dense = Bd * F * Bd.transpose();
    EXPECT_EQ((W - W.transpose()).cwiseAbs().maxCoeff(), 0.0);
    EXPECT_LT((W - dense).cwiseAbs().maxCoeff(), 1e-14 * dense.cwiseAbs().maxCoeff())
        << "interleaved " << interleaved;
  }
}

TEST(Delassus, ZeroFlexibilityColumnsGiveZeroRows)
{
  // A pair whose slave and master DOFs are all held has no flexibility: its rows of W are 0.
  const std::vector<ContactPair> pairs{make_pair(0, {1}, {1.0}, vec({0.0, 1.0})),
                                       make_pair(2, {3}, {1.0}, vec({1.0, 1.0}))};
  Matrix F = Matrix::Identity(8, 8);
  F.topLeftCorner(4, 4).setZero();
  const Matrix W = delassus(gap_operator(2, 4, pairs), F);
  EXPECT_EQ(W.topRows(2).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(W.leftCols(2).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_NEAR(W(2, 2), 2.0, 1e-15);   // |n|² (1 + 1) for the free pair, T rows unit
  EXPECT_NEAR(W(3, 3), 2.0, 1e-15);
}
