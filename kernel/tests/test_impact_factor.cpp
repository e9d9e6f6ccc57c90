// Copyright flexcontact developers. MIT licence.

/// @file test_impact_factor.cpp
/// @brief The impact step's factor path (F̂ applied by blocks through a factor of Ŵ, W_eff's
/// columns of the index set fetched and held) against the dense path (F̂ and W_eff formed),
/// on an elastic body of random stiffness whose front nodes hit a held wall in 3D with
/// friction and crushing: every step's impulses and velocities agree to 1e-10.

#include "contact_testing.hpp"
#include "flexcontact/impact.hpp"

#include <gtest/gtest.h>

#include <random>
#include <vector>

using namespace flexcontact;
using namespace flexcontact::testing;

namespace
{
constexpr int front = 6;  // slave nodes, each facing its own wall node
constexpr int inner = 10; // nodes behind them
constexpr int n_nodes = 2 * front + inner;
constexpr int n_dofs = 3 * n_nodes;

/// @brief Global node of contact node a: the slaves 0…front−1, then the wall nodes.
int global_node(int a) { return a < front ? a : front + inner + (a - front); }

struct Body
{
  Matrix What;                  ///< iteration matrix, identity rows on the held wall
  Eigen::LLT<Matrix> factor;
  std::vector<int> contact;     ///< global DOFs of the contact DOFs, node-major
  std::vector<bool> held;       ///< per contact DOF
  Matrix X;                     ///< contact node coordinates
  std::vector<ContactPair> pairs;
};

Body make_body(double h)
{
  std::mt19937 gen(11);
  std::normal_distribution<double> g;
  const int free = 3 * (front + inner);
  Matrix A(free, free);
  for (int i = 0; i < free; ++i)
    for (int j = 0; j < free; ++j)
      A(i, j) = g(gen);
  Body b;
  b.What = Matrix::Identity(n_dofs, n_dofs);
  // M (unit masses) + h²θ² K with K = AᵀA scaled to a stiff body
  b.What.topLeftCorner(free, free)
      = Matrix::Identity(free, free) + h * h * 0.25 * 1e4 * (A.transpose() * A) / free;
  b.factor.compute(b.What);
  b.X = Matrix::Zero(2 * front, 3);
  for (int a = 0; a < 2 * front; ++a)
  {
    // Slave k starts 0.4k mm from its wall node: the pairs close one after another, so
    // the index set grows over the steps.
    b.X(a, 0) = a < front ? 4e-4 * a : 0.0;
    b.X(a, 1) = 0.1 * (a % front);
    b.X(a, 2) = 0.05 * ((a % front) % 2);
    for (int c = 0; c < 3; ++c)
    {
      b.contact.push_back(3 * global_node(a) + c);
      b.held.push_back(a >= front);
    }
  }
  for (int k = 0; k < front; ++k)
    b.pairs.push_back(make_pair(k, {front + k}, {1.0}, vec({1.0, 0.0, 0.0})));
  return b;
}

Vector gather(const Body& b, const Vector& g)
{
  Vector x(static_cast<Eigen::Index>(b.contact.size()));
  for (std::size_t a = 0; a < b.contact.size(); ++a)
    x[static_cast<Eigen::Index>(a)] = g[b.contact[a]];
  return x;
}

Vector scatter(const Body& b, const Vector& x)
{
  Vector g = Vector::Zero(n_dofs);
  for (std::size_t a = 0; a < b.contact.size(); ++a)
    g[b.contact[a]] = x[static_cast<Eigen::Index>(a)];
  return g;
}

/// @brief Runs `steps` steps with the given kernel object; returns every step's impulses.
std::vector<Vector> run(const Body& b, ImpactContact& c, double h, int steps, Vector& u,
                        Vector& v)
{
  std::vector<Vector> impulses;
  for (int i = 0; i < steps; ++i)
  {
    // No external force: the body flies at the wall and bounces off.
    const Vector res = Vector::Zero(n_dofs);
    const Vector vfree = v + b.factor.solve(res);
    const ImpactStep s = c.step(gather(b, u), gather(b, v), gather(b, vfree));
    const Vector vnew = vfree + b.factor.solve(scatter(b, s.reaction));
    u += h * (0.5 * vnew + 0.5 * v);
    v = vnew;
    impulses.push_back(s.impulse);
  }
  return impulses;
}
} // namespace

