// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file newton_step.hpp
/// @brief Private to the kernel: one step of the semi-smooth Alart–Curnier Newton, the
/// direction from the generalised Jacobian and its globalisation (newton_step.cpp), shared
/// by the plain Newton (newton_ac.cpp) and, for the pieces it has in common, the bordered
/// one (newton_bordered.cpp).

#include "flexcontact/problem.hpp"

#include <algorithm>
#include <vector>

namespace flexcontact::detail
{
/// @brief A pair's block ∂P/∂z as ac_pair() writes it: d×d, row-major.
using DpBlock
    = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>;

/// @brief Pair k's block ∂P/∂z in dP.
inline DpBlock dp_block(const std::vector<double>& dP, int k, int d)
{
  return DpBlock(dP.data() + k * d * d, d, d);
}

/// @brief D_k ρ: pair k's block ∂P/∂z with its normal column times ρ_n and its tangential
/// columns times ρ_t, the factor of W's rows in the generalised Jacobian.
Matrix scaled_dp(const std::vector<double>& dP, int k, int d, double rho_n, double rho_t);

/// @brief The pairs whose block ∂P/∂z is not zero; the others (open) decouple from the
/// Newton system.
void closed_pairs(const std::vector<double>& dP, int m, int d, std::vector<int>& closed);

/// @brief Φ(λ) for all pairs from λ and u = Wλ + q; optionally the blocks ∂P/∂z (d×d each).
void ac_all(const ProblemView& p, const Vector& rho, const Vector& rho_t, const Vector& lam,
            const Vector& u, Vector& phi, std::vector<double>* dP);

/// @brief Φ and the blocks ∂P/∂z at (λ, u); returns the merit ½‖Φ‖².
double merit(const ProblemView& p, const Vector& rho, const Vector& rho_t, const Vector& lam,
             const Vector& u, Vector& phi, std::vector<double>& dP);

/// @brief Newton direction dl from the generalised Jacobian, J Δ = −Φ with
/// J = I − D (I − ρW) = (I − D) + D ρ W, D = blockdiag(∂P/∂z). Pairs with D_k = 0 (open)
/// have identity rows: Δ_k = −Φ_k; only the closed block is factorised, which keeps the
/// dense LU to the size of the contact zone, and within it only the rows whose row of
/// ∂P/∂z is not zero (the others are the identity's too). Returns false if that block has
/// no solution. ``factorised``: the orders of the LUs taken (the reduced block's, and the
/// whole block's where the reduced LU failed), for the work budget.
bool newton_direction(const ProblemView& p, const Vector& rho, const Vector& rho_t,
                      const Vector& phi, const std::vector<double>& dP,
                      const std::vector<int>& closed, Vector& dl,
                      std::vector<double>* factorised = nullptr);

/// @brief Non-monotone reference of the line search: the largest merit of the last few
/// accepted iterates lets the iteration pass the shallow ridges the kinks of Φ create
/// (Grippo–Lampariello–Lucidi).
class MeritHistory
{
public:
  explicit MeritHistory(double f) : f_{f} {}

  /// @brief Forgets the earlier iterates (after a restart).
  void reset(double f) { f_.assign(1, f); }

  void push(double f)
  {
    f_.push_back(f);
    if (static_cast<int>(f_.size()) > memory)
      f_.erase(f_.begin());
  }

  double reference() const { return *std::max_element(f_.begin(), f_.end()); }

private:
  static constexpr int memory = 5;
  std::vector<double> f_;
};

/// @brief The line search's trial iterate: λ + α Δ, u + α WΔ, its Φ, and WΔ.
struct Trial
{
  Vector lam, u, phi, Wdl;
};

/// @brief Line search on ½‖Φ‖², Armijo with the non-monotone reference of history. If the
/// Newton direction dl gives no decrease, the fixed-point direction −Φ (a projected step)
/// replaces it (not with full_step, where the caller then takes the full Newton step).
/// Returns true with the accepted iterate in t.
bool line_search(const ProblemView& p, const Vector& rho, const Vector& rho_t,
                 const Vector& lam, const Vector& u, const Vector& phi, double f,
                 const MeritHistory& history, bool full_step, Vector& dl, Trial& t);

/// @brief Goldstein–Price search along the Newton direction (the merit's slope there is
/// −2f): α is accepted when the mean slope (f(α) − f)/α lies between 0.99 and 0.01 times
/// the initial one; too steep raises the lower bound, too shallow lowers the upper, and
/// α bisects the bracket. Returns true with the accepted iterate in t.
bool goldstein_price(const ProblemView& p, const Vector& rho, const Vector& rho_t,
                     const Vector& lam, const Vector& u, double f, const Vector& dl, Trial& t);
} // namespace flexcontact::detail
