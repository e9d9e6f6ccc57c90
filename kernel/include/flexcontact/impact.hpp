// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file impact.hpp
/// @brief One time step of dynamic contact on the condensed system: the Moreau–Jean
/// θ-scheme at velocity level with Newton restitution and Coulomb friction on impulses
/// (docs/impact.md).
///
/// The iteration matrix Ŵ = M + hθC + h²θ²K is factored once per time-step size outside the
/// kernel; F̂ = (Ŵ⁻¹)_cc, its inverse on the contact DOFs, comes in. With U = B v the relative
/// velocity of the pairs in their local frames (normal first), the step's local problem is
///
///     U⁺ = W_eff P + U_free,   W_eff = B F̂ Bᵀ,
///     for pairs of the index set I:  x_n = U_n⁺ + e U_n⁻ ≥ 0 ⟂ P_n ≥ 0   (U_n⁻ ≤ 0),
///                                    x_n = U_n⁺ + (1 − θ)/θ U_n⁻ ≥ 0 ⟂ P_n ≥ 0   (U_n⁻ > 0),
///                                    Coulomb on (P_t, U_t⁺) as in problem.hpp,
///     for the others:                P = 0,
///
/// which is the kernel's local problem x = W λ + q with q = U_free + e U_n⁻ (normal rows):
/// the same local solvers serve. I holds the pairs whose predicted gap g⁻ + hθ U_n⁻ is ≤ 0.
/// Contact DOFs are node-major as in pairs.hpp.

#include "flexcontact/operator_contact.hpp"
#include "flexcontact/pairs.hpp"
#include "flexcontact/problem.hpp"

#include <algorithm>
#include <Eigen/Sparse>
#include <vector>

namespace flexcontact
{
/// @brief What one time step's contact solve produced. Pair-by-pair vectors are normal
/// first, in the local frames; P is an impulse (N·s; N·s/m per unit thickness in 2D).
struct ImpactStep
{
  Vector impulse;                 ///< m·d, P
  Vector velocity;                ///< m·d, U⁺ = W_eff P + U_free
  Vector velocity_before;         ///< m·d, U⁻ = B v⁻
  Vector gap;                     ///< m·d, gap at the start of the step, B u⁻ + x0
  std::vector<PairState> states;  ///< per pair; open for pairs outside the index set
  std::vector<bool> active;       ///< per pair: in the index set I
  SolveReport report;             ///< the local solve (solver "none" when I is empty)
  Vector reaction;                ///< n_c, r_c = Bᵀ P; zero on constrained contact DOFs
  double normal_impulse = 0.0;    ///< Σ_k P_n,k
  Vector slave_impulse;           ///< d, Σ_k T_kᵀ P_k: impulse on the slave side, global axes
  Matrix pair_tangential;         ///< m × d, T_kᵀ (0, P_t,k) per pair, global axes
  /// Σ_k P_t,k·U_t,k^θ, U^θ = θU⁺ + (1 − θ)U⁻: the work of the tangential impulses along
  /// the step's slip h U_t^θ (the friction dissipation is minus this)
  double friction_work = 0.0;
  /// Σ_k P_k·U_k^θ: the work of all contact impulses in the scheme's energy balance
  double contact_work = 0.0;
  /// Σ_k (P_n,k/h) Δδ_k over the crushing pairs: the capped force times the crush
  /// increment, the part of −contact_work the crushing dissipated (≥ 0)
  double crush_work = 0.0;
  Vector crush_depth;             ///< m, δ of each pair's slave after the step (empty: no cap)
  /// max(0, −min_k (g_n,k + δ_k)) at the start of the step: the crushed surface's overlap
  double max_penetration = 0.0;
  int active_pairs = 0;           ///< |I|
  /// n_c, Δv_c = v⁺_c − v⁻_c = F̂ (b̃_c + r_c) on the contact DOFs (step_condensed only,
  /// empty after step): the contact values from which the factor's expansion of the
  /// condensed right-hand side b̃_c gives the step's whole Δv = Ŵ⁻¹ (b + Bᵀ P)
  Vector velocity_change_c;
  Vector velocity_c;              ///< n_c, v⁺_c = v⁻_c + Δv_c (step_condensed only)
};

/// @brief The contact part of a Moreau–Jean time step on the condensed system.
///
/// Holds B, x0 and W_eff = B F̂ Bᵀ for one time-step size, the restitution coefficient and
/// the last impulses (warm start). Stateless otherwise: the step gets the contact-DOF values
/// of u⁻, v⁻ and the free velocity v_free = v⁻ + Ŵ⁻¹ h r (step) or the condensed h r
/// (step_condensed), so that one step crosses the binding once. A contact DOF held by a
/// Dirichlet condition gets no flexibility (rows and columns of F̂ zeroed): a body whose
/// nodes are all held is exactly rigid.
class ImpactContact
{
public:
  /// @param dim 2 or 3
  /// @param Fhat n_c × n_c, (Ŵ⁻¹)_cc on the contact DOFs
  /// @param X n_nodes × dim coordinates of the contact nodes
  /// @param pairs slave, masters, weights and frame of each pair
  /// @param mu friction coefficient per pair
  /// @param restitution Newton's e in [0, 1]
  /// @param dt_s time step h > 0
  /// @param theta θ in [½, 1]
  /// @param constrained n_c flags of Dirichlet-held contact DOFs, or empty for none
  /// @throws std::invalid_argument naming the argument whose size or value is wrong
  ImpactContact(int dim, Matrix Fhat, Matrix X, std::vector<ContactPair> pairs, Vector mu,
                double restitution, double dt_s, double theta,
                std::vector<bool> constrained = {}, SolverOptions options = {});

