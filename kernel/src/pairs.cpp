// Copyright flexcontact developers. MIT licence.

/// @file pairs.cpp
/// @brief Local frames, the gap operator B, the initial gap and W = B F* Bᵀ.

#include "flexcontact/pairs.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>
#include <stdexcept>
#include <string>

namespace flexcontact
{
namespace
{
/// @brief Throws unless pair k is well formed for dimension d and n_nodes contact nodes.
void check_pair(const ContactPair& c, int k, int dim, int n_nodes)
{
  const std::string which = "flexcontact: contact pair " + std::to_string(k);
  if (c.slave < 0 || c.slave >= n_nodes)
    throw std::invalid_argument(which + ": slave node " + std::to_string(c.slave)
                                + " is outside [0, " + std::to_string(n_nodes) + ")");
  if (c.masters.size() != c.weights.size())
    throw std::invalid_argument(which + ": " + std::to_string(c.masters.size())
                                + " master nodes but " + std::to_string(c.weights.size())
                                + " weights");
  for (std::size_t j = 0; j < c.masters.size(); ++j)
  {
    if (c.masters[j] < 0 || c.masters[j] >= n_nodes)
      throw std::invalid_argument(which + ": master node " + std::to_string(c.masters[j])
                                  + " is outside [0, " + std::to_string(n_nodes) + ")");
    if (!std::isfinite(c.weights[j]))
      throw std::invalid_argument(which + ": weight " + std::to_string(j) + " is not finite");
  }
  if (c.frame.rows() != dim || c.frame.cols() != dim)
    throw std::invalid_argument(which + ": frame is " + std::to_string(c.frame.rows()) + "x"
                                + std::to_string(c.frame.cols()) + ", expected "
                                + std::to_string(dim) + "x" + std::to_string(dim));
  if (!c.frame.allFinite())
    throw std::invalid_argument(which + ": frame is not finite");
  if (!std::isfinite(c.offset))
    throw std::invalid_argument(which + ": offset is not finite");
}
} // namespace

Matrix frame_from_normal(const Eigen::Ref<const Vector>& n_in)
{
  const auto d = n_in.size();
  if (d != 2 && d != 3)
    throw std::invalid_argument("flexcontact: frame_from_normal: normal has "
                                + std::to_string(d) + " components, expected 2 or 3");
  if (!n_in.allFinite())
    throw std::invalid_argument("flexcontact: frame_from_normal: normal is not finite");
  const double len = n_in.norm();
  if (!(len > 0.0))
    throw std::invalid_argument("flexcontact: frame_from_normal: normal has zero length");
  const Vector n = n_in / len;

  Matrix T(d, d);
  T.row(0) = n.transpose();
  if (d == 2)
  {
    T(1, 0) = -n[1];
    T(1, 1) = n[0];
    return T;
  }
  // The axis least aligned with n gives the best-conditioned projection; ties go to the
  // lowest index so that the choice is deterministic.
  int axis = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(n[i]) < std::abs(n[axis]))
      axis = i;
  Eigen::Vector3d e = Eigen::Vector3d::Zero();
  e[axis] = 1.0;
  const Eigen::Vector3d n3 = n;
  Eigen::Vector3d t1 = e - n3.dot(e) * n3;
  t1.normalize();
  const Eigen::Vector3d t2 = n3.cross(t1); // (n, t1, t2) right-handed
  T.row(1) = t1.transpose();
  T.row(2) = t2.transpose();
  return T;
}

Eigen::SparseMatrix<double> gap_operator(int dim, int n_nodes,
                                         const std::vector<ContactPair>& pairs)
{
  if (dim != 2 && dim != 3)
    throw std::invalid_argument("flexcontact: gap_operator: dim must be 2 or 3, got "
                                + std::to_string(dim));
  if (n_nodes < 0)
    throw std::invalid_argument("flexcontact: gap_operator: negative node count "
                                + std::to_string(n_nodes));
  const int m = static_cast<int>(pairs.size());
  std::vector<Eigen::Triplet<double>> entries;
  for (int k = 0; k < m; ++k)
  {
    const ContactPair& c = pairs[k];
    check_pair(c, k, dim, n_nodes);
    entries.reserve(entries.size() + dim * dim * (1 + c.masters.size()));
    for (int r = 0; r < dim; ++r)
      for (int col = 0; col < dim; ++col)
      {
        entries.emplace_back(k * dim + r, c.slave * dim + col, c.frame(r, col));
        for (std::size_t j = 0; j < c.masters.size(); ++j)
          entries.emplace_back(k * dim + r, c.masters[j] * dim + col,
                               -c.weights[j] * c.frame(r, col));
      }
  }
  Eigen::SparseMatrix<double> B(m * dim, n_nodes * dim);
  // Duplicates (a node appearing twice in one pair) are summed, as the gap definition asks.
  B.setFromTriplets(entries.begin(), entries.end());
  B.prune(0.0);
  return B;
}

