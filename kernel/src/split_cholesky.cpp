// Copyright flexcontact developers. MIT licence.

#include "flexcontact/split_cholesky.hpp"

#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

using namespace flexcontact;

namespace
{
const std::string kWho = "SplitCholesky: ";

/// @brief Pivot order: the interior rows by approximate minimum degree on A_ii's pattern,
/// then the contact rows in their given order.
std::vector<int> pivot_order(Eigen::Index n, std::span<const int> indptr,
                             std::span<const int> indices, const std::vector<int>& schur)
{
  std::vector<char> is_contact(static_cast<std::size_t>(n), 0);
  for (int r : schur)
  {
    if (r < 0 || r >= n)
      throw std::invalid_argument(kWho + "contact row " + std::to_string(r)
                                  + " out of range for " + std::to_string(n) + " rows");
    if (is_contact[static_cast<std::size_t>(r)])
      throw std::invalid_argument(kWho + "contact row " + std::to_string(r) + " listed twice");
    is_contact[static_cast<std::size_t>(r)] = 1;
  }
  // interior_id: the row's place among the interior rows, −1 for a contact row.
  std::vector<int> interior_id(static_cast<std::size_t>(n), -1), interior;
  for (Eigen::Index r = 0; r < n; ++r)
    if (!is_contact[static_cast<std::size_t>(r)])
    {
      interior_id[static_cast<std::size_t>(r)] = static_cast<int>(interior.size());
      interior.push_back(static_cast<int>(r));
    }

  const auto ni = static_cast<Eigen::Index>(interior.size());
  std::vector<Eigen::Triplet<double>> pattern;
  for (Eigen::Index r = 0; r < n; ++r)
    if (const int a = interior_id[static_cast<std::size_t>(r)]; a >= 0)
      for (int k = indptr[static_cast<std::size_t>(r)]; k < indptr[static_cast<std::size_t>(r) + 1]; ++k)
        if (const int b = interior_id[static_cast<std::size_t>(indices[static_cast<std::size_t>(k)])];
            b >= 0)
          pattern.emplace_back(a, b, 1.0);
  Eigen::SparseMatrix<double> Aii(ni, ni);
  Aii.setFromTriplets(pattern.begin(), pattern.end());
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> perm;
  if (ni > 0)
    Eigen::AMDOrdering<int>()(Aii, perm);
  else
    perm.resize(0);

  // perm.indices()(k) is the interior row at pivot k (as SimplicialCholesky reads it).
  std::vector<int> order;
  order.reserve(static_cast<std::size_t>(n));
  for (Eigen::Index k = 0; k < ni; ++k)
    order.push_back(interior[static_cast<std::size_t>(perm.indices()(k))]);
  order.insert(order.end(), schur.begin(), schur.end());
  return order;
}
} // namespace

SplitCholesky::SplitCholesky(Eigen::Index n, std::span<const int> indptr,
                             std::span<const int> indices, std::span<const double> values,
                             std::vector<int> schur)
{
  if (n < 0 || indptr.size() != static_cast<std::size_t>(n) + 1 || indptr[0] != 0
      || indices.size() != values.size()
      || static_cast<std::size_t>(indptr.back()) != indices.size())
    throw std::invalid_argument(kWho + "CSR arrays do not describe an " + std::to_string(n)
                                + "-row matrix (indptr " + std::to_string(indptr.size())
                                + " entries, indices " + std::to_string(indices.size())
                                + ", values " + std::to_string(values.size()) + ")");
  long lower = 0, upper = 0;
  for (Eigen::Index r = 0; r < n; ++r)
    for (int k = indptr[static_cast<std::size_t>(r)]; k < indptr[static_cast<std::size_t>(r) + 1]; ++k)
    {
      const int c = indices[static_cast<std::size_t>(k)];
      if (c < 0 || c >= n)
        throw std::invalid_argument(kWho + "column " + std::to_string(c) + " out of range in row "
                                    + std::to_string(r));
      lower += (c < r);
      upper += (c > r);
    }
  // Only one triangle stored would silently drop the other: A must be given whole.
  if (lower != upper)
    throw std::invalid_argument(kWho + "the matrix stores " + std::to_string(lower)
                                + " entries below its diagonal and " + std::to_string(upper)
                                + " above: give every entry of the symmetric matrix");

  order_ = pivot_order(n, indptr, indices, schur);
  ni_ = n - static_cast<Eigen::Index>(schur.size());
  std::vector<int> pivot_of(static_cast<std::size_t>(n));
  for (std::size_t k = 0; k < order_.size(); ++k)
    pivot_of[static_cast<std::size_t>(order_[k])] = static_cast<int>(k);

  std::vector<Eigen::Triplet<double>> lower_entries;
  lower_entries.reserve(static_cast<std::size_t>(n + lower));
  for (Eigen::Index r = 0; r < n; ++r)
    for (int k = indptr[static_cast<std::size_t>(r)]; k < indptr[static_cast<std::size_t>(r) + 1]; ++k)
    {
      const int c = indices[static_cast<std::size_t>(k)];
      if (c > r)
        continue; // its twin below the diagonal is taken
      const int pr = pivot_of[static_cast<std::size_t>(r)], pc = pivot_of[static_cast<std::size_t>(c)];
      lower_entries.emplace_back(std::max(pr, pc), std::min(pr, pc),
                                 values[static_cast<std::size_t>(k)]);
    }
  Eigen::SparseMatrix<double> PAP(n, n);
  PAP.setFromTriplets(lower_entries.begin(), lower_entries.end());

  Eigen::SimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::NaturalOrdering<int>> llt;
  llt.compute(PAP);
  if (llt.info() != Eigen::Success)
    throw std::runtime_error(kWho + "the matrix (" + std::to_string(n)
                             + " rows) is not positive definite");
  L_ = llt.matrixL();
  L_.makeCompressed();
  check_factor();
  y_ = Vector::Zero(n);
}

