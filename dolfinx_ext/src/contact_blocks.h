// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file contact_blocks.h
/// @brief Per-body condensation (docs/architecture.md §7): bodies share no DOFs and are coupled only
/// through contact, so K is block-diagonal by body (up to a permutation), and so are its
/// Schur complement K*_cc on the contact DOFs and F* = (K*_cc)⁻¹. Each body's block is
/// factored (and, where W needs it, inverted) on its own: Σ n_b³ instead of n_c³.
///
/// The blocks are the connected components of K's sparsity graph restricted to the contact
/// DOFs: two contact DOFs share a block if and only if a path of structural non-zeros of K
/// joins them. Structural (not numerical) non-zeros are used, so a block is never split
/// where K couples, and Dirichlet rows (zeroed but kept in DOLFINx's pattern) change nothing.

#include "flexcontact/block_flexibility.hpp"

#include <Eigen/Dense>
#include <petscmat.h>
#include <vector>

namespace flexcontact
{
/// @brief Block label of each contact DOF, on rank 0 (empty elsewhere): labels 0, 1, ... in
/// order of first appearance in `dofs`; equal labels for contact DOFs that K's graph connects.
/// Collective on K's communicator; `dofs` are global rows, read on rank 0 only.
/// Cost: one pass over K's local pattern (union-find), one scatter of component labels to
/// the ghost columns and to rank 0.
std::vector<int> contact_blocks(Mat K, const std::vector<PetscInt>& dofs);

/// @brief Positions (into the contact DOF list) of each block's DOFs, blocks in label order.
std::vector<std::vector<int>> block_members(const std::vector<int>& labels);

/// @brief F = S⁻¹ for a symmetric positive definite S that is block-diagonal by `blocks`,
/// held as each block's Cholesky factor: the block symmetrised and factored by LAPACK
/// (dpotrf). S is read column-major from `s` with leading dimension `lda` (n×n, n the total
/// of the blocks' sizes); entries between blocks are not read.
/// @throws SingularStiffnessError naming the block if one is not positive definite or its
/// reciprocal condition number (dpocon, 1-norm) is below 1e3·ε
BlockFlexibility blockwise_cholesky(const double* s, std::size_t lda,
                                    const std::vector<std::vector<int>>& blocks);
} // namespace flexcontact
