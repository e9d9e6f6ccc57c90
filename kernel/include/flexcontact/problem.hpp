// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file problem.hpp
/// @brief The condensed frictional contact problem of one increment, and what a solver reports.
///
/// Unknowns are ordered pair by pair, normal first: pair k owns entries [k·d, k·d + d) of λ
/// and u, with d = 2 (n, t) or d = 3 (n, t1, t2). λ_n ≥ 0 is compression, u_n ≥ 0 separation.
/// The local problem of one increment is
///
///     u = W λ + q,
///     u_n ≥ 0, λ_n ≥ 0, u_n λ_n = 0,                        (Signorini)
///     |λ_t| ≤ μ λ_n, |λ_t| < μ λ_n ⇒ u_t = 0,
///     u_t ≠ 0 ⇒ λ_t = −μ λ_n u_t/|u_t|                       (Coulomb)
///
/// where u_t is the tangential slip of the increment. The incremental driver (increment.hpp)
/// builds q from the total gap so that this holds.
///
/// A crushable interface caps each pair's normal force, λ_n ≤ c_k (docs/crushing.md):
///
///     λ_n = 0 ⇒ u_n ≥ 0,   0 < λ_n < c_k ⇒ u_n = 0,   λ_n = c_k ⇒ u_n ≤ 0   (crush),
///     |λ_t| ≤ μ λ_n, Coulomb as above,
///
/// i.e. λ lies in the Coulomb cone truncated at λ_n = c_k, and −û (the De Saxcé velocity) is
/// in that set's normal cone. A crushing pair's u_n < 0 is the surface's irreversible
/// crush in the increment; the drivers carry it as a crush depth added to the gap.

#include <Eigen/Dense>
#include <limits>
#include <string>
#include <vector>

namespace flexcontact
{
using Matrix = Eigen::MatrixXd;
using Vector = Eigen::VectorXd;

/// @brief Contact state of one pair (the seed's three states).
/// The one coding of contact states, end to end: the kernel's pairs, the step results that
/// cross to Python (flexcontact.states) and the output field contact_status.
enum class PairState : int
{
  none = 0,  ///< not a contact node (output fields only; never a pair's state)
  open = 1,  ///< no contact: λ = 0
  stick = 2, ///< closed, no slip in the increment
  slip = 3,  ///< closed, sliding: λ_t on the boundary of the Coulomb cone
  crush = 4  ///< closed at the cap of a crushable interface: λ_n = c_k, the surface crushes
};

/// @brief Read-only view of one local problem u = W λ + q with friction coefficients μ.
struct ProblemView
{
  int dim;                           ///< 2 or 3 unknowns per pair
  Eigen::Ref<const Matrix> W;        ///< (m·d)×(m·d), symmetric positive semi-definite
  Eigen::Ref<const Vector> q;        ///< m·d
  Eigen::Ref<const Vector> mu;       ///< m, each ≥ 0
  /// m caps c_k > 0 of the normal forces (+∞: none), or null for no cap at all. A cap of
  /// +∞ and a null pointer give bitwise the same arithmetic.
  const double* cap = nullptr;
  int pairs() const { return static_cast<int>(q.size()) / dim; }
  /// @brief Pair k's cap, +∞ when it has none.
  double cap_of(int k) const { return cap ? cap[k] : std::numeric_limits<double>::infinity(); }
  /// @brief True if some pair has a finite cap.
  bool capped() const
  {
    if (cap)
      for (int k = 0; k < pairs(); ++k)
        if (cap[k] < std::numeric_limits<double>::infinity())
          return true;
    return false;
  }
};

/// @brief Options shared by every local solver.
struct SolverOptions
{
  /// Converged when the relative natural-map residual (residual.hpp) is below this. The
  /// forces are then right to about this times W's conditioning (40× on the patch test);
  /// 1e-13 there gave errors of 5e-12 for a Newton step or two more per increment.
  double tolerance = 1e-10;
  /// Iteration cap of each solver (active-set switches, Newton steps, or projection sweeps
  /// for the projection solver, which gets 50× this many).
  int max_iterations = 100;
  /// Solvers tried in order until one converges; names as in solver_names(). Empty: the
  /// default chain, most robust first.
  std::vector<std::string> chain;
  /// Print one line per iteration to stderr (debugging).
  bool verbose = false;
  /// Work limit, in billions of floating-point operations estimated from the sizes of each
  /// iteration's dense kernels (docs/solvers.md, "The work budget"). A solver alone stops
  /// (converged=false, its best iterate) at its first check past it; 0 means no limit. The
  /// chain (solve()) shares it among its attempts and stops trying once it is spent; there
  /// 0 means the automatic budget chain_work_budget_gflop() of the problem's size. Work,
  /// not time: the same input stops at the same iterate on a quiet and on a loaded machine.
  double work_budget_gflop = 0.0;
};

/// @brief The chain's work budget when SolverOptions::work_budget_gflop is 0, for n
/// unknowns: 50 + 200·(n/1000)³ Gflop (docs/solvers.md, "The work budget"). The cubic term
/// is 300 dense LU factorisations of the whole n × n Newton matrix; the constant is more
/// than the chain can spend within its iteration caps below 200 unknowns, so the hardest
/// small problems (condition numbers near 1e10) keep the thousands of damped Newton steps
/// they need in all the chain's variants, and the projection its turn.
double chain_work_budget_gflop(long n);

/// @brief What a local solver did and found.
struct SolveReport
{
  Vector lambda;                    ///< contact forces, local frame, pair by pair
  Vector u;                         ///< W λ + q
  std::vector<PairState> states;    ///< per pair, from (λ, u)
  std::string solver;               ///< name of the solver whose answer this is
  int iterations = 0;               ///< iterations of that solver
  int state_changes = 0;            ///< pair state switches (active set), 0 for others
  /// Estimated work done, in Gflop (WorkMeter, docs/solvers.md): this solver's, or for solve()
  /// the whole chain's.
  double work_gflop = 0.0;
  double residual = std::numeric_limits<double>::infinity(); ///< relative natural-map residual
  bool converged = false;
  bool cycled = false;              ///< active set revisited an earlier state vector
  std::vector<std::string> attempts; ///< one line per solver tried, in order, with outcome
  /// Bordered problems only (solvers.hpp: solve_newton_bordered): the rigid-mode amplitudes
  /// α of the bodies held only by contact, and an orthonormal basis (k × r) of the
  /// directions of α that no closed pair resists (set to zero: the minimum-norm answer).
  Vector alpha;
  Matrix undetermined;
};

} // namespace flexcontact
