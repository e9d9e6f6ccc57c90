// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file split_cholesky.hpp
/// @brief A small body's sparse Cholesky factor with its contact rows pivoted last, and the
/// three solves of a Schur factor (docs/architecture.md §7, "A small body's sparse split
/// factor").
///
/// P A Pᵀ = L Lᵀ with the interior rows i first (approximate minimum degree on A_ii) and the
/// contact rows c last, in their given order, so that L = [[L_ii, 0], [L_ci, L_cc]] and the
/// Schur complement is S = A_cc − A_ci A_ii⁻¹ A_ic = L_cc L_ccᵀ:
///
/// * condense(b): the forward substitution over the interior columns only; what it leaves
///   in the contact rows is b̃_c = b_c − L_ci L_ii⁻¹ b_i = b_c − A_ci A_ii⁻¹ b_i. The interior
///   part y_i = L_ii⁻¹ b_i is kept for the expansion;
/// * expand(u_c): the backward substitution over the interior columns with the contact
///   rows set to u_c: x_i = L_iiᵀ⁻¹ (y_i − L_ciᵀ u_c) = A_ii⁻¹ (b_i − A_ic u_c);
/// * solve(b): both substitutions over every column.
///
/// Each solve is two plain loops over L's entries with no per-call set-up: for a body of a
/// few thousand DOFs a sparse direct solver's fixed cost per call is several times the
/// substitutions' own (MUMPS: about 0.25 ms per call at 1,556 DOFs). The factorization is
/// simplicial (column by column, no dense kernels), so it is meant for small bodies only.

#include "flexcontact/problem.hpp"

#include <Eigen/Sparse>

#include <span>
#include <vector>

namespace flexcontact
{
class SplitCholesky
{
public:
  /// @brief Order and factor the symmetric positive definite n × n matrix A given by its
  /// rows (CSR: indptr, indices, values, every stored entry of both triangles, as PETSc's
  /// AIJ holds a symmetric matrix); `schur` are the contact rows, pivoted last in this order.
  /// @throws std::invalid_argument on sizes that do not match, an index out of range, a
  ///   contact row listed twice, or a matrix whose two triangles differ in entry count
  /// @throws std::runtime_error if A is not positive definite
  SplitCholesky(Eigen::Index n, std::span<const int> indptr, std::span<const int> indices,
                std::span<const double> values, std::vector<int> schur);

  /// @brief A factor from its parts (saved by order() and L()): no factorization.
  /// @param order row of A at each pivot (a permutation of 0..n−1), the last n_schur rows
  ///   the contact rows
  /// @param L the lower factor, column-compressed, each column's diagonal entry first
  /// @throws std::invalid_argument if the parts do not make such a factor
  SplitCholesky(std::vector<int> order, Eigen::Index n_schur, Eigen::SparseMatrix<double> L);

  Eigen::Index size() const { return static_cast<Eigen::Index>(order_.size()); }
  Eigen::Index schur_size() const { return size() - ni_; }
  Eigen::Index factor_entries() const { return L_.nonZeros(); }

  /// @brief b̃_c (contact rows in their given order); keeps L_ii⁻¹ b_i for expand().
  /// @throws std::invalid_argument if b has the wrong size
  Vector condense(const Eigen::Ref<const Vector>& b);

  /// @brief x = A⁻¹ (b + Sᵀ r) for the b of the last condense() and the contact values
  /// u_c = F*(b̃_c + r): x_c = u_c, x_i from the backward substitution. One expansion per
  /// condensation.
  /// @throws std::logic_error without a condense() since the last expansion
  /// @throws std::invalid_argument on wrong sizes
  void expand(const Eigen::Ref<const Vector>& u_c, Eigen::Ref<Vector> x);

  /// @brief x = A⁻¹ b (both substitutions; the condense/expand state is left alone).
  void solve(const Eigen::Ref<const Vector>& b, Eigen::Ref<Vector> x) const;

  /// @brief F* = S⁻¹ = L_cc⁻ᵀ L_cc⁻¹, dense, in the contact rows' order, symmetrised.
  Matrix flexibility() const;

  const std::vector<int>& order() const { return order_; }
  const Eigen::SparseMatrix<double>& L() const { return L_; }

private:
  void check_factor() const;
  void forward(Vector& y, Eigen::Index from, Eigen::Index to) const;
  void backward(Vector& y, Eigen::Index from, Eigen::Index to) const;

  std::vector<int> order_;        ///< row of A at each pivot
  Eigen::Index ni_ = 0;           ///< interior rows: pivots 0..ni_−1
  Eigen::SparseMatrix<double> L_; ///< column-compressed, diagonal first in each column
  Vector y_;                      ///< the last condensation's substitution, pivot order
  bool condensed_ = false;
};
} // namespace flexcontact
