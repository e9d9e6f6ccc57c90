// Copyright flexcontact developers. MIT licence.

/// @file test_impact.cpp
/// @brief The Moreau–Jean contact step on small systems integrated here with dense algebra:
/// a mass–spring hitting a rigid wall (impulse, contact duration, energy), restitution of a
/// single mass, Coulomb friction on impulses, the step from the condensed right-hand side
/// (one back-substitution) against the two-solve step, and bad input.

#include "contact_testing.hpp"
#include "flexcontact/impact.hpp"
#include "flexcontact/increment.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

using namespace flexcontact;
using namespace flexcontact::testing;

namespace
{
// Three nodes in 2D: node 0 (front mass, slave) touches the wall at x = 0, node 1 (back
// mass) sits at x = L behind it, joined by a spring k along x; node 2 is the wall (master,
// held). Global DOF 2i + c; the contact nodes are node 0 (contact node 0) and node 2
// (contact node 1), so the contact DOFs are 0, 1, 4, 5.
constexpr double m = 2.0, k = 800.0, L = 1.0;
const std::vector<int> contact_dofs{0, 1, 4, 5};
const std::vector<bool> wall_held{false, false, true, true};

struct ImpactRun
{
  Vector u, v;                   ///< final state
  double impulse_x = 0.0;        ///< Σ of the slave impulses along x (on the masses)
  double contact_work = 0.0, friction_work = 0.0;
  int first_contact = -1, last_contact = -1;
  double energy0 = 0.0, energy = 0.0;
};

/// @brief A dense symmetric positive definite n × n flexibility: the Hilbert matrix plus I.
Matrix hilbert_plus_identity(int n)
{
  Matrix A(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      A(i, j) = 1.0 / (1.0 + i + j) + (i == j ? 1.0 : 0.0);
  return A;
}

double energy(const Matrix& M, const Matrix& K, const Vector& u, const Vector& v)
{
  return 0.5 * v.dot(M * v) + 0.5 * u.dot(K * u);
}

/// @brief Integrates the θ = ½ scheme for `steps` steps of size h from v0 on both masses
/// (spring on: the mass–spring; spring off and back mass far: a single mass). `split`: each
/// step as one back-substitution (step_condensed from the condensed right-hand side, then
/// the interior's velocity from the returned contact values, by dense algebra here) instead
/// of the two solves v_free = v + Ŵ⁻¹ res, v⁺ = v_free + Ŵ⁻¹ Bᵀ P.
ImpactRun integrate(double h, int steps, const Vector& v0, double e, double mu, double kk = k,
                    bool split = false)
{
  const double theta = 0.5;
  Matrix M = Matrix::Zero(6, 6), K = Matrix::Zero(6, 6);
  M.diagonal() << m, m, m, m, 0, 0;
  K(0, 0) = K(2, 2) = kk;
  K(0, 2) = K(2, 0) = -kk;
  Matrix What = M + h * h * theta * theta * K;
  What(4, 4) = What(5, 5) = 1.0; // held DOFs: identity rows, as DOLFINx assembles them
  const Eigen::LLT<Matrix> factor(What);
  const Matrix Winv = factor.solve(Matrix::Identity(6, 6));
  Matrix F(4, 4);
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b)
      F(a, b) = Winv(contact_dofs[a], contact_dofs[b]);
  const Matrix X = (Matrix(2, 2) << 0.0, 0.0, 0.0, 0.0).finished();
  ImpactContact c(2, F, X, {make_pair(0, {1}, {1.0}, vec({1.0, 0.0}))}, vec({mu}), e, h, theta,
                  wall_held);

  ImpactRun r;
  Vector u = Vector::Zero(6), v = Vector::Zero(6);
  u[2] = 0.0; // the back node's displacement; its position is L
  v.head(4) << v0[0], v0[1], v0[0], v0[1];
  r.energy0 = energy(M, K, u, v);
  auto gather = [](const Vector& g)
  {
    Vector x(4);
    for (int a = 0; a < 4; ++a)
      x[a] = g[contact_dofs[a]];
    return x;
  };
  // The interior DOFs (the back node's) for the split step's condensation and expansion.
  const std::vector<int> inner{2, 3};
  const Matrix Wii = What(inner, inner), Wic = What(inner, contact_dofs);
  const Eigen::LLT<Matrix> inner_factor(Wii);
  for (int i = 0; i < steps; ++i)
  {
    const Vector res = -h * (K * (u + h * theta * v));
    Vector vnew(6);
    ImpactStep s;
    if (split)
    {
      const Vector res_i = res(inner);
      const Vector b_c = gather(res) - Wic.transpose() * inner_factor.solve(res_i);
      s = c.step_condensed(gather(u), gather(v), b_c);
      Vector dv(6);
      dv(contact_dofs) = s.velocity_change_c;
      const Vector dv_i = inner_factor.solve(res_i - Wic * s.velocity_change_c);
      dv(inner) = dv_i;
      vnew = v + dv;
    }
    else
    {
      const Vector vfree = v + factor.solve(res);
      s = c.step(gather(u), gather(v), gather(vfree));
      Vector rg = Vector::Zero(6);
      for (int a = 0; a < 4; ++a)
        rg[contact_dofs[a]] = s.reaction[a];
      vnew = vfree + factor.solve(rg);
    }
    u += h * (theta * vnew + (1 - theta) * v);
    v = vnew;
    r.impulse_x += s.slave_impulse[0];
    r.contact_work += s.contact_work;
    r.friction_work += s.friction_work;
    if (s.impulse[0] > 0.0)
    {
      r.first_contact = r.first_contact < 0 ? i : r.first_contact;
      r.last_contact = i;
    }
  }
  r.u = u;
  r.v = v;
  r.energy = energy(M, K, u, v);
  return r;
}
} // namespace

