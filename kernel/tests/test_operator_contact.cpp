// Copyright flexcontact developers. MIT licence.

/// @file test_operator_contact.cpp
/// @brief The matrix-free condensed problem (operator_contact.hpp) against the dense one:
/// the same pairs and F* (as a matrix here, as an operator there) give the same λ, gap and
/// states over frictional increments; the answer satisfies the contact laws.

#include "contact_testing.hpp"
#include "flexcontact/condensed.hpp"
#include "flexcontact/operator_contact.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

using namespace flexcontact;
using namespace flexcontact::testing;

namespace
{
// A row of slave nodes 0..m-1 above a row of master nodes m..2m-1, gap growing outwards, so
// that a push closes the middle pairs only; pairs coupled through a dense SPD F*.
struct Row
{
  Matrix X;
  std::vector<ContactPair> pairs;
  Vector mu;
};

Row row_of_pairs(int m, int dim, double mu)
{
  Row r;
  r.X = Matrix::Zero(2 * m, dim);
  Vector n = Vector::Zero(dim);
  n[1] = 1.0;
  for (int k = 0; k < m; ++k)
  {
    const double x = (k - 0.5 * (m - 1)) / m;
    r.X(k, 0) = r.X(m + k, 0) = x;
    r.X(k, 1) = 0.01 * x * x; // slave above the master
    r.pairs.push_back(make_pair(k, {m + k}, {1.0}, n));
  }
  r.mu = Vector::Constant(m, mu);
  return r;
}

/// How OperatorContact solves: the matrix-free iteration only, the working set of W's
/// columns, or the working set with room for one pair's columns (so that it falls back).
enum class Mode
{
  iteration,
  working_set,
  working_set_too_small
};

void compare(int dim, double mu, Mode mode = Mode::iteration)
{
  const int m = 12;
  const Row row = row_of_pairs(m, dim, mu);
  const int n_c = 2 * m * dim;
  const Matrix F = random_spd(n_c, 50.0, 5, 1e-3);
  SolverOptions opt;
  CondensedContact dense(dim, F, row.X, row.pairs, row.mu, {}, opt);
  OperatorContact op(dim, [&F](const Vector& r) { return Vector(F * r); }, row.X, row.pairs,
                     row.mu, {}, opt);
  const double one_pair = 8.0 * m * dim * dim;
  if (mode != Mode::iteration)
    op.use_working_set([&F](const Matrix& R) { return Matrix(F * R); },
                       mode == Mode::working_set ? 1e9 : one_pair);
  // Push the slaves down and sideways in two increments (the second slides further).
  for (int inc = 1; inc <= 2; ++inc)
  {
    Vector up = Vector::Zero(n_c);
    for (int k = 0; k < m; ++k)
    {
      up[k * dim + 1] = -0.002 * inc;
      up[k * dim] = 0.0004 * inc;
    }
    const CondensedStep a = dense.step(up);
    const CondensedStep b = op.step(up);
    ASSERT_TRUE(b.report.converged);
    // Both certified to 1e-10 in their natural-map residuals: the forces agree to a few
    // times that relative to their size (W's conditioning is 50).
    const double scale = a.lambda.norm();
    EXPECT_GT(scale, 0.0);
    EXPECT_LT((a.lambda - b.lambda).norm(), 1e-7 * scale) << "increment " << inc;
    EXPECT_LT((a.gap - b.gap).norm(), 1e-7 * a.gap.norm()) << "increment " << inc;
    EXPECT_LT((a.reaction - b.reaction).norm(), 1e-7 * a.reaction.norm());
    const ProblemView view{dim, dense.W(), a.local_q, row.mu};
    EXPECT_EQ(check_laws(view, b.lambda, 1e-7), "") << "increment " << inc;
    EXPECT_GT(b.report.iterations, 0);
    EXPECT_EQ(b.report.solver, mode == Mode::working_set ? "working_set" : "operator");
    if (mode == Mode::working_set)
    {
      // Columns only of pairs that penetrated at some point, and no F* product alone.
      EXPECT_GT(op.cached_pairs(), 0);
      EXPECT_LE(op.cached_pairs(), m);
      EXPECT_EQ(op.applications(), 0);
    }
  }
}
} // namespace

TEST(OperatorContact, MatchesDenseFrictionless2D) { compare(2, 0.0); }
TEST(OperatorContact, MatchesDenseFrictional2D) { compare(2, 0.3); }
TEST(OperatorContact, MatchesDenseFrictional3D) { compare(3, 0.3); }
TEST(OperatorContact, WorkingSetMatchesDenseFrictionless2D) { compare(2, 0.0, Mode::working_set); }
TEST(OperatorContact, WorkingSetMatchesDenseFrictional2D) { compare(2, 0.3, Mode::working_set); }
TEST(OperatorContact, WorkingSetMatchesDenseFrictional3D) { compare(3, 0.3, Mode::working_set); }
TEST(OperatorContact, WorkingSetPastItsMemoryFallsBack)
{
  compare(2, 0.3, Mode::working_set_too_small);
}

