// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file condensed.hpp
/// @brief The condensed contact problem x = W λ + q as one object (docs/architecture.md §1, §2).
///
/// It owns the gap operator B, the initial gap x0, W = B F* Bᵀ and the incremental driver, so
/// that one increment is one call: the contact-DOF values of u_p = K⁻¹ p go in; λ, the gap,
/// the states, the contact reaction r_c = Bᵀ λ and the totals come out. Contact DOFs are
/// node-major (contact node a owns DOFs a·d + c), as in pairs.hpp.

#include "flexcontact/block_flexibility.hpp"
#include "flexcontact/increment.hpp"
#include "flexcontact/pairs.hpp"
#include "flexcontact/problem.hpp"

#include <Eigen/Sparse>
#include <string>
#include <vector>

namespace flexcontact
{
/// @brief What one increment of the condensed problem produced. Vectors are pair by pair,
/// normal first (as λ); "global" means the mesh's x, y (, z) axes.
struct CondensedStep
{
  Vector lambda;                  ///< m·d contact forces in the local frames
  Vector gap;                     ///< m·d total gap x = W λ + q
  Vector slip;                    ///< m·(d−1) tangential slip of this increment
  std::vector<PairState> states;  ///< per pair
  SolveReport report;             ///< what the local solver did
  Vector reaction;                ///< n_c, r_c = Bᵀ λ; zero on constrained contact DOFs
  /// n_c, u_p,c + F* r_c: the contact values of K⁻¹ (p + Bᵀ λ) (K⁺ with rigid modes: R_c α
  /// not included), from which a solver that split K⁻¹ p expands the full displacement
  Vector solution_c;
  Vector local_q;                 ///< q' of the local problem u = W λ + q' that was solved
  double normal_force = 0.0;      ///< Σ_k λ_n,k
  Vector tangential_force;        ///< d, Σ_k T_kᵀ (0, λ_t,k): the total friction force
  double max_penetration = 0.0;   ///< max(0, −min_k x_n,k)
  Matrix pair_tangential;         ///< m × d, T_kᵀ (0, λ_t,k) per pair
  Vector crush_depth;             ///< m crush depths δ after the increment (empty: no cap)
  double crush_work = 0.0;        ///< Σ_k λ_n,k Δδ_k: energy the crushing dissipated
  Vector alpha;                   ///< k rigid-mode amplitudes (bodies held only by contact)
  Matrix undetermined;            ///< k × r directions of α no contact resists (α = 0 there)
};

/// @brief Pairs, B, x0, W = B F* Bᵀ and the incremental driver of one contact problem.
///
/// F* = (K⁻¹)_cc is the flexibility on the n_c contact DOFs. A contact DOF held by a
/// Dirichlet condition does not move under contact forces: its rows and columns of F* are
/// zeroed (K's identity row would otherwise give it a flexibility of 1) and its entry of the
/// reaction r_c is zero, the constraint taking that force.
class CondensedContact
{
public:
  /// @param dim 2 or 3
  /// @param Fstar n_c × n_c flexibility, n_c = n_nodes·dim
  /// @param X n_nodes × dim coordinates of the contact nodes
  /// @param pairs slave, masters, weights and frame of each pair (indices are contact nodes)
  /// @param mu friction coefficient per pair
  /// @param constrained n_c flags of Dirichlet-held contact DOFs, or empty for none
  /// @throws std::invalid_argument naming the argument whose size or value is wrong
  CondensedContact(int dim, Matrix Fstar, Matrix X, std::vector<ContactPair> pairs, Vector mu,
                   std::vector<bool> constrained = {}, SolverOptions options = {});

  /// @brief As above, with F* held by body as Cholesky factors (block_flexibility.hpp): W is
  /// formed per body by the cheaper of the inverse and the triangular route
  /// (delassus_routes()).
  CondensedContact(int dim, BlockFlexibility Fstar, Matrix X, std::vector<ContactPair> pairs,
                   Vector mu, std::vector<bool> constrained = {}, SolverOptions options = {});

  /// @brief Solve one increment from the contact-DOF values of u_p = K⁻¹ p (total load).
  /// @throws std::invalid_argument if up_c has the wrong size or is not finite
  /// @throws ConvergenceError if a pair with no normal flexibility is pushed into
  /// penetration (no contact force can open it), or if no solver converges; the history is
  /// then unchanged
  CondensedStep step(const Eigen::Ref<const Vector>& up_c);

  /// @brief One increment with bodies held only by contact (set_rigid_modes): up_c are the
  /// contact-DOF values of K⁺ p (K⁺ a generalized inverse), e = −Rᵀ p the loads along the
  /// rigid modes; the gap is W λ + q + G α with G = B R_c, and Gᵀ λ = e.
  /// @throws as step(up_c); std::invalid_argument if e's size is not the mode count
  CondensedStep step(const Eigen::Ref<const Vector>& up_c, const Eigen::Ref<const Vector>& e);

