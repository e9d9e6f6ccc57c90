// Copyright flexcontact developers. MIT licence.
#pragma once

#include "flexcontact/condensed.hpp"

#include <algorithm>
#include <vector>

namespace flexcontact::detail
{
/// @brief An increment's totals from its λ and gap, shared by the dense and the operator
/// condensed problems: slip (tangential gap − slip_origin), each pair's friction force in
/// global axes, the normal and tangential resultants, the largest penetration (of the
/// crushed surface where r.crush_depth is set) and the
/// contact forces r_c = Bᵀ λ (zero on held DOFs).
inline void summarize_step(CondensedStep& r, const std::vector<ContactPair>& pairs, int d,
                           const Vector& slip_origin, const Eigen::SparseMatrix<double>& B,
                           const std::vector<bool>& constrained)
{
  const int m = static_cast<int>(pairs.size());
  r.slip.resize(m * (d - 1));
  r.pair_tangential = Matrix::Zero(m, d);
  r.normal_force = 0.0;
  double min_gap = 0.0;
  for (int k = 0; k < m; ++k)
  {
    r.normal_force += r.lambda[k * d];
    // A crushed surface is δ behind the elastic one: that much gap is not penetration.
    min_gap = std::min(min_gap, r.gap[k * d] + (r.crush_depth.size() ? r.crush_depth[k] : 0.0));
    for (int j = 1; j < d; ++j)
    {
      r.slip[k * (d - 1) + j - 1] = r.gap[k * d + j] - slip_origin[k * d + j];
      // The friction force in global axes: the tangent rows of T_k carry λ_t back.
      r.pair_tangential.row(k) += r.lambda[k * d + j] * pairs[k].frame.row(j);
    }
  }
  r.tangential_force = r.pair_tangential.colwise().sum().transpose();
  r.max_penetration = std::max(0.0, -min_gap);
  r.reaction = B.transpose() * r.lambda;
  for (std::size_t i = 0; i < constrained.size(); ++i)
    if (constrained[i])
      r.reaction[static_cast<Eigen::Index>(i)] = 0.0;
}
} // namespace flexcontact::detail
