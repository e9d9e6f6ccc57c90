// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file pairs.hpp
/// @brief Contact pairs, local frames, the gap operator B, and W = B F* Bᵀ.
///
/// Contact DOFs are numbered node-major: contact node a owns columns a·d + c, c < d, of B and
/// rows/columns of F*. A pair joins slave node s to a master point Σ_j w_j X_j (node–node: one
/// master node, weight 1). Its local frame T has rows (n, t) in 2D, (n, t1, t2) in 3D, n the
/// master's outward normal (towards the slave).

#include "flexcontact/problem.hpp"
#include <Eigen/Sparse>

namespace flexcontact
{
/// @brief One slave node against a master point.
struct ContactPair
{
  int slave = -1;                 ///< contact node index of the slave
  std::vector<int> masters;       ///< contact node indices of the master point's nodes
  std::vector<double> weights;    ///< shape weights w_j of the master point (sum 1)
  Matrix frame;                   ///< d×d rotation, rows n, t (, t2)
  /// Normal distance of the master surface from the master point [m], subtracted from the
  /// normal gap: a rigid circle or sphere pairs its slaves with its centre and offset R.
  double offset = 0.0;
};

/// @brief Local frame from a unit outward normal: rows (n, t) with t = (−n_y, n_x) in 2D;
/// in 3D (n, t1, t2) with t1 the normalised projection of the global axis least aligned
/// with n (continuous away from the switching cones) and t2 = n × t1.
/// @throws std::invalid_argument if n is not finite or has zero length
Matrix frame_from_normal(const Eigen::Ref<const Vector>& n);

/// @brief B (m·d × n_nodes·d): row block k is T_k (e_s − Σ_j w_j e_j).
/// @throws std::invalid_argument on out-of-range nodes, frames of the wrong size
Eigen::SparseMatrix<double> gap_operator(int dim, int n_nodes,
                                         const std::vector<ContactPair>& pairs);

/// @brief Initial gap x0 (m·d): x0_k = T_k (X_s − Σ_j w_j X_j) − offset_k e_n; X holds node
/// coordinates row by row (n_nodes × d).
Vector initial_gap(const std::vector<ContactPair>& pairs, const Eigen::Ref<const Matrix>& X);

/// @brief W = B F* Bᵀ, symmetrised. F* is the flexibility (K⁻¹)_cc on the contact DOFs.
Matrix delassus(const Eigen::SparseMatrix<double>& B, const Eigen::Ref<const Matrix>& Fstar);
} // namespace flexcontact