  /// @brief The factor path: F̂ is not formed but applied to blocks of columns through the
  /// caller's factor of Ŵ (`Fhat`: Y = F̂ R, one multi-right-hand-side back-substitution).
  /// A step fetches W_eff's columns of the pairs of its index set that it does not hold yet
  /// (W[:, k] = B F̂ Bᵀ e_k, one block for all of them) and keeps them for the next steps,
  /// within `max_bytes` (8 bytes per entry of the m·d × d·pairs columns); the local problem
  /// is then the dense one's, restricted to the index set as on the dense path, so the
  /// answers agree to rounding. step_condensed is not available (it needs F̂ itself).
  ImpactContact(int dim, BlockOperator Fhat, Matrix X, std::vector<ContactPair> pairs, Vector mu,
                double restitution, double dt_s, double theta, std::vector<bool> constrained,
                SolverOptions options, double max_bytes);

  /// @brief Contact impulses of one step from the contact-DOF values of u⁻, v⁻ and v_free.
  /// @throws std::invalid_argument on wrong sizes or non-finite values
  /// @throws ConvergenceError if no local solver converges (the warm start is kept)
  ImpactStep step(const Eigen::Ref<const Vector>& u_c, const Eigen::Ref<const Vector>& v_c,
                  const Eigen::Ref<const Vector>& vfree_c);

  /// @brief The same step from the condensed right-hand side, so that the whole time step
  /// is one back-substitution with a factor that splits its solves (MUMPS condensation and
  /// expansion).
  ///
  /// b_c = b̃_c = b_c − Ŵ_ci Ŵ_ii⁻¹ b_i is the condensation onto the contact DOFs of the
  /// step's right-hand side b = h [f − C v⁻ − K (u⁻ + hθ v⁻)] (forward elimination only).
  /// The free velocity is v_free,c = v_c + F̂ b̃_c (a held DOF has an identity row in Ŵ:
  /// v_free,c = v_c + b̃_c there), then step() as above; the result also holds
  /// velocity_change_c = F̂ (b̃_c + r_c) (held DOFs: b̃_c), whose expansion is the whole
  /// Δv = Ŵ⁻¹ (b + Bᵀ P): r = Bᵀ P lives on the contact DOFs and leaves the interior's
  /// forward elimination unchanged.
  /// @throws std::invalid_argument on wrong sizes or non-finite values
  /// @throws ConvergenceError if no local solver converges (the warm start is kept)
  ImpactStep step_condensed(const Eigen::Ref<const Vector>& u_c,
                            const Eigen::Ref<const Vector>& v_c,
                            const Eigen::Ref<const Vector>& b_c);

  /// @brief New pairs on the same contact nodes (re-pairing between steps): B, x0 and
  /// W_eff rebuilt from the stored F̂, no factorization. Pair k keeps its last impulse and
  /// state as the next step's warm start (pair k is slave node k's before and after).
  /// @throws std::invalid_argument on bad pairs or mu; the object is then unchanged
  /// A crushable interface gives the new pairs' force caps in `cap` (set_crushing); the
  /// crush depth is the slave node's and carries over.
  void set_pairs(std::vector<ContactPair> pairs, Vector mu, Vector cap = Vector());

  /// @brief Caps c_k > 0 of the pairs' normal contact forces [N; N/m in 2D] (+∞: none;
  /// empty: no crushing), kept until the next set_pairs. The impulse of a step is capped
  /// at c_k h. Where the cap binds the pair's surface crushes: its slave node's crush depth
  /// δ (zero at first, carried across re-pairing) grows by the overlap the crushed surface
  /// would have at the end of the step, −(g_n + δ + h U_n^θ), at most the step's approach
  /// h max(0, −U_n^θ); the gap of the index set and of the next steps is g_n + δ
  /// (docs/crushing.md).
  /// @throws std::invalid_argument on a wrong size or a cap ≤ 0 or NaN
  void set_crushing(Vector cap);

  /// @brief δ of every contact node [m].
  const Vector& node_crush_depth() const { return crush_node_; }
  const Vector& cap() const { return cap_; } ///< per pair (empty: no crushing)

  /// @brief New time-step size: F̂ of the new Ŵ, W_eff rebuilt; pairs kept.
  /// @throws std::invalid_argument on a wrong size, non-finite entries or dt_s ≤ 0
  void set_flexibility(Matrix Fhat, double dt_s);