SplitCholesky::SplitCholesky(std::vector<int> order, Eigen::Index n_schur,
                             Eigen::SparseMatrix<double> L)
    : order_(std::move(order)), L_(std::move(L))
{
  const auto n = static_cast<Eigen::Index>(order_.size());
  if (n_schur < 0 || n_schur > n || L_.rows() != n || L_.cols() != n)
    throw std::invalid_argument(kWho + "a factor of " + std::to_string(L_.rows()) + "×"
                                + std::to_string(L_.cols()) + " for " + std::to_string(n)
                                + " pivots and " + std::to_string(n_schur) + " contact rows");
  std::vector<char> seen(static_cast<std::size_t>(n), 0);
  for (int r : order_)
  {
    if (r < 0 || r >= n || seen[static_cast<std::size_t>(r)])
      throw std::invalid_argument(kWho + "the pivot order is not a permutation of 0.."
                                  + std::to_string(n - 1));
    seen[static_cast<std::size_t>(r)] = 1;
  }
  ni_ = n - n_schur;
  L_.makeCompressed();
  check_factor();
  y_ = Vector::Zero(n);
}

void SplitCholesky::check_factor() const
{
  const int* p = L_.outerIndexPtr();
  const int* r = L_.innerIndexPtr();
  const double* v = L_.valuePtr();
  for (Eigen::Index j = 0; j < L_.cols(); ++j)
  {
    if (p[j] >= p[j + 1] || r[p[j]] != j || !(v[p[j]] > 0.0))
      throw std::invalid_argument(kWho + "column " + std::to_string(j)
                                  + " of L does not start with a positive diagonal entry");
    for (int k = p[j] + 1; k < p[j + 1]; ++k)
      if (r[k] <= j || !std::isfinite(v[k]))
        throw std::invalid_argument(kWho + "column " + std::to_string(j)
                                    + " of L has an entry above the diagonal or not finite");
  }
}

void SplitCholesky::forward(Vector& y, Eigen::Index from, Eigen::Index to) const
{
  const int* p = L_.outerIndexPtr();
  const int* r = L_.innerIndexPtr();
  const double* v = L_.valuePtr();
  for (Eigen::Index j = from; j < to; ++j)
  {
    const double yj = (y[j] /= v[p[j]]);
    for (int k = p[j] + 1; k < p[j + 1]; ++k)
      y[r[k]] -= v[k] * yj;
  }
}

void SplitCholesky::backward(Vector& y, Eigen::Index from, Eigen::Index to) const
{
  const int* p = L_.outerIndexPtr();
  const int* r = L_.innerIndexPtr();
  const double* v = L_.valuePtr();
  for (Eigen::Index j = to - 1; j >= from; --j)
  {
    double s = y[j];
    for (int k = p[j] + 1; k < p[j + 1]; ++k)
      s -= v[k] * y[r[k]];
    y[j] = s / v[p[j]];
  }
}

Vector SplitCholesky::condense(const Eigen::Ref<const Vector>& b)
{
  if (b.size() != size())
    throw std::invalid_argument(kWho + "condense: b has " + std::to_string(b.size())
                                + " entries for " + std::to_string(size()) + " rows");
  for (Eigen::Index k = 0; k < size(); ++k)
    y_[k] = b[order_[static_cast<std::size_t>(k)]];
  forward(y_, 0, ni_);
  condensed_ = true;
  return y_.tail(schur_size());
}

void SplitCholesky::expand(const Eigen::Ref<const Vector>& u_c, Eigen::Ref<Vector> x)
{
  if (!condensed_)
    throw std::logic_error(kWho + "expand without a condense since the last expansion");
  if (u_c.size() != schur_size() || x.size() != size())
    throw std::invalid_argument(kWho + "expand: u_c has " + std::to_string(u_c.size())
                                + " entries for " + std::to_string(schur_size())
                                + " contact rows, x " + std::to_string(x.size()) + " for "
                                + std::to_string(size()));
  y_.tail(schur_size()) = u_c;
  backward(y_, 0, ni_);
  for (Eigen::Index k = 0; k < size(); ++k)
    x[order_[static_cast<std::size_t>(k)]] = y_[k];
  condensed_ = false;
}

void SplitCholesky::solve(const Eigen::Ref<const Vector>& b, Eigen::Ref<Vector> x) const
{
  if (b.size() != size() || x.size() != size())
    throw std::invalid_argument(kWho + "solve: b has " + std::to_string(b.size()) + " and x "
                                + std::to_string(x.size()) + " entries for "
                                + std::to_string(size()) + " rows");
  Vector y(size());
  for (Eigen::Index k = 0; k < size(); ++k)
    y[k] = b[order_[static_cast<std::size_t>(k)]];
  forward(y, 0, size());
  backward(y, 0, size());
  for (Eigen::Index k = 0; k < size(); ++k)
    x[order_[static_cast<std::size_t>(k)]] = y[k];
}

Matrix SplitCholesky::flexibility() const
{
  const Eigen::Index nc = schur_size();
  const Matrix Lcc = Eigen::SparseMatrix<double>(L_.block(ni_, ni_, nc, nc)).toDense();
  const Matrix Linv = Lcc.triangularView<Eigen::Lower>().solve(Matrix::Identity(nc, nc));
  const Matrix F = Linv.transpose() * Linv;
  return 0.5 * (F + F.transpose());
}
