// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file pair_columns.hpp
/// @brief Private to the kernel: W's columns of some pairs, W[:, k] = B F (Bᵀ e_k), computed
/// through a caller's block flexibility and held across steps within a memory cap. Shared
/// by the static factor path (OperatorContact) and the impact one (ImpactContact).

#include "flexcontact/operator_contact.hpp"

#include <stdexcept>
#include <string>
#include <vector>

namespace flexcontact::detail
{
/// @brief B F Bᵀ[:, pairs] (m·d × d·|pairs|) by one block product; constrained contact DOFs
/// neither loaded nor moving.
inline Matrix delassus_columns(const Eigen::SparseMatrix<double>& B,
                               const std::vector<bool>& constrained, const BlockOperator& block,
                               const std::vector<int>& pairs, int d, const std::string& who)
{
  const Eigen::SparseMatrix<double> Bt = B.transpose();
  const int m = static_cast<int>(B.rows()) / d;
  Matrix R = Matrix::Zero(B.cols(), static_cast<Eigen::Index>(pairs.size()) * d);
  for (std::size_t a = 0; a < pairs.size(); ++a)
  {
    if (pairs[a] < 0 || pairs[a] >= m)
      throw std::invalid_argument(who + "W_columns: pair " + std::to_string(pairs[a])
                                  + " out of range");
    for (int i = 0; i < d; ++i)
      for (Eigen::SparseMatrix<double>::InnerIterator it(Bt, pairs[a] * d + i); it; ++it)
        R(it.row(), static_cast<Eigen::Index>(a) * d + i) = it.value();
  }
  for (std::size_t i = 0; i < constrained.size(); ++i)
    if (constrained[i])
      R.row(static_cast<Eigen::Index>(i)).setZero();
  Matrix F = block(R);
  if (F.rows() != R.rows() || F.cols() != R.cols())
    throw std::runtime_error(who + "the block operator returned " + std::to_string(F.rows())
                             + "×" + std::to_string(F.cols()) + " for "
                             + std::to_string(R.rows()) + "×" + std::to_string(R.cols()));
  for (std::size_t i = 0; i < constrained.size(); ++i)
    if (constrained[i])
      F.row(static_cast<Eigen::Index>(i)).setZero();
  return B * F;
}

/// @brief Makes the columns of `pairs` held in c, computing the missing ones by one call of
/// `compute`; false (nothing computed) if `pairs` alone would pass max_bytes (8 bytes per
/// entry of the rows × d·pairs columns). Columns of pairs not asked for are dropped first
/// when the new ones would not fit beside them.
template <class Compute>
bool fetch_pair_columns(PairColumns& c, const std::vector<int>& pairs, double max_bytes,
                        Eigen::Index rows, int d, std::size_t total_pairs,
                        const Compute& compute)
{
  std::vector<int> missing;
  for (int k : pairs)
    if (c.slot[static_cast<std::size_t>(k)] < 0)
      missing.push_back(k);
  if (missing.empty())
    return true;
  const double per_pair = 8.0 * static_cast<double>(rows) * d;
  auto fits = [&](std::size_t count) { return per_pair * static_cast<double>(count) <= max_bytes; };
  if (!fits(pairs.size()))
    return false;
  if (!fits(c.order.size() + missing.size()))
  {
    PairColumns kept;
    kept.slot.assign(total_pairs, -1);
    kept.columns.resize(rows, static_cast<Eigen::Index>(pairs.size() - missing.size()) * d);
    for (int k : pairs)
      if (const int s = c.slot[static_cast<std::size_t>(k)]; s >= 0)
      {
        kept.slot[static_cast<std::size_t>(k)] = static_cast<int>(kept.order.size());
        kept.columns.middleCols(static_cast<Eigen::Index>(kept.order.size()) * d, d)
            = c.columns.middleCols(static_cast<Eigen::Index>(s) * d, d);
        kept.order.push_back(k);
      }
    c = std::move(kept);
  }
  const Matrix fresh = compute(missing);
  const Eigen::Index old = c.columns.cols();
  c.columns.conservativeResize(rows, old + fresh.cols());
  c.columns.rightCols(fresh.cols()) = fresh;
  for (int k : missing)
  {
    c.slot[static_cast<std::size_t>(k)] = static_cast<int>(c.order.size());
    c.order.push_back(k);
  }
  return true;
}

/// @brief W_AA from the held columns, symmetrised: each column is a separate solve, so W's
/// symmetry holds only to rounding, and the dense chain expects a symmetric W.
inline Matrix restricted_W(const PairColumns& c, const std::vector<int>& A, int d)
{
  const Eigen::Index n = static_cast<Eigen::Index>(A.size()) * d;
  Matrix WA(n, n);
  for (std::size_t b = 0; b < A.size(); ++b)
  {
    const Eigen::Index col = static_cast<Eigen::Index>(c.slot[static_cast<std::size_t>(A[b])]) * d;
    for (std::size_t a = 0; a < A.size(); ++a)
      WA.block(static_cast<Eigen::Index>(a) * d, static_cast<Eigen::Index>(b) * d, d, d)
          = c.columns.block(static_cast<Eigen::Index>(A[a]) * d, col, d, d);
  }
  return 0.5 * (WA + WA.transpose());
}

/// @brief u = W λ + q on every pair, λ nonzero only on the set A (its columns are held).
inline Vector full_u(const PairColumns& c, const std::vector<int>& A, const Vector& lamA,
                     const Eigen::Ref<const Vector>& q, int d)
{
  Vector u = q;
  for (std::size_t b = 0; b < A.size(); ++b)
    u.noalias() += c.columns.middleCols(
                       static_cast<Eigen::Index>(c.slot[static_cast<std::size_t>(A[b])]) * d, d)
                   * lamA.segment(static_cast<Eigen::Index>(b) * d, d);
  return u;
}
} // namespace flexcontact::detail