  /// @brief One increment from the condensed load b̃_c = p_c − K_ci K_ii⁻¹ p_i on the contact
  /// DOFs (a sparse solver's condensation of p), u_p,c = F* b̃_c computed here: the same as
  /// step(F* b̃_c, e). A constrained contact DOF's entry is its prescribed value, taken as is
  /// (its row of K is the identity, as assembled with Dirichlet conditions; a rigid target's
  /// virtual DOF likewise).
  /// @throws as step(up_c, e); std::invalid_argument if b_c has the wrong size
  CondensedStep step_condensed(const Eigen::Ref<const Vector>& b_c,
                               const Eigen::Ref<const Vector>& e);

  /// @brief Rigid modes R_c (n_c × k: the values at the contact DOFs of the free rigid modes
  /// of the bodies held only by contact); G = B R_c is kept up to date with the pairs.
  /// k = 0 removes them. The rigid-mode amplitude restarts at zero.
  /// @throws std::invalid_argument on a wrong row count or non-finite entries
  void set_rigid_modes(Matrix Rc);

  const Matrix& rigid_modes() const { return R_; }            ///< R_c, n_c × k
  const Matrix& border() const { return solver_.border(); }  ///< G = B R_c

  /// @brief Replace F* (e.g. K_eff⁻¹ for another time step) and rebuild W. Pairs and history
  /// (gap, λ, states) are kept: the next increment starts from them.
  /// @throws std::invalid_argument on a wrong size or non-finite entries
  void set_flexibility(Matrix Fstar);

  /// @brief Replace the pairs (re-pairing as bodies slide) and rebuild B, x0, W from the
  /// stored F*. Slip is measured from the new pairs' gap at the contact displacement of the
  /// last increment, u_c = u_p,c + F* r_c (zero before the first one), so that re-pairing
  /// does not count as slip and the next increment's slip is the relative motion at the
  /// master point where the slave node is now (its convected master coordinate). A slave
  /// node that had a pair before keeps its λ (the same force in global axes, expressed in
  /// the new frame) and state as the warm start of the next increment; a new slave node
  /// starts open with λ = 0.
  /// A crushable interface gives the new pairs' caps in `cap` (set_crushing); the crush
  /// depth is the slave node's and carries over.
  /// @throws std::invalid_argument as the constructor
  void set_pairs(std::vector<ContactPair> pairs, Vector mu, Vector cap = Vector());

  /// @brief Caps c_k > 0 of the pairs' normal forces [N; N/m in 2D] (+∞: none; empty: no
  /// crushing), kept until the next set_pairs. The crush depth δ of each slave node starts
  /// at zero and is carried by the node across re-pairing (docs/crushing.md).
  /// @throws std::invalid_argument on a wrong size or a cap ≤ 0 or NaN
  void set_crushing(Vector cap);

  /// @brief δ of every contact node [m] (zero where it is no pair's slave or never crushed).
  const Vector& node_crush_depth() const { return crush_node_; }

  /// @brief q' = q with the last increment's tangential gap removed, as
  /// IncrementalSolver::local_q: the local problem the next step(up_c) solves for this q.
  Vector local_q(const Eigen::Ref<const Vector>& q) const { return solver_.local_q(q); }

  /// @brief q = B up_c + x0 of the last step() call, also when it failed (empty before).
  const Vector& last_q() const { return q_; }

  const Eigen::SparseMatrix<double>& B() const { return B_; } ///< m·d × n_c
  const Vector& x0() const { return x0_; }                   ///< initial gap, m·d
  const Matrix& W() const { return solver_.W(); }            ///< B F* Bᵀ, m·d × m·d
  Matrix flexibility() const { return F_.dense(); }          ///< F*, constrained DOFs zeroed
  /// @brief Per body, how the last W was formed: "inverse", "triangular", "none" (no pair
  /// touches it) or "dense" (F* given dense).
  const std::vector<std::string>& delassus_routes() const { return F_.routes(); }
  const BlockFlexibility& block_flexibility() const { return F_; }
  const std::vector<ContactPair>& contact_pairs() const { return pairs_; }
  const Vector& mu() const { return mu_; }
  const IncrementalSolver& solver() const { return solver_; }
  int dim() const { return dim_; }
  int pairs() const { return static_cast<int>(pairs_.size()); }
  int contact_dofs() const { return static_cast<int>(F_.rows()); } ///< n_c

private:
  /// @brief Message naming held pairs pushed into penetration by q, or empty.
  std::string held_and_penetrating(const Vector& q) const;

  int dim_;
  BlockFlexibility F_;
  Matrix X_;
  std::vector<ContactPair> pairs_;
  Vector mu_;
  std::vector<bool> constrained_;
  SolverOptions options_;
  Eigen::SparseMatrix<double> B_;
  Vector x0_;
  IncrementalSolver solver_;
  Vector q_;          ///< q of the last step() call
  Vector u_c_;        ///< contact displacement of the last increment, u_p,c + F* r_c + R_c α
  Matrix R_;          ///< rigid modes at the contact DOFs, n_c × k
  Vector cap_;        ///< per pair, empty: no crushing
  Vector crush_node_; ///< δ per contact node, the slave's material depth
};
} // namespace flexcontact