Vector initial_gap(const std::vector<ContactPair>& pairs, const Eigen::Ref<const Matrix>& X)
{
  const int dim = static_cast<int>(X.cols());
  if (dim != 2 && dim != 3)
    throw std::invalid_argument("flexcontact: initial_gap: coordinates have "
                                + std::to_string(dim) + " columns, expected 2 or 3");
  const int n_nodes = static_cast<int>(X.rows());
  const int m = static_cast<int>(pairs.size());
  Vector x0(m * dim);
  for (int k = 0; k < m; ++k)
  {
    const ContactPair& c = pairs[k];
    check_pair(c, k, dim, n_nodes);
    Vector d = X.row(c.slave).transpose();
    for (std::size_t j = 0; j < c.masters.size(); ++j)
      d -= c.weights[j] * X.row(c.masters[j]).transpose();
    x0.segment(k * dim, dim) = c.frame * d;
    x0[k * dim] -= c.offset;
  }
  return x0;
}

namespace
{
/// @brief Rows [first, last) outside which column j of F is zero. F* is block-diagonal by
/// body (bodies share no DOFs) and the contact numbering keeps a body's nodes together (each
/// interface numbers its slaves, then its masters), so most of a column is exact zeros.
std::pair<Eigen::Index, Eigen::Index> nonzero_rows(const Eigen::Ref<const Matrix>& F,
                                                   Eigen::Index j)
{
  const double* col = F.col(j).data();
  Eigen::Index first = 0, last = F.rows();
  while (first < last && col[first] == 0.0)
    ++first;
  while (last > first && col[last - 1] == 0.0)
    --last;
  return {first, last};
}
} // namespace

Matrix delassus(const Eigen::SparseMatrix<double>& B, const Eigen::Ref<const Matrix>& Fstar)
{
  if (Fstar.rows() != Fstar.cols() || Fstar.rows() != B.cols())
    throw std::invalid_argument("flexcontact: delassus: F* is "
                                + std::to_string(Fstar.rows()) + "x"
                                + std::to_string(Fstar.cols()) + " but B has "
                                + std::to_string(B.cols()) + " columns");
  if (!Fstar.allFinite())
    throw std::invalid_argument("flexcontact: delassus: F* is not finite");
  // Each row of B touches a slave's and a few masters' DOFs, so W = B (F* Bᵀ) is built a
  // column at a time: y = F* Bᵀ e_j combines the few columns of F* that row j names (over
  // their nonzero rows only), then W e_j = B y reads a few entries of y per row. The work is
  // nnz(B)·n_c for y and nnz(B)·(m·d) for W, with y in cache, instead of two dense products.
  const Eigen::SparseMatrix<double, Eigen::RowMajor> Br(B);
  const Eigen::Index r = Br.rows(), n = Br.cols();
  std::vector<std::pair<Eigen::Index, Eigen::Index>> range(static_cast<std::size_t>(n));
  std::vector<bool> seen(static_cast<std::size_t>(n), false);
  Matrix W(r, r);
  Vector y(n);
  for (Eigen::Index j = 0; j < r; ++j)
  {
    Eigen::Index lo = n, hi = 0;
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(Br, j); it; ++it)
    {
      const auto c = static_cast<std::size_t>(it.col());
      if (!seen[c])
        range[c] = nonzero_rows(Fstar, it.col());
      seen[c] = true;
      lo = std::min(lo, range[c].first);
      hi = std::max(hi, range[c].second);
    }
    if (lo < hi)
      y.segment(lo, hi - lo).setZero();
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(Br, j); it; ++it)
    {
      const auto [a, b] = range[static_cast<std::size_t>(it.col())];
      if (a < b)
        y.segment(a, b - a) += it.value() * Fstar.col(it.col()).segment(a, b - a);
    }
    for (Eigen::Index i = 0; i < r; ++i)
    {
      double w = 0.0;
      for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(Br, i); it; ++it)
        if (it.col() >= lo && it.col() < hi)
          w += it.value() * y[it.col()];
      W(i, j) = w;
    }
  }
  // Rounding leaves W slightly unsymmetric; the solvers assume symmetry.
  for (Eigen::Index j = 0; j < r; ++j)
    for (Eigen::Index i = j + 1; i < r; ++i)
      W(i, j) = W(j, i) = 0.5 * (W(i, j) + W(j, i));
  return W;
}
} // namespace flexcontact
