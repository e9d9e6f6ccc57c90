// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file block_flexibility.hpp
/// @brief The flexibility F* held by body: each body's block as the Cholesky factor of its
/// condensed stiffness S_b = L_b L_bᵀ, so that W = B F* Bᵀ is formed by whichever of two
/// routes costs fewer flops (docs/architecture.md §7):
///
/// * inverse:    F*_b = S_b⁻¹ (LAPACK dpotri, ⅔ n³), then B_b F*_b B_bᵀ on the sparse B_b;
/// * triangular: G = L_b⁻¹ B_bᵀ (n² r), then W_b = Gᵀ G (n r²),
///
/// with n the block's contact DOFs and r the rows of B that touch them. The triangular route
/// wins when r/n < 0.457 (r/n + (r/n)² < ⅔): a large candidate zone on a body that few pairs
/// touch. A block inverted once keeps its inverse (W is then rebuilt from it on re-pairing
/// at no further cubic cost). Everything else needs F* only as a product F* v, made from the
/// inverse where it exists and by two triangular solves otherwise.

#include "flexcontact/problem.hpp"

#include <Eigen/Sparse>

#include <string>
#include <vector>

namespace flexcontact
{
class BlockFlexibility
{
public:
  /// @brief F* given as a dense n × n matrix (one block, its inverse known).
  explicit BlockFlexibility(Matrix F = Matrix());

  /// @brief F* from the lower Cholesky factors `L[b]` of the blocks S_b on the contact DOFs
  /// `blocks[b]` (positions in 0..n−1, disjoint); a DOF in no block has zero flexibility.
  /// @throws std::invalid_argument on sizes that do not match, a position out of range or
  /// listed twice, or a factor that is not finite or has a diagonal entry ≤ 0
  BlockFlexibility(Eigen::Index n, std::vector<std::vector<int>> blocks, std::vector<Matrix> L);

  /// @brief Flexibility zero on the rows and columns of the flagged contact DOFs (held by a
  /// Dirichlet condition); `constrained` is empty or has n entries.
  void set_constrained(std::vector<bool> constrained);

  /// @brief n grows to `n` (≥ rows()): the new DOFs (rigid targets' virtual ones) get none.
  void extend(Eigen::Index n);

  Eigen::Index rows() const { return n_; }
  bool factored() const { return by_block_; } ///< held by block (Cholesky factors)

  /// @brief F* v, constrained entries zero.
  Vector apply(const Eigen::Ref<const Vector>& v) const;

  /// @brief W = B F* Bᵀ, symmetrised; each block by the cheaper route (routes()).
  /// Non-const: a block inverted for it keeps its inverse.
  Matrix delassus(const Eigen::SparseMatrix<double>& B);

  /// @brief F* as a dense n × n matrix, constrained rows and columns zero (blocks not yet
  /// inverted are inverted for it, and not kept).
  Matrix dense() const;

  /// @brief The dense F* given to the first constructor (empty when held by block).
  const Matrix& given() const { return dense_; }

  /// @brief Per block, the route of the last delassus(): "inverse", "triangular" or "none"
  /// (no row of B touched it); "dense" for a dense F*.
  const std::vector<std::string>& routes() const { return routes_; }

  /// @brief Flop estimates of the last delassus(), summed over the blocks: the route taken
  /// and the inverse route for all.
  double flops_taken() const { return flops_taken_; }
  double flops_inverse() const { return flops_inverse_; }

  /// @brief The block sizes (n for a dense F*).
  std::vector<int> block_sizes() const;

private:
  void invert(std::size_t b);
  Matrix inverse_of(std::size_t b) const; ///< F*_b, formed if not kept

  Eigen::Index n_ = 0;
  bool by_block_ = false;
  Matrix dense_;                          ///< F* when given dense (no blocks)
  std::vector<std::vector<int>> blocks_;  ///< positions of each block's DOFs
  std::vector<Matrix> L_;                 ///< lower Cholesky factor of each block
  std::vector<Matrix> inverse_;           ///< F*_b once formed (empty before)
  std::vector<bool> constrained_;
  std::vector<std::string> routes_;
  double flops_taken_ = 0.0, flops_inverse_ = 0.0;
};
} // namespace flexcontact