  /// @brief The factor path's new time-step size: the new Ŵ's block flexibility; the held
  /// columns are dropped.
  /// @throws std::invalid_argument on dt_s ≤ 0, std::logic_error on the dense path
  void set_block_flexibility(BlockOperator Fhat, double dt_s);

  /// @brief True when F̂ is applied through a factor rather than held (the factor path).
  bool factor_path() const { return static_cast<bool>(block_); }
  /// @brief Pairs whose columns of W_eff are held (factor path).
  int cached_pairs() const { return static_cast<int>(columns_.order.size()); }
  /// @brief Block products and the columns they solved for, since construction (factor path).
  long block_products() const { return block_products_; }
  long block_columns() const { return block_columns_; }

  const Eigen::SparseMatrix<double>& B() const { return B_; } ///< m·d × n_c
  const Vector& x0() const { return x0_; }                   ///< initial gap, m·d
  const Matrix& W() const { return W_; }          ///< W_eff, m·d × m·d (dense path only)
  const Matrix& flexibility() const { return F_; } ///< F̂, constrained zeroed (dense path only)
  /// @brief Dense path: how many diagonal blocks F̂'s products go by (1: F̂ whole).
  int diagonal_blocks() const { return blocks_.empty() ? 0 : static_cast<int>(blocks_.size()) - 1; }
  /// @brief Dense path: how many of those blocks are symmetric (to 1e-12 of their largest
  /// entry), whose whole products read their lower triangle only.
  int symmetric_blocks() const
  { return static_cast<int>(std::count(symmetric_.begin(), symmetric_.end(), true)); }
  const std::vector<ContactPair>& contact_pairs() const { return pairs_; }
  const Vector& mu() const { return mu_; }
  double restitution() const { return e_; }
  double dt() const { return dt_; }
  double theta() const { return theta_; }
  int dim() const { return dim_; }
  int pairs() const { return static_cast<int>(pairs_.size()); }
  int contact_dofs() const { return static_cast<int>(X_.rows()) * dim_; }

private:
  /// @brief Throws std::invalid_argument naming a bad dim, coordinates, e, dt or θ.
  void check_scheme() const;
  /// @brief B, x0 and a state at rest (no impulse, all pairs open, nothing crushed).
  void start();
  /// @brief Impulses of the pairs in I from the local problem x = W_II P + q_I.
  void solve_active(ImpactStep& r, const Vector& Ufree);
  /// @brief W P, reading only the index set's columns of W when they are few.
  Vector impulse_effect(const ImpactStep& r) const;
  /// @brief Reaction, totals and the energy terms of a solved step.
  void finish(ImpactStep& r) const;
  /// @brief Crush depths and crushing work of a solved step (pairs at their cap).
  void crush(ImpactStep& r);
  /// @brief δ of pair k's slave node (0 without crushing).
  double crush_of(int k) const;
  /// @brief Factor path: W_eff's columns of `pairs` held (fetched if missing).
  void fetch(const std::vector<int>& pairs);
  /// @brief Dense path: the contact DOFs B reads and F̂'s rows there (step_condensed).
  void keep_read_rows();
  /// @brief Dense path: F̂'s diagonal blocks (blocks_), where no entry couples them, and
  /// which of them are symmetric (symmetric_).
  void find_blocks();
  /// @brief Dense path: F̂ x by F̂'s diagonal blocks, a block whose part of x is zero
  /// skipped, and one where x is mostly zero (a contact reaction) read by its nonzero
  /// columns only.
  Vector product(const Vector& x) const;

  int dim_;
  Matrix F_;
  Matrix X_;
  std::vector<ContactPair> pairs_;
  Vector mu_;
  double e_, dt_, theta_;
  std::vector<bool> constrained_;
  SolverOptions options_;
  Eigen::SparseMatrix<double> B_;
  Vector x0_;
  Matrix W_;
  /// Dense path: the contact DOFs with a column in B (sorted), and F̂'s rows there, kept
  /// when they are at most half of F̂ (otherwise empty and F̂ b̃_c is formed whole).
  std::vector<Eigen::Index> read_;
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> F_read_;
  /// Dense path: the first DOF of each of F̂'s diagonal blocks and F̂'s size last. Bodies
  /// condensed apart (a log and a dam) give one block each, and a product by the blocks
  /// reads their entries only (half of F̂'s for two equal bodies).
  std::vector<Eigen::Index> blocks_;
  /// Dense path: per block, whether it is symmetric. F̂ is the inverse of a symmetric
  /// iteration matrix, but only to round-off, and a caller may hand any F̂: a block that is
  /// not symmetric is multiplied whole.
  std::vector<bool> symmetric_;
  Vector cap_;                     ///< force caps per pair, empty: no crushing
  Vector crush_node_;              ///< crush depth δ per contact node [m]
  Vector last_P_;                  ///< warm start
  BlockOperator block_;            ///< factor path: Y = F̂ R (empty: the dense path)
  double max_bytes_ = 0.0;
  PairColumns columns_;            ///< factor path: W_eff's held columns
  long block_products_ = 0, block_columns_ = 0;
  std::vector<PairState> last_states_;
};
} // namespace flexcontact
