// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file dense_blocks.hpp
/// @brief A block-diagonal F̂ whose dense blocks are held once and shared by several
/// contact objects (docs/architecture.md §7, "Blocks shared between runs").
///
/// Bodies condensed separately couple only through contact, so F̂ = diag(F̂_1, …, F̂_B). A
/// sweep meets the same blocks again and again: the dam face's block in every scenario, a
/// log's block in every placement of that log. `DenseBlock` holds one block; `SharedBlocks`
/// is the F̂ of one run, made of such blocks, each optionally turned from its body's own
/// frame into the run's by a d × d rotation Q of every node, F̂_b = Q F_b Qᵀ: a log placed
/// at some pitch and yaw needs no rotated copy of its block. Applied to a few columns (W_eff's
/// columns of the pairs that close, through the kernel's factor path), a product reads only
/// the columns of F_b that the right-hand side's nonzero rows name.

#include "flexcontact/problem.hpp"

#include <memory>
#include <vector>

namespace flexcontact
{
/// @brief One dense flexibility block F (n × n), and whether it is symmetric (then a product
/// with one whole column reads its lower triangle only: half the bytes). The block either
/// owns F or reads F where its caller keeps it (a model's array): a block made once per
/// model then costs no second copy of an n² array that is hundreds of megabytes.
class DenseBlock
{
public:
  /// @throws std::invalid_argument if F is not square or not finite
  explicit DenseBlock(Matrix F);

  /// @brief A block read in place from n × n column-major values at `data`, which `keeper`
  /// keeps alive and unchanged for the block's lifetime.
  /// @throws std::invalid_argument if the values are not finite
  DenseBlock(const double* data, Eigen::Index n, std::shared_ptr<const void> keeper);

  // F_ maps own_ or the keeper's values: a copy would map the original's.
  DenseBlock(const DenseBlock&) = delete;
  DenseBlock& operator=(const DenseBlock&) = delete;

  Eigen::Index rows() const { return F_.rows(); }
  bool symmetric() const { return symmetric_; }
  const Eigen::Map<const Matrix>& matrix() const { return F_; }

  /// @brief F X. A column of X with fewer than n/2 nonzero entries is formed from F's
  /// columns at those entries (contiguous, F is column-major); the other columns together,
  /// in one pass over F.
  /// @throws std::invalid_argument if X has not n rows
  Matrix product(const Eigen::Ref<const Matrix>& X) const;

private:
  void check();

  Matrix own_;
  std::shared_ptr<const void> keeper_;
  Eigen::Map<const Matrix> F_;
  bool symmetric_ = false;
};

/// @brief F̂ = diag(Q_1 F_1 Q_1ᵀ, …) over shared blocks, as a block operator Y = F̂ R.
class SharedBlocks
{
public:
  /// @param dim spatial dimension d (2 or 3)
  /// @param blocks the blocks in the order of the contact DOFs (node-major)
  /// @param rotations per block: a d × d rotation of its nodes, or an empty matrix (none)
  /// @throws std::invalid_argument on a missing block, a block whose size is not a multiple
  /// of d, or a rotation that is not d × d and orthogonal to 1e-10
  SharedBlocks(int dim, std::vector<std::shared_ptr<const DenseBlock>> blocks,
               std::vector<Matrix> rotations);

  Eigen::Index rows() const { return n_; }

  /// @brief F̂ R (R with rows() rows).
  Matrix apply(const Matrix& R) const;

private:
  int dim_;
  std::vector<std::shared_ptr<const DenseBlock>> blocks_;
  std::vector<Matrix> rotations_;
  std::vector<Eigen::Index> offsets_;
  Eigen::Index n_ = 0;
};

} // namespace flexcontact
