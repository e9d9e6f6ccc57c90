// Copyright flexcontact developers. MIT licence.

/// @file test_block_flexibility.cpp
/// @brief F* held by block as Cholesky factors: W by the triangular route equals W by the
/// inverse (1e-12 of its largest entry), the flop model's choice per block, F* v, the
/// constrained and the extra (rigid-target) DOFs, and bad input.

#include "contact_testing.hpp"
#include "flexcontact/block_flexibility.hpp"
#include "flexcontact/pairs.hpp"

#include <gtest/gtest.h>

#include <random>

using namespace flexcontact;
using namespace flexcontact::testing;

namespace
{
/// A random symmetric positive definite n × n matrix, fixed seed.
Matrix spd(int n, unsigned seed)
{
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Matrix A(n, n);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      A(i, j) = u(gen);
  return A * A.transpose() + n * Matrix::Identity(n, n);
}

/// Two blocks on 2·60 + 2 DOFs: block 0 on the even positions below 120, block 1 on the odd
/// ones; the last two DOFs in no block. B has `r0` rows on block 0 (two entries each) and
/// 60 rows that each touch one DOF of block 1 and one of block 0.
struct Case
{
  std::vector<std::vector<int>> blocks{{}, {}};
  std::vector<Matrix> S, L;
  Eigen::SparseMatrix<double> B;
  Matrix F; // the dense reference, F*_b = S_b⁻¹ in place
  Eigen::Index n = 122;

  explicit Case(int r0)
  {
    for (int k = 0; k < 60; ++k)
    {
      blocks[0].push_back(2 * k);
      blocks[1].push_back(2 * k + 1);
    }
    F = Matrix::Zero(n, n);
    for (int b = 0; b < 2; ++b)
    {
      S.push_back(spd(60, 7u + static_cast<unsigned>(b)));
      L.push_back(S.back().llt().matrixL());
      const Matrix Fb = S.back().inverse();
      for (int j = 0; j < 60; ++j)
        for (int i = 0; i < 60; ++i)
          F(blocks[b][i], blocks[b][j]) = Fb(i, j);
    }
    std::vector<Eigen::Triplet<double>> t;
    for (int k = 0; k < r0; ++k)
    {
      t.emplace_back(k, 2 * ((3 * k) % 60), 1.0);
      t.emplace_back(k, 2 * ((3 * k + 1) % 60), -0.5);
    }
    for (int k = 0; k < 60; ++k)
    {
      t.emplace_back(r0 + k, 2 * k + 1, 1.0);
      t.emplace_back(r0 + k, 2 * ((k + 5) % 60), 0.25);
    }
    t.emplace_back(r0 + 59, 121, 1.0); // an extra DOF: no flexibility
    B.resize(r0 + 60, n);
    B.setFromTriplets(t.begin(), t.end());
  }
};

double rel(const Matrix& a, const Matrix& b) { return (a - b).cwiseAbs().maxCoeff() / b.cwiseAbs().maxCoeff(); }
} // namespace

TEST(BlockFlexibility, WhereEveryBlockHasAsManyRowsAsDofsItIsInverted)
{
  // Block 0 is touched by 64 rows, block 1 by 60, each on 60 DOFs: the inverse is cheaper.
  Case c(4);
  BlockFlexibility F(c.n, c.blocks, c.L);
  const Matrix W = F.delassus(c.B);
  EXPECT_EQ(F.routes(), (std::vector<std::string>{"inverse", "inverse"}));
  EXPECT_LT(rel(W, delassus(c.B, c.F)), 1e-12);
}

TEST(BlockFlexibility, TheFlopModelChoosesPerBlock)
{
  // Block 0, on 60 DOFs, touched by 10 rows: n²r + nr² = 42,000 < ⅔n³ = 144,000; W by the
  // triangular route equals the dense one.
  Case c(0);
  std::vector<Eigen::Triplet<double>> t;
  for (int k = 0; k < 10; ++k)
    t.emplace_back(k, 2 * (6 * k), 1.0);
  for (int k = 0; k < 60; ++k) // block 1: r = n, the inverse is cheaper
    t.emplace_back(10 + k, 2 * k + 1, 1.0);
  Eigen::SparseMatrix<double> B(70, c.n);
  B.setFromTriplets(t.begin(), t.end());
  BlockFlexibility F(c.n, c.blocks, c.L);
  const Matrix W = F.delassus(B);
  EXPECT_EQ(F.routes(), (std::vector<std::string>{"triangular", "inverse"}));
  EXPECT_LT(F.flops_taken(), F.flops_inverse());
  EXPECT_LT(rel(W, delassus(B, c.F)), 1e-12);
  // Block 1 keeps its inverse: a second W costs it no cubic work, and takes it again.
  F.delassus(B);
  EXPECT_EQ(F.routes()[1], "inverse");
  // A block no row touches.
  Eigen::SparseMatrix<double> B0(1, c.n);
  B0.insert(0, 0) = 1.0;
  F.delassus(B0);
  EXPECT_EQ(F.routes()[1], "none");
}

TEST(BlockFlexibility, ApplyDenseAndConstrainedDofs)
{
  Case c(4);
  std::vector<bool> held(static_cast<std::size_t>(c.n), false);
  held[4] = held[9] = true;
  BlockFlexibility F(c.n, c.blocks, c.L);
  F.set_constrained(held);
  BlockFlexibility D(c.F);
  D.set_constrained(held);
  const Vector v = Vector::LinSpaced(c.n, -1.0, 2.0);
  EXPECT_LT(rel(F.apply(v), D.apply(v)), 1e-12);
  EXPECT_EQ(F.apply(v)[4], 0.0);
  EXPECT_LT(rel(F.dense(), D.dense()), 1e-12);
  EXPECT_LT(rel(F.delassus(c.B), D.delassus(c.B)), 1e-12);
  // Two more DOFs in no block (a rigid target's): zero flexibility.
  F.extend(c.n + 2);
  EXPECT_EQ(F.rows(), c.n + 2);
  EXPECT_EQ(F.apply(Vector::Ones(c.n + 2)).tail(2).cwiseAbs().maxCoeff(), 0.0);
}

TEST(BlockFlexibility, BadInputIsNamed)
{
  Case c(4);
  EXPECT_NE(message_of([&] { BlockFlexibility(c.n, c.blocks, {c.L[0]}); }).find("2 blocks but 1 factors"),
            std::string::npos);
  auto blocks = c.blocks;
  blocks[1][3] = blocks[0][0];
  EXPECT_NE(message_of([&] { BlockFlexibility(c.n, blocks, c.L); }).find("in two blocks"),
            std::string::npos);
  auto L = c.L;
  L[1](2, 2) = 0.0;
  EXPECT_NE(message_of([&] { BlockFlexibility(c.n, c.blocks, L); }).find("block 1"),
            std::string::npos);
  BlockFlexibility F(c.n, c.blocks, c.L);
  EXPECT_NE(message_of([&] { F.apply(Vector::Zero(3)); }).find("3 entries, expected 122"),
            std::string::npos);
  EXPECT_NE(message_of([&] { F.set_constrained(std::vector<bool>(5, false)); }).find("constrained"),
            std::string::npos);
}
