// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file contact_checks.hpp
/// @brief The argument checks that the contact objects (CondensedContact, OperatorContact,
/// IncrementalSolver) have in common, so that the same mistake reads the same from each.
/// `who` names the object and ends in ": ".

#include "flexcontact/problem.hpp"
#include "message_numbers.hpp"

#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <string>

namespace flexcontact::detail
{
/// @brief dim if it is 2 or 3; throws otherwise (usable in a member initialiser).
inline int checked_dim(int dim, const std::string& who)
{
  if (dim != 2 && dim != 3)
    throw std::invalid_argument(who + "dim is " + std::to_string(dim) + "; it must be 2 or 3");
  return dim;
}

/// @brief Throws unless the contact node coordinates X have dim columns and are finite.
inline void check_coordinates(const Matrix& X, int dim, const std::string& who)
{
  if (X.cols() != dim)
    throw std::invalid_argument(who + "X is " + std::to_string(X.rows()) + "x"
                                + std::to_string(X.cols()) + "; it must have dim = "
                                + std::to_string(dim) + " columns");
  if (!X.allFinite())
    throw std::invalid_argument(who + "X (contact node coordinates) is not finite");
}

/// @brief Throws unless the flexibility F (`name`: "F*", "Fhat") is n_c × n_c and finite.
inline void check_flexibility(const Matrix& F, Eigen::Index n_c, const char* name,
                              const std::string& who)
{
  if (F.rows() != n_c || F.cols() != n_c)
    throw std::invalid_argument(who + name + " is " + std::to_string(F.rows()) + "x"
                                + std::to_string(F.cols()) + ", expected "
                                + std::to_string(n_c) + "x" + std::to_string(n_c)
                                + " (contact nodes × dim)");
  if (!F.allFinite())
    throw std::invalid_argument(who + name + " is not finite");
}

/// @brief Throws unless a flexibility held by block (`name`) has n_c rows.
inline void check_flexibility_rows(Eigen::Index rows, Eigen::Index n_c, const char* name,
                                   const std::string& who)
{
  if (rows != n_c)
    throw std::invalid_argument(who + name + " has " + std::to_string(rows) + " rows, expected "
                                + std::to_string(n_c) + " (contact nodes × dim)");
}

/// @brief Throws unless there is one friction coefficient per pair.
inline void check_mu_count(const Vector& mu, std::size_t pairs, const std::string& who)
{
  if (static_cast<std::size_t>(mu.size()) != pairs)
    throw std::invalid_argument(who + "mu has " + std::to_string(mu.size())
                                + " entries but there are " + std::to_string(pairs) + " pairs");
}

/// @brief Throws unless `cap` is empty (no crushing) or holds one normal force cap per pair,
/// each > 0 (+∞: that pair has none), naming the first bad one (docs/crushing.md).
inline void check_caps(const Vector& cap, std::size_t pairs, const std::string& who)
{
  if (cap.size() == 0)
    return;
  if (static_cast<std::size_t>(cap.size()) != pairs)
    throw std::invalid_argument(who + "cap has " + std::to_string(cap.size())
                                + " entries but there are " + std::to_string(pairs) + " pairs");
  for (Eigen::Index k = 0; k < cap.size(); ++k)
    if (!(cap[k] > 0.0))
      throw std::invalid_argument(who + "the normal force cap of pair " + std::to_string(k)
                                  + " is " + num(cap[k]) + "; it must be > 0 (+inf: no cap)");
}

/// @brief Throws naming the first friction coefficient that is negative or not finite.
inline void check_friction(const Vector& mu, const std::string& who)
{
  for (Eigen::Index k = 0; k < mu.size(); ++k)
    if (!std::isfinite(mu[k]) || mu[k] < 0.0)
      throw std::invalid_argument(who + "friction coefficient of pair " + std::to_string(k)
                                  + " is " + num(mu[k]) + "; it must be finite and >= 0");
}

/// @brief Throws unless max_iterations ≥ 1 and the tolerance is finite and > 0.
inline void check_iteration_options(const SolverOptions& options, const std::string& who)
{
  if (options.max_iterations < 1)
    throw std::invalid_argument(who + "max_iterations is "
                                + std::to_string(options.max_iterations)
                                + "; it must be at least 1");
  if (!(options.tolerance > 0.0) || !std::isfinite(options.tolerance))
    throw std::invalid_argument(who + "tolerance is " + num(options.tolerance)
                                + "; it must be finite and > 0");
}

/// @brief Throws unless the contact-DOF vector `name` has n_c entries, all finite.
inline void check_contact_values(const std::string& who, const char* name,
                                 const Eigen::Ref<const Vector>& v, Eigen::Index n_c)
{
  if (v.size() != n_c)
    throw std::invalid_argument(who + name + " has " + std::to_string(v.size())
                                + " entries, expected n_c = " + std::to_string(n_c));
  if (!v.allFinite())
    throw std::invalid_argument(who + name + " is not finite");
}
} // namespace flexcontact::detail