TEST(Impact, MassSpringOnAWallLosesTheFrontMassEnergyAndBouncesOff)
{
  // e = 0: the front mass stops at once (impulse m v), the spring stops the back mass over
  // half a period π/ω of the back mass on a fixed spring (impulse 2 m v), and the pair
  // leaves with the back mass at v: 3 m v in all, and ½ m v² of the m v² is lost.
  const double v = 1.5, omega = std::sqrt(k / m), tc = std::numbers::pi / omega;
  const double h = tc / 400;
  const ImpactRun r = integrate(h, 600, vec({-v, 0.0}), 0.0, 0.0);
  EXPECT_NEAR(r.impulse_x, 3 * m * v, 1e-3 * m * v);
  // Impulse = change of momentum, exactly for the scheme (K's rows sum to zero).
  EXPECT_NEAR(r.impulse_x, m * (r.v[0] + r.v[2]) - m * (-2 * v), 1e-10 * m * v);
  EXPECT_NEAR((r.last_contact + 1 - r.first_contact) * h, tc, 0.01 * tc);
  EXPECT_NEAR(r.energy, 0.5 * m * v * v, 0.01 * 0.5 * m * v * v);
  // Energy balance of the θ = ½ scheme: E − E0 = Σ P·U^θ, U^θ = (U⁺ + U⁻)/2, to round-off.
  EXPECT_NEAR(r.energy - r.energy0, r.contact_work, 1e-10 * r.energy0);
}

TEST(Impact, RestitutionSetsTheReboundOfASingleMass)
{
  // No spring: the front mass alone. U_n⁺ = −e U_n⁻, and with e = 1 no energy is lost.
  for (double e : {0.0, 0.5, 1.0})
  {
    const ImpactRun r = integrate(1e-3, 20, vec({-2.0, 0.0}), e, 0.0, 0.0);
    EXPECT_NEAR(r.v[0], 2.0 * e, 1e-12) << "e = " << e;
    EXPECT_NEAR(r.impulse_x, m * 2.0 * (1 + e), 1e-12) << "e = " << e;
    EXPECT_NEAR(r.energy - r.energy0, r.contact_work, 1e-12 * r.energy0) << "e = " << e;
  }
}

TEST(Impact, FrictionImpulseIsMuTimesNormalWhileSliding)
{
  // A single mass hits the wall obliquely, fast along the wall: it slides throughout, so
  // P_t = μ P_n and the tangential speed drops by μ (1 + e) v_n. Friction dissipates.
  const double vn = 1.0, vt = 3.0, mu = 0.3, e = 0.5;
  const ImpactRun r = integrate(1e-3, 20, vec({-vn, vt}), e, mu, 0.0);
  EXPECT_NEAR(r.v[0], e * vn, 1e-12);
  EXPECT_NEAR(r.v[1], vt - mu * (1 + e) * vn, 1e-9);
  EXPECT_NEAR(r.impulse_x, m * vn * (1 + e), 1e-12);
  EXPECT_LT(r.friction_work, 0.0);
  EXPECT_NEAR(r.energy - r.energy0, r.contact_work, 1e-12 * r.energy0);
  // Slow along the wall: it sticks, and the tangential velocity stops.
  const ImpactRun s = integrate(1e-3, 20, vec({-vn, 0.1}), e, mu, 0.0);
  EXPECT_NEAR(s.v[1], 0.0, 1e-9);
}

