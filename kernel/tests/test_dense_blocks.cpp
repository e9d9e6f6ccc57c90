// Copyright flexcontact developers. MIT licence.

/// @file test_dense_blocks.cpp
/// @brief Shared dense flexibility blocks (dense_blocks.hpp): their products against plain
/// dense ones, and an impact run whose F̂ is made of a rotated "log" block and a "face"
/// block, on the factor path, against the dense path on the same F̂ formed whole (every
/// step's impulses to 1e-10 of the largest).

#include "contact_testing.hpp"
#include "flexcontact/dense_blocks.hpp"
#include "flexcontact/impact.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <random>

using namespace flexcontact;
using namespace flexcontact::testing;

namespace
{
Matrix random_spd(int n, unsigned seed)
{
  std::mt19937 gen(seed);
  std::normal_distribution<double> g;
  Matrix A(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      A(i, j) = g(gen);
  return A.transpose() * A / n + Matrix::Identity(n, n);
}

Matrix rotation(double yaw, double pitch)
{
  Matrix Rz(3, 3), Ry(3, 3);
  Rz << std::cos(yaw), -std::sin(yaw), 0.0, std::sin(yaw), std::cos(yaw), 0.0, 0.0, 0.0, 1.0;
  Ry << std::cos(pitch), 0.0, std::sin(pitch), 0.0, 1.0, 0.0, -std::sin(pitch), 0.0,
      std::cos(pitch);
  return Rz * Ry;
}

/// Q F Qᵀ on every d × d node block.
Matrix rotated(const Matrix& F, const Matrix& Q)
{
  Matrix T = Matrix::Zero(F.rows(), F.cols());
  for (Eigen::Index a = 0; a < F.rows(); a += 3)
    T.block(a, a, 3, 3) = Q;
  return T * F * T.transpose();
}

double max_abs(const Matrix& A) { return A.cwiseAbs().maxCoeff(); }
} // namespace

TEST(DenseBlock, ProductsEqualThePlainProductOnSparseAndDenseColumns)
{
  for (const bool symmetric : {true, false})
  {
    // 13 rows: the pass over F takes its columns four at a time, and one is left over.
    Matrix F = random_spd(13, 3);
    if (!symmetric)
      F(0, 5) += 0.25;
    const DenseBlock block(F);
    EXPECT_EQ(block.symmetric(), symmetric);
    Matrix X = Matrix::Zero(13, 4);
    X(4, 0) = 2.0;                           // one entry: F's column route
    X.col(1).setLinSpaced(13, -1.0, 1.0);    // whole
    X(0, 2) = 1.0;                           // six of thirteen: still the column route
    X(3, 2) = -0.5;
    X(7, 2) = 0.25;
    X(8, 2) = 3.0;
    X(11, 2) = -2.0;
    X(12, 2) = 0.5;
    X.col(3).setConstant(0.75);              // whole too: the two in one pass over F
    const Matrix Y = block.product(X);
    EXPECT_LE(max_abs(Y - F * X), 1e-13 * max_abs(F * X)) << "symmetric " << symmetric;
    // One whole column alone takes the matrix-vector product (symmetric: its lower half).
    const Matrix y = block.product(X.col(1));
    EXPECT_LE(max_abs(y - F * X.col(1)), 1e-13 * max_abs(F * X.col(1)));
  }
}

TEST(DenseBlock, RefusesBadInputByName)
{
  EXPECT_NE(message_of([] { DenseBlock(Matrix::Zero(3, 4)); }).find("must be square"),
            std::string::npos);
  Matrix F = Matrix::Identity(3, 3);
  F(1, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(message_of([&] { DenseBlock{F}; }).find("not finite"), std::string::npos);
  const DenseBlock ok(Matrix::Identity(3, 3));
  EXPECT_NE(message_of([&] { ok.product(Matrix::Zero(4, 1)); }).find("4 rows"),
            std::string::npos);
  auto b = std::make_shared<const DenseBlock>(Matrix::Identity(6, 6));
  EXPECT_NE(message_of([&] { SharedBlocks(3, {b}, {2.0 * Matrix::Identity(3, 3)}); })
                .find("not orthogonal"),
            std::string::npos);
  EXPECT_NE(message_of([&] { SharedBlocks(3, {nullptr}, {}); }).find("block 0 is missing"),
            std::string::npos);
  auto odd = std::make_shared<const DenseBlock>(Matrix::Identity(4, 4));
  EXPECT_NE(message_of([&] { SharedBlocks(3, {odd}, {}); }).find("not a multiple of dim 3"),
            std::string::npos);
  EXPECT_NE(message_of([&] { SharedBlocks(3, {b, b}, {Matrix()}); }).find("1 rotations for 2"),
            std::string::npos);
}

TEST(DenseBlock, ReadsItsCallersValuesInPlaceAndKeepsThemAlive)
{
  const Matrix F = random_spd(7, 8);
  auto values = std::make_shared<Matrix>(F);
  std::weak_ptr<Matrix> watch = values;
  const double* data = values->data();
  auto block = std::make_unique<DenseBlock>(data, 7, values);
  values.reset();
  EXPECT_FALSE(watch.expired()); // the block keeps them
  EXPECT_EQ(block->matrix().data(), data);
  EXPECT_TRUE(block->symmetric());
  const Matrix X = Matrix::Ones(7, 2);
  EXPECT_LE(max_abs(block->product(X) - F * X), 1e-13 * max_abs(F * X));
  block.reset();
  EXPECT_TRUE(watch.expired()); // and lets them go with it
  auto nan = std::make_shared<Matrix>(Matrix::Identity(2, 2));
  (*nan)(0, 1) = std::numeric_limits<double>::infinity();
  EXPECT_NE(message_of([&] { DenseBlock(nan->data(), 2, nan); }).find("not finite"),
            std::string::npos);
  EXPECT_NE(message_of([] { DenseBlock(nullptr, 3, nullptr); }).find("no values for a block of 3"),
            std::string::npos);
}

TEST(SharedBlocks, AppliesTheRotatedBlockDiagonal)
{
  const Matrix F1 = random_spd(12, 5), F2 = random_spd(9, 6);
  const Matrix Q = rotation(0.35, -0.2);
  const SharedBlocks op(3,
                        {std::make_shared<const DenseBlock>(F1),
                         std::make_shared<const DenseBlock>(F2)},
                        {Q, Matrix()});
  Matrix F = Matrix::Zero(21, 21);
  F.topLeftCorner(12, 12) = rotated(F1, Q);
  F.bottomRightCorner(9, 9) = F2;
  Matrix R = Matrix::Zero(21, 2);
  R(4, 0) = 1.0;    // a node of the rotated block
  R(14, 0) = -0.5;  // and one of the other
  R.col(1).setLinSpaced(21, 0.5, 2.0);
  EXPECT_EQ(op.rows(), 21);
  EXPECT_LE(max_abs(op.apply(R) - F * R), 1e-13 * max_abs(F * R));
}

TEST(SharedBlocks, AnImpactRunOnTheFactorPathEqualsTheDensePath)
{
  // Slaves 0–3 on a "log" (its block in its own frame, placed by Q), masters 4–9 on a
  // "face"; each slave faces the face nodes 4 + k and 5 + k, 0.3k mm away, and moves at it.
  constexpr int slaves = 4, faces = 6, nodes = slaves + faces, n = 3 * nodes;
  const double h = 1e-3, theta = 0.5;
  const Matrix F1 = 1e-3 * random_spd(3 * slaves, 8), F2 = 1e-4 * random_spd(3 * faces, 9);
  const Matrix Q = rotation(0.3, 0.15);
  Matrix F = Matrix::Zero(n, n);
  F.topLeftCorner(3 * slaves, 3 * slaves) = rotated(F1, Q);
  F.bottomRightCorner(3 * faces, 3 * faces) = F2;
  const auto op = std::make_shared<SharedBlocks>(
      3,
      std::vector<std::shared_ptr<const DenseBlock>>{std::make_shared<const DenseBlock>(F1),
                                                     std::make_shared<const DenseBlock>(F2)},
      std::vector<Matrix>{Q, Matrix()});
  Matrix X = Matrix::Zero(nodes, 3);
  std::vector<ContactPair> pairs;
  for (int k = 0; k < slaves; ++k)
  {
    X(k, 0) = 3e-4 * k;
    X(k, 1) = X(slaves + k, 1) = 0.1 * k;
    X(slaves + k + 1, 1) = 0.1 * (k + 1);
    pairs.push_back(make_pair(k, {slaves + k, slaves + k + 1}, {0.5, 0.5},
                              vec({1.0, 0.0, 0.0})));
  }
  const Vector mu = Vector::Constant(slaves, 0.3);
  ImpactContact dense(3, F, X, pairs, mu, 0.0, h, theta, {});
  ImpactContact shared(3, [op](const Matrix& R) { return op->apply(R); }, X, pairs, mu, 0.0,
                       h, theta, {}, SolverOptions{}, 1e9);
  Vector cap = Vector::Constant(slaves, std::numeric_limits<double>::infinity());
  cap[2] = 50.0; // one pair crushes
  dense.set_crushing(cap);
  shared.set_crushing(cap);
  Vector u1 = Vector::Zero(n), v1 = Vector::Zero(n);
  for (int k = 0; k < slaves; ++k)
  {
    v1[3 * k] = -1.0;
    v1[3 * k + 2] = 0.1 * (k - 1);
  }
  Vector u2 = u1, v2 = v1;
  double peak = 0.0, worst = 0.0;
  for (int i = 0; i < 30; ++i)
  {
    // A stiffness pulling each DOF back: b̃ = −h k (u + hθ v), the same law on both paths.
    const Vector b1 = -h * 1e3 * (u1 + h * theta * v1), b2 = -h * 1e3 * (u2 + h * theta * v2);
    const ImpactStep s1 = dense.step_condensed(u1, v1, b1);
    const Vector Fb = op->apply(b2);
    const ImpactStep s2 = shared.step(u2, v2, v2 + Fb);
    const Vector change2 = Fb + op->apply(s2.reaction);
    peak = std::max(peak, s1.impulse.cwiseAbs().maxCoeff());
    worst = std::max(worst, (s1.impulse - s2.impulse).cwiseAbs().maxCoeff());
    EXPECT_LE((s1.velocity_change_c - change2).cwiseAbs().maxCoeff(),
              1e-10 * s1.velocity_change_c.cwiseAbs().maxCoeff() + 1e-300)
        << "step " << i;
    u1 += h * (theta * (v1 + s1.velocity_change_c) + (1.0 - theta) * v1);
    v1 += s1.velocity_change_c;
    u2 += h * (theta * (v2 + change2) + (1.0 - theta) * v2);
    v2 += change2;
  }
  ASSERT_GT(peak, 0.0);
  EXPECT_LE(worst, 1e-10 * peak);
  EXPECT_GT(dense.node_crush_depth().maxCoeff(), 0.0); // the cap did bind
  EXPECT_LE((dense.node_crush_depth() - shared.node_crush_depth()).cwiseAbs().maxCoeff(),
            1e-10 * dense.node_crush_depth().maxCoeff());
  // Columns are fetched for the pairs that closed, never F̂ whole.
  EXPECT_LE(shared.block_columns(), 3L * slaves);
}
