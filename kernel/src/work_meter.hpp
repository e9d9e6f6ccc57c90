// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file work_meter.hpp
/// @brief Private to the kernel: the work budget of SolverOptions::work_budget_gflop.
///
/// Each iteration charges the floating-point operations of its dense kernels, estimated
/// from their sizes (docs/solvers.md, "The work budget"). The count depends only on the
/// path the iterations take, never on the machine or its load, so a budget in work stops
/// a solver at the same iterate on a quiet and on a busy machine; a wall-clock budget did
/// not (the same problem stopped after 76 Newton steps in one run and 89 in another).

namespace flexcontact::detail
{
/// @brief Dense LU of an s × s matrix.
inline double lu_flops(double s) { return 2.0 / 3.0 * s * s * s; }

/// @brief Dense matrix–vector product with an n × n matrix.
inline double product_flops(double n) { return 2.0 * n * n; }

class WorkMeter
{
public:
  /// @brief A budget of 0 (or less) never runs out.
  explicit WorkMeter(double budget_gflop)
      : limited_{budget_gflop > 0.0}, budget_{limited_ ? budget_gflop * 1e9 : 0.0}
  {
  }

  void charge(double flops) { used_ += flops; }

  /// @brief True once the work charged reaches the budget.
  bool spent() const { return limited_ && used_ >= budget_; }

  double used_gflop() const { return used_ * 1e-9; }

private:
  bool limited_;
  double budget_;
  double used_ = 0.0;
};
} // namespace flexcontact::detail