TEST(Impact, CondensedStepIsTheTwoSolveStep)
{
  // The same runs with each step split (condensed right-hand side in, contact-DOF velocity
  // change out, the rest by expansion): the states agree to round-off, with and without
  // friction, restitution and the spring.
  struct Case
  {
    double h;
    int steps;
    Vector v0;
    double e, mu, kk;
  };
  const double omega = std::sqrt(k / m), tc = std::numbers::pi / omega;
  const std::vector<Case> cases{{tc / 400, 600, vec({-1.5, 0.0}), 0.0, 0.0, k},
                                {1e-3, 20, vec({-2.0, 0.0}), 0.5, 0.0, 0.0},
                                {1e-3, 20, vec({-1.0, 3.0}), 0.5, 0.3, 0.0},
                                {tc / 200, 300, vec({-1.0, 0.5}), 0.2, 0.3, k}};
  for (const Case& cs : cases)
  {
    const ImpactRun a = integrate(cs.h, cs.steps, cs.v0, cs.e, cs.mu, cs.kk, true);
    const ImpactRun b = integrate(cs.h, cs.steps, cs.v0, cs.e, cs.mu, cs.kk, false);
    ASSERT_GE(b.first_contact, 0);
    EXPECT_EQ(a.first_contact, b.first_contact);
    EXPECT_EQ(a.last_contact, b.last_contact);
    EXPECT_LE((a.v - b.v).norm(), 1e-12 * b.v.norm()) << "mu = " << cs.mu;
    EXPECT_LE((a.u - b.u).norm(), 1e-12 * std::max(b.u.norm(), 1e-300));
    EXPECT_NEAR(a.impulse_x, b.impulse_x, 1e-12 * std::abs(b.impulse_x));
    EXPECT_NEAR(a.contact_work, b.contact_work, 1e-12 * b.energy0);
    EXPECT_NEAR(a.friction_work, b.friction_work, 1e-12 * b.energy0);
  }
}

TEST(Impact, CondensedStepHoldsHeldDofsAndNamesBadInput)
{
  // Held DOFs (the wall's, 2 and 3 here) take Ŵ's identity rows: their velocity change is
  // the condensed right-hand side itself, and the reaction does not reach them.
  const Matrix F = (Matrix(4, 4) << 2, 1, 0, 0, 1, 3, 0, 0, 0, 0, 5, 0, 0, 0, 0, 7).finished();
  ImpactContact c(2, F, Matrix::Zero(2, 2), {make_pair(0, {1}, {1.0}, vec({1.0, 0.0}))},
                  vec({0.0}), 0.0, 1e-3, 0.5, wall_held);
  const Vector z = Vector::Zero(4), b = vec({-1.0, 0.5, 0.25, -0.125});
  const ImpactStep s = c.step_condensed(z, z, b);
  ASSERT_EQ(s.active_pairs, 1);
  // W_eff = F_00 = 2 on the normal; U_free,n = (F b)_0 − b_2 = −1.5 − 0.25, so
  // P_n = 0.875 and U_n⁺ = 0; the reaction is on the slave's DOFs only.
  EXPECT_NEAR(s.impulse[0], 0.875, 1e-10);
  EXPECT_NEAR(s.velocity[0], 0.0, 1e-10);
  const Vector r = vec({0.875, 0.0, 0.0, 0.0});
  const Vector expected = vec({(F * (b + r))[0], (F * (b + r))[1], b[2], b[3]});
  EXPECT_LE((s.velocity_change_c - expected).norm(), 1e-10);
  EXPECT_EQ((s.velocity_c - s.velocity_change_c).norm(), 0.0);
  // The same step from v_free = v + F b (held DOFs: + b) gives the same impulse.
  const Vector vfree = vec({(F * b)[0], (F * b)[1], b[2], b[3]});
  ImpactContact d(2, F, Matrix::Zero(2, 2), {make_pair(0, {1}, {1.0}, vec({1.0, 0.0}))},
                  vec({0.0}), 0.0, 1e-3, 0.5, wall_held);
  EXPECT_NEAR(d.step(z, z, vfree).impulse[0], s.impulse[0], 1e-12);
  EXPECT_EQ(d.step(z, z, vfree).velocity_change_c.size(), 0);
  EXPECT_NE(message_of([&] { c.step_condensed(z, z, Vector::Zero(3)); })
                .find("b_c has 3 entries"),
            std::string::npos);
  const Vector bad = vec({NAN, 0.0, 0.0, 0.0});
  EXPECT_NE(message_of([&] { c.step_condensed(z, z, bad); }).find("b_c is not finite"),
            std::string::npos);
}

