// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file writeback.h
/// @brief Values computed on rank 0 (contact forces, gaps, states…) written into a
/// distributed DOLFINx Function.

#include "compat.h"
#include <cstdint>
#include <span>

namespace flexcontact
{
/// @brief Set the listed DOFs of u to the given values; every other DOF keeps its value.
///
/// The DOF indices are global, as in PETSc vectors of u's space: global block index · bs +
/// component (for a scalar space, the global block index itself). Rank 0 gives them (and
/// the values, same count); other ranks pass empty arrays. Each owning rank sets its owned
/// entries, then the ghosts are updated (scatter forward). Collective.
/// @throws std::invalid_argument if sizes differ or an index is out of range (raised on every
/// rank)
void set_nodal_values(compat::Function& u, std::span<const std::int64_t> dofs,
                      std::span<const double> values);
} // namespace flexcontact
