// Copyright flexcontact developers. MIT licence.

/// @file block_flexibility.cpp
/// @brief F* by body, as Cholesky factors or a dense matrix, and W = B F* Bᵀ by the cheaper
/// route per body (block_flexibility.hpp).

#include "flexcontact/block_flexibility.hpp"
#include "constrained.hpp"
#include "flexcontact/pairs.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

extern "C"
{
void dpotri_(const char* uplo, const int* n, double* a, const int* lda, int* info);
}

namespace flexcontact
{
namespace
{
const std::string who = "flexcontact: BlockFlexibility: ";
} // namespace

BlockFlexibility::BlockFlexibility(Matrix F) : n_(F.rows()), dense_(std::move(F))
{
  if (dense_.rows() != dense_.cols())
    throw std::invalid_argument(who + "F* is " + std::to_string(dense_.rows()) + "x"
                                + std::to_string(dense_.cols()) + "; it must be square");
}

BlockFlexibility::BlockFlexibility(Eigen::Index n, std::vector<std::vector<int>> blocks,
                                   std::vector<Matrix> L)
    : n_(n), by_block_(true), blocks_(std::move(blocks)), L_(std::move(L))
{
  if (blocks_.size() != L_.size())
    throw std::invalid_argument(who + std::to_string(blocks_.size()) + " blocks but "
                                + std::to_string(L_.size()) + " factors");
  std::vector<bool> seen(static_cast<std::size_t>(std::max<Eigen::Index>(n, 0)), false);
  for (std::size_t b = 0; b < blocks_.size(); ++b)
  {
    const auto nb = static_cast<Eigen::Index>(blocks_[b].size());
    const std::string block = "block " + std::to_string(b) + ": ";
    if (L_[b].rows() != nb or L_[b].cols() != nb)
      throw std::invalid_argument(who + block + "the factor is " + std::to_string(L_[b].rows())
                                  + "x" + std::to_string(L_[b].cols()) + " for "
                                  + std::to_string(nb) + " DOFs");
    for (int p : blocks_[b])
    {
      if (p < 0 or p >= n)
        throw std::invalid_argument(who + block + "position " + std::to_string(p)
                                    + " is outside 0.." + std::to_string(n - 1));
      if (seen[static_cast<std::size_t>(p)])
        throw std::invalid_argument(who + block + "position " + std::to_string(p)
                                    + " is in two blocks or listed twice");
      seen[static_cast<std::size_t>(p)] = true;
    }
    const Matrix& Lb = L_[b];
    if (!Lb.triangularView<Eigen::Lower>().toDenseMatrix().allFinite()
        or (nb and Lb.diagonal().minCoeff() <= 0.0))
      throw std::invalid_argument(who + block
                                  + "the Cholesky factor is not finite or has a diagonal "
                                    "entry <= 0");
  }
  inverse_.resize(blocks_.size());
}

void BlockFlexibility::set_constrained(std::vector<bool> constrained)
{
  check_constrained(constrained, n_, who);
  if (!factored())
    zero_constrained(dense_, constrained, who);
  constrained_ = std::move(constrained);
}

void BlockFlexibility::extend(Eigen::Index n)
{
  if (n < n_)
    throw std::invalid_argument(who + "extend: " + std::to_string(n) + " < "
                                + std::to_string(n_) + " rows");
  if (!factored())
  {
    Matrix F = Matrix::Zero(n, n);
    F.topLeftCorner(n_, n_) = dense_;
    dense_ = std::move(F);
  }
  if (!constrained_.empty())
    constrained_.resize(static_cast<std::size_t>(n), true);
  n_ = n;
}

std::vector<int> BlockFlexibility::block_sizes() const
{
  if (!factored())
    return {static_cast<int>(n_)};
  std::vector<int> s;
  for (const auto& b : blocks_)
    s.push_back(static_cast<int>(b.size()));
  return s;
}

Matrix BlockFlexibility::inverse_of(std::size_t b) const
{
  if (inverse_[b].size() or blocks_[b].empty())
    return inverse_[b];
  Matrix A = L_[b];
  const int nb = static_cast<int>(A.rows());
  int info = 0;
  dpotri_("L", &nb, A.data(), &nb, &info);
  if (info != 0) // the factor was checked: only a zero diagonal entry makes dpotri fail
    throw std::runtime_error(who + "block " + std::to_string(b) + ": dpotri failed (info "
                             + std::to_string(info) + ")");
  A.triangularView<Eigen::StrictlyUpper>() = A.transpose();
  return A;
}

void BlockFlexibility::invert(std::size_t b)
{
  if (inverse_[b].size() or blocks_[b].empty())
    return;
  inverse_[b] = inverse_of(b);
  L_[b] = Matrix(); // the inverse serves every later use
}

Vector BlockFlexibility::apply(const Eigen::Ref<const Vector>& v) const
{
  if (v.size() != n_)
    throw std::invalid_argument(who + "apply: " + std::to_string(v.size())
                                + " entries, expected " + std::to_string(n_));
  const auto held = [this](Eigen::Index i)
  { return !constrained_.empty() and constrained_[static_cast<std::size_t>(i)]; };
  if (!factored())
    return dense_ * v; // constrained rows and columns already zero
  Vector out = Vector::Zero(n_);
  for (std::size_t b = 0; b < blocks_.size(); ++b)
  {
    const std::vector<int>& idx = blocks_[b];
    Vector x(static_cast<Eigen::Index>(idx.size()));
    for (std::size_t k = 0; k < idx.size(); ++k)
      x[static_cast<Eigen::Index>(k)] = held(idx[k]) ? 0.0 : v[idx[k]];
    if (inverse_[b].size())
      x = (inverse_[b] * x).eval();
    else
    {
      L_[b].triangularView<Eigen::Lower>().solveInPlace(x);
      L_[b].transpose().triangularView<Eigen::Upper>().solveInPlace(x);
    }
    for (std::size_t k = 0; k < idx.size(); ++k)
      out[idx[k]] = held(idx[k]) ? 0.0 : x[static_cast<Eigen::Index>(k)];
  }
  return out;
}

Matrix BlockFlexibility::delassus(const Eigen::SparseMatrix<double>& B)
{
  if (B.cols() != n_)
    throw std::invalid_argument(who + "delassus: B has " + std::to_string(B.cols())
                                + " columns, expected n_c = " + std::to_string(n_));
  const Eigen::Index r = B.rows();
  if (!factored())
  {
    routes_ = {"dense"};
    const double nnz = static_cast<double>(B.nonZeros());
    flops_taken_ = flops_inverse_ = 2.0 * nnz * static_cast<double>(n_ + r);
    return flexcontact::delassus(B, dense_);
  }
  // Each block's part of B: the rows that touch its free DOFs, in local numbering.
  std::vector<int> block_of(static_cast<std::size_t>(n_), -1), local(static_cast<std::size_t>(n_), -1);
  for (std::size_t b = 0; b < blocks_.size(); ++b)
    for (std::size_t k = 0; k < blocks_[b].size(); ++k)
    {
      const auto p = static_cast<std::size_t>(blocks_[b][k]);
      block_of[p] = static_cast<int>(b);
      local[p] = static_cast<int>(k);
    }
  using Triplet = Eigen::Triplet<double>;
  std::vector<std::vector<Triplet>> entries(blocks_.size());
  for (Eigen::Index c = 0; c < B.outerSize(); ++c)
    for (Eigen::SparseMatrix<double>::InnerIterator it(B, c); it; ++it)
    {
      const auto p = static_cast<std::size_t>(it.col());
      const bool held = !constrained_.empty() and constrained_[p];
      if (block_of[p] >= 0 and !held and it.value() != 0.0)
        entries[static_cast<std::size_t>(block_of[p])].emplace_back(
            static_cast<int>(it.row()), local[p], it.value());
    }

  Matrix W = Matrix::Zero(r, r);
  routes_.assign(blocks_.size(), "none");
  flops_taken_ = flops_inverse_ = 0.0;
  std::vector<int> row_local(static_cast<std::size_t>(r), -1);
  for (std::size_t b = 0; b < blocks_.size(); ++b)
  {
    if (entries[b].empty())
      continue;
    std::vector<int> rows;
    for (const Triplet& t : entries[b])
      rows.push_back(t.row());
    std::sort(rows.begin(), rows.end());
    rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
    for (std::size_t i = 0; i < rows.size(); ++i)
      row_local[static_cast<std::size_t>(rows[i])] = static_cast<int>(i);
    for (Triplet& t : entries[b])
      t = Triplet(row_local[static_cast<std::size_t>(t.row())], t.col(), t.value());

    const auto rb = static_cast<Eigen::Index>(rows.size());
    const auto nb = static_cast<Eigen::Index>(blocks_[b].size());
    const double n = static_cast<double>(nb), m = static_cast<double>(rb);
    const double product = 2.0 * static_cast<double>(entries[b].size()) * (n + m);
    const double inverse = (inverse_[b].size() ? 0.0 : 2.0 / 3.0 * n * n * n) + product;
    const double triangular = n * n * m + n * m * m;
    flops_inverse_ += inverse;

    Eigen::SparseMatrix<double> Bb(rb, nb);
    Bb.setFromTriplets(entries[b].begin(), entries[b].end());
    Matrix Wb;
    if (triangular < inverse)
    {
      routes_[b] = "triangular";
      flops_taken_ += triangular;
      Matrix G = Matrix(Bb.transpose()); // n × r
      L_[b].triangularView<Eigen::Lower>().solveInPlace(G);
      Wb = Matrix::Zero(rb, rb);
      Wb.selfadjointView<Eigen::Lower>().rankUpdate(G.transpose());
      Wb.triangularView<Eigen::StrictlyUpper>() = Wb.transpose();
    }
    else
    {
      routes_[b] = "inverse";
      flops_taken_ += inverse;
      invert(b);
      Wb = flexcontact::delassus(Bb, inverse_[b]);
    }
    for (Eigen::Index j = 0; j < rb; ++j)
      for (Eigen::Index i = 0; i < rb; ++i)
        W(rows[static_cast<std::size_t>(i)], rows[static_cast<std::size_t>(j)]) += Wb(i, j);
  }
  return W;
}

Matrix BlockFlexibility::dense() const
{
  if (!factored())
    return dense_;
  Matrix F = Matrix::Zero(n_, n_);
  for (std::size_t b = 0; b < blocks_.size(); ++b)
  {
    const Matrix Fb = inverse_of(b);
    const std::vector<int>& idx = blocks_[b];
    for (std::size_t j = 0; j < idx.size(); ++j)
      for (std::size_t i = 0; i < idx.size(); ++i)
        F(idx[i], idx[j]) = Fb(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j));
  }
  zero_constrained(F, constrained_, who);
  return F;
}
} // namespace flexcontact