TEST(Impact, CondensedStepOnAFewOfManyContactNodesEqualsTheWholeProduct)
{
  // Five contact nodes, one pair (slave 0 on master 3): B reads 4 of the 10 DOFs, so the
  // free velocity before the solve is formed on those rows only, and the velocity change
  // after it from one product F (b + r). It must equal the two whole products of
  // v_free = v + F b, Δv = F b + F r, on every DOF, held ones (node 4) included.
  const int n = 10;
  const Matrix A = hilbert_plus_identity(n);
  std::vector<bool> held(n, false);
  held[8] = held[9] = true;
  Matrix F = A;
  for (int i = 8; i < n; ++i)
  {
    F.row(i).setZero();
    F.col(i).setZero();
  }
  const Matrix X = Matrix::Zero(5, 2);
  const auto pair_on = [](int master)
  { return std::vector<ContactPair>{make_pair(0, {master}, {1.0}, vec({1.0, 0.0}))}; };
  ImpactContact c(2, A, X, pair_on(3), vec({0.3}), 0.0, 1e-3, 0.5, held);
  ImpactContact whole(2, A, X, pair_on(3), vec({0.3}), 0.0, 1e-3, 0.5, held);
  const Vector u = Vector::Zero(n);
  Vector v(n), b(n);
  for (int i = 0; i < n; ++i)
  {
    v[i] = 0.1 * std::sin(1.0 + i);
    b[i] = -0.5 + 0.2 * std::cos(2.0 * i);
  }
  v[0] = -0.5; // the slave approaches either master
  auto check = [&](ImpactContact& a, ImpactContact& ref)
  {
    const ImpactStep s = a.step_condensed(u, v, b);
    Vector dv = F * b;
    for (int i = 8; i < n; ++i)
      dv[i] = b[i];
    const ImpactStep t = ref.step(u, v, v + dv);
    ASSERT_EQ(s.active_pairs, 1);
    EXPECT_LE((s.impulse - t.impulse).norm(), 1e-13 * t.impulse.norm());
    Vector expected = dv + F * t.reaction;
    EXPECT_LE((s.velocity_change_c - expected).norm(), 1e-13 * expected.norm());
    EXPECT_EQ(s.velocity_change_c[8], b[8]);
    EXPECT_EQ(s.velocity_change_c[9], b[9]);
  };
  check(c, whole);
  // Re-paired on master 1: the rows read change with B.
  c.set_pairs(pair_on(1), vec({0.3}));
  whole.set_pairs(pair_on(1), vec({0.3}));
  check(c, whole);
  // A body at rest away from contact: no load, no impulse, no velocity change at all.
  ImpactContact apart(2, A, Matrix::Constant(5, 2, 0.0), pair_on(3), vec({0.3}), 0.0, 1e-3,
                      0.5, held);
  Vector away = Vector::Zero(n);
  away[0] = 1.0; // the gap n·(u_slave − u_master) opens by 1 m
  const ImpactStep r = apart.step_condensed(away, Vector::Zero(n), Vector::Zero(n));
  EXPECT_EQ(r.active_pairs, 0);
  EXPECT_EQ(r.velocity_change_c.norm(), 0.0);
}

TEST(Impact, TheVelocityAfterAStepReadsOnlyTheClosedPairsColumnsOfW)
{
  // Four pairs (slave k on master k + 4, normal x), all touching: U⁺ = W P + U_free with P
  // zero outside the index set. With one pair closing, the product reads that pair's
  // columns of W only; with all four closing, all of W. Both equal the whole product.
  const int n = 16;
  const Matrix F = hilbert_plus_identity(n);
  std::vector<ContactPair> pairs;
  for (int k = 0; k < 4; ++k)
    pairs.push_back(make_pair(k, {k + 4}, {1.0}, vec({1.0, 0.0})));
  const Matrix X = Matrix::Zero(8, 2);
  const Vector mu = Vector::Constant(4, 0.3);
  for (const int closing : {1, 4})
  {
    ImpactContact c(2, F, X, pairs, mu, 0.0, 1e-3, 0.5);
    Vector v = Vector::Zero(n);
    for (int k = 0; k < 4; ++k)
    {
      v[2 * k] = k < closing ? -0.5 - 0.1 * k : 0.5; // the slave's x: closing or opening
      v[2 * k + 1] = 0.05 * (k + 1);                  // and a tangential slip
    }
    const ImpactStep s = c.step(Vector::Zero(n), v, v);
    ASSERT_EQ(s.active_pairs, closing);
    const Vector expected = c.W() * s.impulse + s.velocity_before;
    EXPECT_LE((s.velocity - expected).norm(), 1e-14 * expected.norm()) << closing;
    EXPECT_GT(s.impulse.norm(), 0.0);
  }
}

