// Copyright flexcontact developers. MIT licence.

/// @file test_split_cholesky.cpp
/// @brief The sparse split Cholesky factor against dense linear algebra on a 2D five-point
/// Laplacian plus a mass term (SPD, the sparsity of a small body): condense gives
/// b_c − A_ci A_ii⁻¹ b_i, expand gives A⁻¹ (b + Sᵀ r) from u_c = S⁻¹(b̃_c + r), solve gives
/// A⁻¹ b, flexibility() gives S⁻¹ (all to 1e-12 relative); a factor rebuilt from its parts
/// solves bitwise alike; bad input and misuse are refused.

#include "flexcontact/split_cholesky.hpp"

#include <gtest/gtest.h>

#include <random>
#include <stdexcept>

using namespace flexcontact;

namespace
{
/// The n² × n² matrix 4I − neighbours + 0.1 I of an n × n grid, as CSR of both triangles.
struct Grid
{
  int n = 0;
  std::vector<int> indptr{0}, indices;
  std::vector<double> values;
  Matrix dense;

  explicit Grid(int side) : n(side * side), dense(Matrix::Zero(side * side, side * side))
  {
    for (int i = 0; i < side; ++i)
      for (int j = 0; j < side; ++j)
      {
        const int r = i * side + j;
        auto add = [&](int c, double v)
        {
          indices.push_back(c);
          values.push_back(v);
          dense(r, c) = v;
        };
        if (i > 0)
          add(r - side, -1.0);
        if (j > 0)
          add(r - 1, -1.0);
        add(r, 4.1);
        if (j + 1 < side)
          add(r + 1, -1.0);
        if (i + 1 < side)
          add(r + side, -1.0);
        indptr.push_back(static_cast<int>(indices.size()));
      }
  }
};

Vector random_vector(Eigen::Index n, unsigned seed)
{
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Vector v(n);
  for (Eigen::Index i = 0; i < n; ++i)
    v[i] = u(gen);
  return v;
}

/// Contact rows: the grid's last row of nodes, given right to left (not sorted).
std::vector<int> edge_rows(int side)
{
  std::vector<int> c;
  for (int j = side - 1; j >= 0; --j)
    c.push_back((side - 1) * side + j);
  return c;
}

struct Blocks
{
  Matrix Aii, Aic, Acc;
  std::vector<int> interior;
};

Blocks split(const Matrix& A, const std::vector<int>& c)
{
  Blocks b;
  std::vector<char> is_c(static_cast<std::size_t>(A.rows()), 0);
  for (int r : c)
    is_c[static_cast<std::size_t>(r)] = 1;
  for (int r = 0; r < A.rows(); ++r)
    if (!is_c[static_cast<std::size_t>(r)])
      b.interior.push_back(r);
  const auto ni = static_cast<Eigen::Index>(b.interior.size());
  const auto nc = static_cast<Eigen::Index>(c.size());
  b.Aii.resize(ni, ni);
  b.Aic.resize(ni, nc);
  b.Acc.resize(nc, nc);
  for (Eigen::Index a = 0; a < ni; ++a)
  {
    for (Eigen::Index k = 0; k < ni; ++k)
      b.Aii(a, k) = A(b.interior[a], b.interior[k]);
    for (Eigen::Index k = 0; k < nc; ++k)
      b.Aic(a, k) = A(b.interior[a], c[k]);
  }
  for (Eigen::Index a = 0; a < nc; ++a)
    for (Eigen::Index k = 0; k < nc; ++k)
      b.Acc(a, k) = A(c[a], c[k]);
  return b;
}
} // namespace

