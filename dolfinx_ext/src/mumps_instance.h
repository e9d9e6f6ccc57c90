// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file mumps_instance.h
/// @brief What the MUMPS instances this module owns (DistributedSchur, SavedFactor) share:
/// the matrix as triplets, the factorization that grows its workspace, the files of a saved
/// instance, and the release.

#include <dmumps_c.h>
#include <petscmat.h>

#include <string>
#include <vector>

namespace flexcontact
{
/// @brief The upper triangle (col ≥ row) of this rank's rows of the symmetric K, as
/// MUMPS's 1-based triplets (an SBAIJ K gives its stored triangle, an AIJ K its full rows,
/// halved here).
void upper_triplets(Mat K, std::vector<int>& irn, std::vector<int>& jcn,
                    std::vector<double>& a);

/// @brief MUMPS's numerical factorization (JOB=2) after its analysis. LDLᵀ with pivoting
/// can outgrow the workspace the analysis estimated; MUMPS's remedy is a larger ICNTL(14)
/// (the analysis stays valid), tried up to five times. Returns the retries.
/// @throws MumpsError
int factorize_growing_workspace(DMUMPS_STRUC_C& id);

/// @brief Point the instance's SAVE_DIR and SAVE_PREFIX at `dir` and `prefix` (for JOB=7
/// and JOB=8). `who` names the caller in the error.
/// @throws std::invalid_argument if either is longer than MUMPS's fixed-size fields
void set_save_files(DMUMPS_STRUC_C& id, const std::string& dir, const std::string& prefix,
                    const std::string& who);

/// @brief End the instance (JOB=-2) if it is alive and MPI still runs; `alive` becomes false.
void end_instance(DMUMPS_STRUC_C& id, bool& alive);
} // namespace flexcontact