TEST(Impact, CondensedStepGoesByTheDiagonalBlocksOfTwoBodies)
{
  // Two bodies condensed apart, three contact nodes each (DOFs 0–5 and 6–11), three pairs
  // from the first onto the second, so B reads every DOF: F̂ = diag(F₁, F₂), and the
  // products go by its two blocks. They must equal the whole products F̂ b and F̂ (b + r)
  // to round-off, with a body at rest (its part of b zero), a coupling entry (one block)
  // and a block that is not symmetric (multiplied whole, not by its lower triangle).
  const int n = 12;
  Matrix F = Matrix::Zero(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      if ((i < 6) == (j < 6))
        F(i, j) = 1.0 / (1.0 + i % 6 + j % 6) + (i == j ? 1.0 + 0.1 * i : 0.0);
  const Matrix X = Matrix::Zero(6, 2);
  std::vector<ContactPair> pairs;
  for (int k = 0; k < 3; ++k)
    pairs.push_back(make_pair(k, {3 + k}, {1.0}, vec({1.0, 0.0})));
  const Vector mu = vec({0.3, 0.3, 0.3});
  const Vector u = Vector::Zero(n);
  Vector v(n), b(n);
  for (int i = 0; i < n; ++i)
  {
    v[i] = 0.1 * std::sin(1.0 + i);
    b[i] = -0.5 + 0.2 * std::cos(2.0 * i);
  }
  for (int k = 0; k < 3; ++k)
    v[2 * k] = -0.5; // the first body's nodes approach the second's
  auto check = [&](const Matrix& Fh, const Vector& load, int blocks, int closed = 3,
                   int symmetric = -1)
  {
    ImpactContact c(2, Fh, X, pairs, mu, 0.0, 1e-3, 0.5, {});
    ImpactContact ref(2, Fh, X, pairs, mu, 0.0, 1e-3, 0.5, {});
    EXPECT_EQ(c.diagonal_blocks(), blocks);
    EXPECT_EQ(c.symmetric_blocks(), symmetric < 0 ? blocks : symmetric);
    const ImpactStep s = c.step_condensed(u, v, load);
    const Vector dv = Fh * load;
    const ImpactStep t = ref.step(u, v, v + dv);
    ASSERT_EQ(s.active_pairs, closed);
    EXPECT_LE((s.impulse - t.impulse).norm(), 1e-13 * t.impulse.norm());
    const Vector expected = dv + Fh * t.reaction;
    EXPECT_LE((s.velocity_change_c - expected).norm(), 1e-13 * expected.norm());
  };
  check(F, b, 2);
  Vector resting = b;
  resting.tail(6).setZero(); // the second body unloaded: its block's product skipped
  check(F, resting, 2);
  Matrix coupled = F;
  coupled(1, 7) = coupled(7, 1) = 1e-3;
  check(coupled, b, 1);
  Matrix skewed = F;
  skewed(7, 6) += 0.05; // the second block loses its symmetry, the first keeps it
  check(skewed, b, 2, 3, 1);
  // One pair closing: its reaction has 2 of each block's 6 DOFs, read by those columns.
  v[2] = v[4] = 0.5;
  check(F, b, 2, 1);
  check(F, resting, 2, 1);
}

namespace
{
/// @brief One contact step of a slave node against a held wall node, W = I on the pair:
/// contact DOFs (slave x, slave y, wall x, wall y), normal along x.
ImpactStep one_step(const Vector& u_c, const Vector& v_c, const Vector& vfree_c, double e,
                    double mu, double theta = 0.5)
{
  const Matrix X = Matrix::Zero(2, 2);
  ImpactContact c(2, Matrix::Identity(4, 4), X, {make_pair(0, {1}, {1.0}, vec({1.0, 0.0}))},
                  vec({mu}), e, 1e-3, theta, wall_held);
  return c.step(u_c, v_c, vfree_c);
}
} // namespace

TEST(Impact, FrictionWorkIsTakenAlongTheStepsSlip)
{
  // A node in contact slides at 0.1 and is pushed in (U_n,free = −1) and along (2) the
  // wall: P_n = 1, P_t = μ against the slip, U_t⁺ = 2 − μ = 1.7. The slip of the step is
  // h U_t^θ = h (U_t⁺ + U_t⁻)/2, so friction works −μ P_n (1.7 + 0.1)/2 and, with U_n⁺ = U_n⁻
  // = 0, that is all the contact work: the scheme's own contact dissipation is zero. Taking
  // friction's work at U_t⁺ instead (−μ P_n 1.7) left −0.24 as "contact dissipation".
  const double mu = 0.3;
  const ImpactStep s = one_step(vec({0, 0, 0, 0}), vec({0, 0.1, 0, 0}), vec({-1, 2, 0, 0}),
                                0.0, mu);
  ASSERT_EQ(s.active_pairs, 1);
  EXPECT_NEAR(s.impulse[0], 1.0, 1e-10);
  EXPECT_NEAR(std::abs(s.impulse[1]), mu, 1e-10);
  EXPECT_NEAR(std::abs(s.velocity[1]), 2.0 - mu, 1e-10);
  EXPECT_NEAR(s.friction_work, -mu * (2.0 - mu + 0.1) / 2, 1e-10);
  EXPECT_NEAR(s.contact_work - s.friction_work, 0.0, 1e-10);
  // θ = 1: the slip is h U_t⁺, and friction works −μ P_n |U_t⁺|.
  const ImpactStep t = one_step(vec({0, 0, 0, 0}), vec({0, 0.1, 0, 0}), vec({-1, 2, 0, 0}),
                                0.0, mu, 1.0);
  EXPECT_NEAR(t.friction_work, -mu * (2.0 - mu), 1e-10);
}

TEST(Impact, AnOverlappingPairThatOpensDoesNoPositiveWork)
{
  // The node overlaps the wall by 1 cm and moves out at 0.05 (U_n⁻ > 0), but the free
  // velocity pushes it in: Newton's law (closing pairs) does not apply; the gap is held
  // over the step instead, U_n^θ = 0, so the impulse does no work (U_n⁺ = 0 would have let
  // it work +½ P_n U_n⁻ > 0, an energy gain).
  for (double theta : {0.5, 0.75, 1.0})
  {
    const ImpactStep s = one_step(vec({-0.01, 0, 0, 0}), vec({0.05, 0, 0, 0}),
                                  vec({-1, 0, 0, 0}), 0.0, 0.0, theta);
    ASSERT_EQ(s.active_pairs, 1);
    EXPECT_GT(s.impulse[0], 0.0);
    EXPECT_NEAR(theta * s.velocity[0] + (1 - theta) * s.velocity_before[0], 0.0, 1e-12);
    EXPECT_NEAR(s.contact_work, 0.0, 1e-12) << "theta = " << theta;
  }
}

TEST(Impact, BadInputIsNamed)
{
  const Matrix F = Matrix::Identity(4, 4);
  const Matrix X = Matrix::Zero(2, 2);
  auto make = [&](double e, double h, double theta)
  {
    ImpactContact c(2, F, X, {make_pair(0, {1}, {1.0}, vec({1.0, 0.0}))}, vec({0.0}), e, h,
                    theta);
  };
  EXPECT_NE(message_of([&] { make(1.5, 1e-3, 0.5); }).find("restitution is 1.5"),
            std::string::npos);
  EXPECT_NE(message_of([&] { make(0.0, 0.0, 0.5); }).find("dt_s is 0"), std::string::npos);
  EXPECT_NE(message_of([&] { make(0.0, NAN, 0.5); }).find("dt_s is nan"), std::string::npos);
  EXPECT_NE(message_of([&] { make(0.0, 1e-3, 0.3); }).find("theta is 0.3"), std::string::npos);
  ImpactContact c(2, F, X, {make_pair(0, {1}, {1.0}, vec({1.0, 0.0}))}, vec({0.0}), 0.0, 1e-3,
                  0.5);
  const Vector z = Vector::Zero(4);
  EXPECT_NE(message_of([&] { c.step(z, Vector::Zero(3), z); }).find("v_c has 3 entries"),
            std::string::npos);
}
