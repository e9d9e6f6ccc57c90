// Copyright flexcontact developers. MIT licence.

/// @file dense_blocks.cpp
/// @brief Dense flexibility blocks shared between runs, and the block-diagonal F̂ of one run
/// made of them (dense_blocks.hpp).

#include "message_numbers.hpp"
#include "flexcontact/dense_blocks.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace flexcontact
{
namespace
{
const std::string who = "flexcontact: ";

bool is_symmetric(const Eigen::Ref<const Matrix>& F)
{
  const double tol = 1e-12 * F.cwiseAbs().maxCoeff();
  for (Eigen::Index j = 0; j < F.cols(); ++j)
    for (Eigen::Index i = j + 1; i < F.rows(); ++i)
      if (std::abs(F(i, j) - F(j, i)) > tol)
        return false;
  return true;
}

/// F X for a few columns, reading F once: each column of Y takes four columns of F at a
/// time. A matrix product would first pack F (as many bytes again) for a panel of only k
/// columns; k products with F read it k times. Measured at n = 4,188, k = 8 (one run on a
/// loaded machine): 55 ms, against 130 ms for k symmetric products and 139 ms for Eigen's
/// matrix product.
Matrix stream_product(const Eigen::Ref<const Matrix>& F, const Matrix& X)
{
  const Eigen::Index n = F.rows(), k = X.cols();
  Matrix Y = Matrix::Zero(n, k);
  Eigen::Index j = 0;
  for (; j + 4 <= n; j += 4)
    for (Eigen::Index c = 0; c < k; ++c)
      Y.col(c).noalias() += F.col(j) * X(j, c) + F.col(j + 1) * X(j + 1, c)
                            + F.col(j + 2) * X(j + 2, c) + F.col(j + 3) * X(j + 3, c);
  for (; j < n; ++j)
    for (Eigen::Index c = 0; c < k; ++c)
      Y.col(c).noalias() += F.col(j) * X(j, c);
  return Y;
}

/// Every node's d rows of Y, Y_node ← A Y_node (A = Q into the run's frame, Qᵀ out of it).
void turn_nodes(Matrix& Y, const Matrix& A)
{
  const Eigen::Index d = A.rows();
  for (Eigen::Index a = 0; a < Y.rows(); a += d)
    Y.middleRows(a, d) = (A * Y.middleRows(a, d)).eval();
}
} // namespace

DenseBlock::DenseBlock(Matrix F)
    : own_(std::move(F)), F_(own_.data(), own_.rows(), own_.cols())
{
  if (F_.rows() != F_.cols())
    throw std::invalid_argument(who + "DenseBlock: the block is " + std::to_string(F_.rows())
                                + "×" + std::to_string(F_.cols()) + "; it must be square");
  check();
}

DenseBlock::DenseBlock(const double* data, Eigen::Index n, std::shared_ptr<const void> keeper)
    : keeper_(std::move(keeper)), F_(data, n, n)
{
  if (n < 0 || (n > 0 && data == nullptr))
    throw std::invalid_argument(who + "DenseBlock: no values for a block of " + std::to_string(n)
                                + " rows");
  check();
}

void DenseBlock::check()
{
  if (!F_.allFinite())
    throw std::invalid_argument(who + "DenseBlock: the block is not finite");
  symmetric_ = F_.size() > 0 && is_symmetric(F_);
}

Matrix DenseBlock::product(const Eigen::Ref<const Matrix>& X) const
{
  const Eigen::Index n = F_.rows();
  if (X.rows() != n)
    throw std::invalid_argument(who + "DenseBlock: product with " + std::to_string(X.rows())
                                + " rows for a block of " + std::to_string(n));
  Matrix Y = Matrix::Zero(n, X.cols());
  std::vector<Eigen::Index> whole, nonzero;
  for (Eigen::Index j = 0; j < X.cols(); ++j)
  {
    nonzero.clear();
    for (Eigen::Index i = 0; i < n; ++i)
      if (X(i, j) != 0.0)
        nonzero.push_back(i);
    if (2 * static_cast<Eigen::Index>(nonzero.size()) >= n)
      whole.push_back(j);
    else
      for (Eigen::Index i : nonzero)
        Y.col(j).noalias() += X(i, j) * F_.col(i);
  }
  if (whole.empty())
    return Y;
  Matrix Xw(n, static_cast<Eigen::Index>(whole.size()));
  for (std::size_t k = 0; k < whole.size(); ++k)
    Xw.col(static_cast<Eigen::Index>(k)) = X.col(whole[k]);
  Matrix Yw(n, Xw.cols());
  if (Xw.cols() == 1)
  {
    // As a vector, Eigen streams F once (gemv/symv); as an n × 1 matrix it would pack F
    // for a matrix product first.
    Vector y(n);
    if (symmetric_)
      y.noalias() = F_.selfadjointView<Eigen::Lower>() * Xw.col(0);
    else
      y.noalias() = F_ * Xw.col(0);
    Yw.col(0) = y;
  }
  else
    Yw = stream_product(F_, Xw);
  for (std::size_t k = 0; k < whole.size(); ++k)
    Y.col(whole[k]) = Yw.col(static_cast<Eigen::Index>(k));
  return Y;
}

SharedBlocks::SharedBlocks(int dim, std::vector<std::shared_ptr<const DenseBlock>> blocks,
                           std::vector<Matrix> rotations)
    : dim_(dim), blocks_(std::move(blocks)), rotations_(std::move(rotations))
{
  if (dim_ != 2 && dim_ != 3)
    throw std::invalid_argument(who + "SharedBlocks: dim is " + std::to_string(dim_)
                                + "; it must be 2 or 3");
  if (rotations_.empty())
    rotations_.resize(blocks_.size());
  if (rotations_.size() != blocks_.size())
    throw std::invalid_argument(who + "SharedBlocks: " + std::to_string(rotations_.size())
                                + " rotations for " + std::to_string(blocks_.size())
                                + " blocks");
  for (std::size_t b = 0; b < blocks_.size(); ++b)
  {
    const std::string which = "SharedBlocks: block " + std::to_string(b);
    if (!blocks_[b])
      throw std::invalid_argument(who + which + " is missing");
    if (blocks_[b]->rows() % dim_ != 0)
      throw std::invalid_argument(who + which + " has " + std::to_string(blocks_[b]->rows())
                                  + " rows, not a multiple of dim " + std::to_string(dim_));
    const Matrix& Q = rotations_[b];
    if (Q.size() == 0)
      continue;
    if (Q.rows() != dim_ || Q.cols() != dim_ || !Q.allFinite())
      throw std::invalid_argument(who + which + ": its rotation must be a finite "
                                  + std::to_string(dim_) + "×" + std::to_string(dim_)
                                  + " matrix");
    const double off = (Q.transpose() * Q - Matrix::Identity(dim_, dim_)).cwiseAbs().maxCoeff();
    if (off > 1e-10)
      throw std::invalid_argument(who + which + ": its rotation is not orthogonal (|QᵀQ − I| = "
                                  + detail::num(off) + ")");
  }
  offsets_.push_back(0);
  for (const auto& b : blocks_)
    offsets_.push_back(offsets_.back() + b->rows());
  n_ = offsets_.back();
}

Matrix SharedBlocks::apply(const Matrix& R) const
{
  if (R.rows() != n_)
    throw std::invalid_argument(who + "SharedBlocks: apply to " + std::to_string(R.rows())
                                + " rows; F̂ has " + std::to_string(n_));
  Matrix Y(n_, R.cols());
  for (std::size_t b = 0; b < blocks_.size(); ++b)
  {
    const Eigen::Index a = offsets_[b], s = offsets_[b + 1] - a;
    const Matrix& Q = rotations_[b];
    if (Q.size() == 0)
    {
      Y.middleRows(a, s) = blocks_[b]->product(R.middleRows(a, s));
      continue;
    }
    // Qᵀ turns each node's rows into the body's frame: a zero node stays zero, so the
    // product still reads only the nonzero nodes' columns.
    Matrix local = R.middleRows(a, s);
    turn_nodes(local, Q.transpose());
    Matrix Yb = blocks_[b]->product(local);
    turn_nodes(Yb, Q);
    Y.middleRows(a, s) = Yb;
  }
  return Y;
}

} // namespace flexcontact