TEST(OperatorContact, ColumnsOfWAreTheDenseOnes)
{
  // W[:, pairs] by one block product equals the columns of the dense W = B F* Bᵀ.
  const int m = 7, dim = 3;
  const Row row = row_of_pairs(m, dim, 0.2);
  const Matrix F = random_spd(2 * m * dim, 30.0, 11, 1e-3);
  CondensedContact dense(dim, F, row.X, row.pairs, row.mu);
  OperatorContact op(dim, [&F](const Vector& r) { return Vector(F * r); }, row.X, row.pairs,
                     row.mu);
  op.use_working_set([&F](const Matrix& R) { return Matrix(F * R); }, 1e9);
  const std::vector<int> some{5, 1, 3};
  const Matrix cols = op.W_columns(some);
  ASSERT_EQ(cols.rows(), m * dim);
  ASSERT_EQ(cols.cols(), 3 * dim);
  for (std::size_t a = 0; a < some.size(); ++a)
    EXPECT_LT((cols.middleCols(static_cast<Eigen::Index>(a) * dim, dim)
               - dense.W().middleCols(some[a] * dim, dim))
                  .norm(),
              1e-12 * dense.W().norm());
  EXPECT_EQ(op.block_products(), 1);
  EXPECT_EQ(op.block_columns(), 3 * dim);
  EXPECT_THROW(op.W_columns({m}), std::invalid_argument);
}

TEST(OperatorContact, NotConvergedIsAConvergenceError)
{
  const Row row = row_of_pairs(6, 2, 0.3);
  const Matrix F = random_spd(24, 1e6, 3, 1e-3);
  SolverOptions opt;
  opt.max_iterations = 1; // 100 iterations of the operator solver: too few at κ = 1e6
  opt.tolerance = 1e-14;
  OperatorContact op(2, [&F](const Vector& r) { return Vector(F * r); }, row.X, row.pairs,
                     row.mu, {}, opt);
  Vector up = Vector::Constant(24, 0.0);
  for (int k = 0; k < 6; ++k)
    up[k * 2 + 1] = -0.01;
  try
  {
    op.step(up);
    FAIL() << "expected a ConvergenceError";
  }
  catch (const ConvergenceError& e)
  {
    EXPECT_FALSE(e.report.converged);
    EXPECT_NE(std::string(e.what()).find("contact_operator='factor'"), std::string::npos);
  }
}

namespace
{
/// @brief What `make` throws, with the object's name taken out, so that the dense and the
/// operator objects' messages can be compared word for word.
std::string message_without(const std::string& name, const std::function<void()>& make)
{
  std::string m = message_of(make);
  const auto at = m.find(name);
  return at == std::string::npos ? "(no '" + name + "' in: " + m + ")" : m.erase(at, name.size());
}
} // namespace

TEST(OperatorContact, BadArgumentsReadAsForTheDenseObject)
{
  // Two nodes (slave 0 above master 1), one pair, F* = I: every bad argument must be refused
  // before anything is computed, in the words CondensedContact uses.
  const Matrix X = (Matrix(2, 2) << 0.5, 0.1, 0.5, 0.0).finished();
  const std::vector<ContactPair> pair = {make_pair(0, {1}, {1.0}, vec({0.0, 1.0}))};
  const Matrix F = Matrix::Identity(4, 4);
  const LinearOperator Fop = [&F](const Vector& r) { return Vector(F * r); };
  struct Case
  {
    int dim;
    Matrix X;
    Vector mu;
    std::vector<bool> constrained;
  };
  const Matrix X_nan = (Matrix(2, 2) << 0.5, NAN, 0.5, 0.0).finished();
  const std::vector<Case> cases = {
      {4, X, vec({0.3}), {}},                  // dim
      {2, Matrix::Zero(2, 3), vec({0.3}), {}}, // X's columns
      {2, X_nan, vec({0.3}), {}},              // X not finite
      {2, X, vec({0.3, 0.1}), {}},             // one μ per pair
      {2, X, vec({0.3}), {true, false}},       // constrained's size
  };
  for (const Case& c : cases)
  {
    const std::string dense = message_without(
        "CondensedContact: ", [&] { CondensedContact(c.dim, F, c.X, pair, c.mu, c.constrained); });
    const std::string op = message_without(
        "OperatorContact: ", [&] { OperatorContact(c.dim, Fop, c.X, pair, c.mu, c.constrained); });
    EXPECT_FALSE(dense.empty());
    EXPECT_EQ(op, dense);
  }

  CondensedContact dense(2, F, X, pair, vec({0.3}));
  OperatorContact op(2, Fop, X, pair, vec({0.3}));
  for (const Vector& up : {vec({0.0, 0.0}), vec({0.0, NAN, 0.0, 0.0})})
    EXPECT_EQ(message_without("OperatorContact: ", [&] { op.step(up); }),
              message_without("CondensedContact: ", [&] { dense.step(up); }));
}

TEST(OperatorContact, BadFrictionOnRepairingKeepsThePairs)
{
  // A negative μ is refused before the pairs are replaced: the object keeps its pairs and μ
  // and still solves (a pushed pair closes).
  const Matrix X = (Matrix(2, 2) << 0.5, 0.1, 0.5, 0.0).finished();
  const std::vector<ContactPair> pair = {make_pair(0, {1}, {1.0}, vec({0.0, 1.0}))};
  const Matrix F = Matrix::Identity(4, 4);
  OperatorContact op(2, [&F](const Vector& r) { return Vector(F * r); }, X, pair, vec({0.3}));
  const std::string what = message_of([&] { op.set_pairs(pair, vec({-0.5})); });
  EXPECT_NE(what.find("friction coefficient of pair 0 is -0.5"), std::string::npos) << what;
  ASSERT_EQ(op.pairs(), 1);
  EXPECT_EQ(op.mu()[0], 0.3);
  // Slave pushed 0.2 down onto the master 0.1 below it: with F* = I, W_nn = 2 and the normal
  // force closes the gap, λ_n = (0.2 − 0.1)/2.
  const CondensedStep r = op.step(vec({0.0, -0.2, 0.0, 0.0}));
  EXPECT_NEAR(r.lambda[0], 0.05, 1e-9);
}
