// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file ordering.h
/// @brief The fill-reducing ordering of the MUMPS factorization of K.
///
/// Debian's MUMPS is built without sequential METIS and SCOTCH (ICNTL(7) = 5 or 3 fall back
/// to AMF or PORD, and its parallel analysis has neither PT-SCOTCH nor ParMETIS), and PETSc's
/// Cholesky interface to MUMPS ignores a user permutation and refuses ICNTL(7) = 1. So a
/// nested-dissection ordering from METIS (METIS_NodeND on the graph of the mesh nodes,
/// expanded to their DOFs) is handed to MUMPS here: after PETSc's analysis has set MUMPS up,
/// the analysis is redone on the same MUMPS instance with ICNTL(7) = 1 and PERM_IN. That
/// needs MUMPS's own structure, which PETSc keeps in the factor's private data (where:
/// mumps_layout.h); it is checked (job, size, symmetry, INFOG) before use and INFOG(7) = 1 is checked after, so a
/// PETSc that lays it out otherwise never gives a wrong factor: "auto" then keeps MUMPS's own
/// ordering (and says why in info["ordering_fallback"]), an explicit "metis" is a clear error.

#include <petscmat.h>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace flexcontact
{
/// @brief The orderings flexibility() accepts: "auto" (see resolve_ordering), "metis" (METIS
/// nested dissection given to MUMPS), "mumps" (MUMPS's automatic choice, ICNTL(7) = 7), and
/// MUMPS's own "amd", "amf", "pord", "qamd" (ICNTL(7) = 0, 2, 4, 6).
bool is_ordering(const std::string& name);

/// @brief The ordering "auto" stands for: "metis" for K of block size 3 (3D elasticity,
/// where METIS needs 2.7 times fewer flops than MUMPS's choice at 30k DOFs) and for a K of
/// at least 100,000 rows factored with a Schur complement (`schur`: MUMPS then keeps only
/// AMD of its own; on the 2D Hertz meshes METIS with the contact DOFs last takes less time
/// and fewer entries from 200k DOFs on, more time at 50k; bench/schur_ordering_2d.py),
/// "mumps" otherwise (a plain 2D factor: MUMPS's PORD is as good as METIS there and needs
/// no second analysis; bench/ordering.py). Other names are returned as they are.
std::string resolve_ordering(const std::string& name, Mat K, bool schur = false);

/// @brief MUMPS's ICNTL(7) for a resolved ordering name ("mumps" → 7, "amd" → 0, ...); 1 for
/// "metis" (a user permutation).
int mumps_icntl7(const std::string& name);

/// @brief MUMPS's name of the ordering INFOG(7) reports ("metis_nd" for a user permutation).
std::string ordering_name(int infog7);

/// @brief MUMPS's PERM_IN (1-based position of each row in the pivot order) from METIS
/// nested dissection of the nodal graph of K (blocks of K's block size), serial K only.
/// The rows `last` (the Schur variables) are put last, in the given order, as MUMPS needs;
/// their nodes are removed from the graph before it is dissected (less fill than moving them
/// out of a dissection of the whole graph: docs/architecture.md §4).
std::vector<int> metis_pivot_order(Mat K, std::span<const PetscInt> last);

/// @brief metis_pivot_order() for a K distributed by rows: the nodal graph of each rank's rows
/// is gathered on rank 0, which orders it. Collective; PERM_IN on rank 0, empty elsewhere.
std::vector<int> metis_pivot_order_gathered(Mat K, std::span<const PetscInt> last);

/// @brief The MUMPS instance inside PETSc's factor is not laid out as this build expects
/// (another PETSc): no ordering can be handed to it; nothing was changed.
struct MumpsLayoutError : std::runtime_error
{
  using std::runtime_error::runtime_error;
};

/// @brief Redo MUMPS's analysis of the factor F (after MatCholeskyFactorSymbolic) with the
/// ordering `icntl7`, and PERM_IN = `perm_in` when icntl7 = 1. Serial only.
/// @throws MumpsLayoutError if F's MUMPS instance is not as expected (F unchanged);
/// std::runtime_error if PERM_IN was not
/// used (MUMPS may replace its own orderings: with a Schur complement AMF, PORD, QAMD by AMD)
void reanalyse(Mat F, PetscInt N, int icntl7, std::vector<int> perm_in);
} // namespace flexcontact
