// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file constrained.hpp
/// @brief Shared by the static, the operator and the impact contact objects: contact DOFs
/// held by a Dirichlet condition do not move under contact forces.

#include "flexcontact/problem.hpp"

#include <stdexcept>
#include <string>
#include <vector>

namespace flexcontact
{
/// @brief Throws unless `constrained` is empty (none held) or has one entry per contact
/// DOF; `who` prefixes the error.
inline void check_constrained(const std::vector<bool>& constrained, Eigen::Index n_c,
                              const std::string& who)
{
  if (!constrained.empty() && static_cast<Eigen::Index>(constrained.size()) != n_c)
    throw std::invalid_argument(who + "constrained has " + std::to_string(constrained.size())
                                + " entries, expected 0 or n_c = " + std::to_string(n_c));
}

/// @brief Zeroes the rows and columns of a flexibility that belong to constrained contact
/// DOFs (K's identity rows would otherwise give them a flexibility of 1). `constrained` is
/// empty (none held) or has one entry per row of F; `who` prefixes the error otherwise.
inline void zero_constrained(Matrix& F, const std::vector<bool>& constrained,
                             const std::string& who)
{
  check_constrained(constrained, F.rows(), who);
  for (std::size_t i = 0; i < constrained.size(); ++i)
    if (constrained[i])
    {
      F.row(static_cast<Eigen::Index>(i)).setZero();
      F.col(static_cast<Eigen::Index>(i)).setZero();
    }
}
} // namespace flexcontact