TEST(SplitCholesky, CondenseExpandSolveAndFlexibilityMatchDenseAlgebra)
{
  const int side = 12;
  Grid g(side);
  const auto c = edge_rows(side);
  SplitCholesky f(g.n, g.indptr, g.indices, g.values, c);
  ASSERT_EQ(f.size(), g.n);
  ASSERT_EQ(f.schur_size(), side);

  const Blocks b = split(g.dense, c);
  const Eigen::LLT<Matrix> Lii(b.Aii);
  const Matrix S = b.Acc - b.Aic.transpose() * Lii.solve(b.Aic);
  const Matrix F = S.inverse();
  EXPECT_LE((f.flexibility() - F).cwiseAbs().maxCoeff(), 1e-12 * F.cwiseAbs().maxCoeff());

  const Vector rhs = random_vector(g.n, 7);
  Vector bi(b.interior.size()), bc(side);
  for (std::size_t a = 0; a < b.interior.size(); ++a)
    bi[static_cast<Eigen::Index>(a)] = rhs[b.interior[a]];
  for (int a = 0; a < side; ++a)
    bc[a] = rhs[c[static_cast<std::size_t>(a)]];
  const Vector bt_expected = bc - b.Aic.transpose() * Lii.solve(bi);
  const Vector bt = f.condense(rhs);
  EXPECT_LE((bt - bt_expected).cwiseAbs().maxCoeff(), 1e-12 * bt_expected.cwiseAbs().maxCoeff());

  // A contact reaction r on the contact rows: x = A⁻¹(b + Sᵀ r), u_c = F*(b̃_c + r).
  const Vector r = random_vector(side, 11);
  const Vector uc = F * (bt + r);
  Vector x(g.n);
  f.expand(uc, x);
  Vector loaded = rhs;
  for (int a = 0; a < side; ++a)
    loaded[c[static_cast<std::size_t>(a)]] += r[a];
  const Vector x_expected = g.dense.llt().solve(loaded);
  EXPECT_LE((x - x_expected).cwiseAbs().maxCoeff(), 1e-12 * x_expected.cwiseAbs().maxCoeff());

  Vector y(g.n);
  f.solve(rhs, y);
  const Vector y_expected = g.dense.llt().solve(rhs);
  EXPECT_LE((y - y_expected).cwiseAbs().maxCoeff(), 1e-12 * y_expected.cwiseAbs().maxCoeff());

  // Rebuilt from its parts: the same factor, so bitwise the same solves.
  SplitCholesky g2(f.order(), f.schur_size(), f.L());
  Vector y2(g.n);
  g2.solve(rhs, y2);
  EXPECT_EQ(y2, y);
  EXPECT_EQ(g2.condense(rhs), bt);
}

TEST(SplitCholesky, NoContactRowsIsAPlainFactor)
{
  Grid g(6);
  SplitCholesky f(g.n, g.indptr, g.indices, g.values, {});
  const Vector rhs = random_vector(g.n, 3);
  Vector y(g.n);
  f.solve(rhs, y);
  EXPECT_LE((g.dense * y - rhs).cwiseAbs().maxCoeff(), 1e-12 * rhs.cwiseAbs().maxCoeff());
  EXPECT_EQ(f.flexibility().size(), 0);
}

TEST(SplitCholesky, RefusesBadInputAndMisuse)
{
  Grid g(5);
  EXPECT_THROW(SplitCholesky(g.n, g.indptr, g.indices, g.values, {3, 3}), std::invalid_argument);
  EXPECT_THROW(SplitCholesky(g.n, g.indptr, g.indices, g.values, {g.n}), std::invalid_argument);
  std::vector<int> short_ptr(g.indptr.begin(), g.indptr.end() - 1);
  EXPECT_THROW(SplitCholesky(g.n, short_ptr, g.indices, g.values, {}), std::invalid_argument);

  // The upper triangle only: refused, not factored as if the lower one were zero.
  std::vector<int> up_ptr{0}, up_idx;
  std::vector<double> up_val;
  for (int r = 0; r < g.n; ++r)
  {
    for (int k = g.indptr[r]; k < g.indptr[r + 1]; ++k)
      if (g.indices[k] >= r)
      {
        up_idx.push_back(g.indices[k]);
        up_val.push_back(g.values[k]);
      }
    up_ptr.push_back(static_cast<int>(up_idx.size()));
  }
  EXPECT_THROW(SplitCholesky(g.n, up_ptr, up_idx, up_val, {}), std::invalid_argument);

  // Indefinite: the diagonal made negative.
  std::vector<double> neg = g.values;
  for (double& v : neg)
    if (v > 0)
      v = -v;
  EXPECT_THROW(SplitCholesky(g.n, g.indptr, g.indices, neg, {0}), std::runtime_error);

  SplitCholesky f(g.n, g.indptr, g.indices, g.values, {0, 1});
  Vector x(g.n);
  EXPECT_THROW(f.expand(Vector::Zero(2), x), std::logic_error);
  EXPECT_THROW(f.condense(Vector::Zero(g.n - 1)), std::invalid_argument);
  f.condense(Vector::Ones(g.n));
  EXPECT_THROW(f.expand(Vector::Zero(3), x), std::invalid_argument);
  f.expand(Vector::Zero(2), x);
  EXPECT_THROW(f.expand(Vector::Zero(2), x), std::logic_error); // one expansion per condensation
}