TEST(ImpactFactorPath, AgreesWithTheDensePathStepByStep)
{
  const double h = 1e-3;
  const Body b = make_body(h);
  const Matrix Winv = b.factor.solve(Matrix::Identity(n_dofs, n_dofs));
  Matrix F(b.contact.size(), b.contact.size());
  for (std::size_t i = 0; i < b.contact.size(); ++i)
    for (std::size_t j = 0; j < b.contact.size(); ++j)
      F(i, j) = Winv(b.contact[i], b.contact[j]);
  int blocks = 0;
  BlockOperator block = [&](const Matrix& R)
  {
    ++blocks;
    Matrix G = Matrix::Zero(n_dofs, R.cols());
    for (std::size_t a = 0; a < b.contact.size(); ++a)
      G.row(b.contact[a]) = R.row(static_cast<Eigen::Index>(a));
    const Matrix Y = b.factor.solve(G);
    Matrix out(R.rows(), R.cols());
    for (std::size_t a = 0; a < b.contact.size(); ++a)
      out.row(static_cast<Eigen::Index>(a)) = Y.row(b.contact[a]);
    return out;
  };
  const Vector mu = Vector::Constant(front, 0.3);
  ImpactContact dense(3, F, b.X, b.pairs, mu, 0.0, h, 0.5, b.held);
  ImpactContact factor(3, block, b.X, b.pairs, mu, 0.0, h, 0.5, b.held, SolverOptions{}, 1e9);
  // Two pairs crush at a cap their impact force passes.
  Vector cap = Vector::Constant(front, std::numeric_limits<double>::infinity());
  cap[1] = cap[4] = 20.0;
  dense.set_crushing(cap);
  factor.set_crushing(cap);

  Vector u0 = Vector::Zero(n_dofs), v0 = Vector::Zero(n_dofs);
  for (int node = 0; node < front + inner; ++node)
  {
    v0[3 * node] = -1.0;                   // towards the wall
    v0[3 * node + 1] = 0.2 * (node % 3 - 1); // and sliding along it
  }
  Vector u1 = u0, v1 = v0, u2 = u0, v2 = v0;
  const std::vector<Vector> Pd = run(b, dense, h, 40, u1, v1);
  const std::vector<Vector> Pf = run(b, factor, h, 40, u2, v2);
  double peak = 0.0;
  for (const Vector& P : Pd)
    peak = std::max(peak, P.cwiseAbs().maxCoeff());
  ASSERT_GT(peak, 0.0);
  for (std::size_t i = 0; i < Pd.size(); ++i)
    EXPECT_LE((Pd[i] - Pf[i]).cwiseAbs().maxCoeff(), 1e-10 * peak) << "step " << i;
  EXPECT_LE((v1 - v2).cwiseAbs().maxCoeff(), 1e-10 * v0.cwiseAbs().maxCoeff());
  EXPECT_LE((dense.node_crush_depth() - factor.node_crush_depth()).cwiseAbs().maxCoeff(),
            1e-10 * std::max(dense.node_crush_depth().maxCoeff(), 1e-300));
  EXPECT_GT(dense.node_crush_depth().maxCoeff(), 0.0); // the caps did bind
  // The columns are fetched once per pair, not per step, as the index set grows.
  EXPECT_EQ(factor.block_columns(), 3L * front);
  EXPECT_GT(factor.block_products(), 1);
  EXPECT_LE(factor.block_products(), front);
  EXPECT_EQ(factor.cached_pairs(), front);
}

TEST(ImpactFactorPath, RefusesWhatNeedsFhatAndTooLittleMemory)
{
  const double h = 1e-3;
  const Body b = make_body(h);
  BlockOperator block = [&](const Matrix& R) { return R; };
  const Vector mu = Vector::Constant(front, 0.3);
  ImpactContact c(3, block, b.X, b.pairs, mu, 0.0, h, 0.5, b.held, SolverOptions{}, 100.0);
  const Vector z = Vector::Zero(static_cast<Eigen::Index>(b.contact.size()));
  EXPECT_THROW(c.step_condensed(z, z, z), std::logic_error);
  EXPECT_THROW(c.set_flexibility(Matrix::Identity(z.size(), z.size()), h), std::logic_error);
  Vector v = z;
  for (int k = 0; k < front; ++k)
    v[3 * k] = -1.0;
  try
  {
    c.step(z, v, v);
    FAIL() << "100 bytes held W_eff's columns";
  }
  catch (const std::runtime_error& e)
  {
    EXPECT_NE(std::string(e.what()).find("GB for W_eff's columns"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(ImpactContact(3, block, b.X, b.pairs, mu, 0.0, h, 0.5, b.held, SolverOptions{}, 0.0),
               std::invalid_argument);
}
