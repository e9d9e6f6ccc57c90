// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file carry_over.hpp
/// @brief Re-pairing, shared by the dense and the operator condensed problems: a slave node
/// that keeps a pair keeps its contact force and state as the next increment's warm start,
/// so that re-pairing a sliding contact does not restart its iteration from zero.

#include "flexcontact/pairs.hpp"
#include "flexcontact/problem.hpp"

#include <cstddef>
#include <vector>

namespace flexcontact::detail
{
/// @brief For each of the new `pairs`, the index in `old_pairs` of its slave node's pair
/// (−1 if it had none). `nodes` is the contact node count; the slaves must be in range
/// (gap_operator() checks them first).
inline std::vector<int> previous_pair_of(const std::vector<ContactPair>& old_pairs,
                                         const std::vector<ContactPair>& pairs,
                                         Eigen::Index nodes)
{
  std::vector<int> of_slave(static_cast<std::size_t>(nodes), -1);
  for (std::size_t k = 0; k < old_pairs.size(); ++k)
    of_slave[static_cast<std::size_t>(old_pairs[k].slave)] = static_cast<int>(k);
  std::vector<int> previous(pairs.size(), -1);
  for (std::size_t k = 0; k < pairs.size(); ++k)
    previous[k] = of_slave[static_cast<std::size_t>(pairs[k].slave)];
  return previous;
}

/// @brief λ of the new pairs: the slave node's old force in global axes, T_oldᵀ λ_old, seen
/// in the new frame; zero for a slave node that had no pair.
inline Vector carried_force(const std::vector<ContactPair>& old_pairs, const Vector& old_lambda,
                            const std::vector<ContactPair>& pairs,
                            const std::vector<int>& previous, int dim)
{
  Vector lambda = Vector::Zero(static_cast<Eigen::Index>(pairs.size()) * dim);
  for (std::size_t k = 0; k < pairs.size(); ++k)
    if (const int j = previous[k]; j >= 0)
      lambda.segment(static_cast<Eigen::Index>(k) * dim, dim)
          = pairs[k].frame * (old_pairs[j].frame.transpose() * old_lambda.segment(j * dim, dim));
  return lambda;
}

/// @brief A value kept per contact node (a crush depth) read for each pair at its slave.
inline Vector at_slaves(const std::vector<ContactPair>& pairs, const Vector& node_values)
{
  Vector v(static_cast<Eigen::Index>(pairs.size()));
  for (std::size_t k = 0; k < pairs.size(); ++k)
    v[static_cast<Eigen::Index>(k)] = node_values[pairs[k].slave];
  return v;
}

/// @brief States of the new pairs: the slave node's old state, open for a new one.
inline std::vector<PairState> carried_states(const std::vector<PairState>& old_states,
                                             const std::vector<int>& previous)
{
  std::vector<PairState> states(previous.size(), PairState::open);
  for (std::size_t k = 0; k < previous.size(); ++k)
    if (previous[k] >= 0)
      states[k] = old_states[static_cast<std::size_t>(previous[k])];
  return states;
}
} // namespace flexcontact::detail
