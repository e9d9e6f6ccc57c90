// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file collective.h
/// @brief Errors raised on every rank: a condition decided on rank 0 (or by MUMPS's global
/// INFOG, the same everywhere) must not leave the other ranks waiting in a collective call.

#include <mpi.h>
#include <string>

namespace flexcontact
{
/// @brief Throw on the same condition on every rank: `fail_on_root` and its message, decided
/// on rank 0, are broadcast; `make(what)` throws.
inline void throw_collective_if(MPI_Comm comm, bool fail_on_root, const std::string& what_on_root,
                                const auto& make)
{
  int flag = fail_on_root ? 1 : 0;
  MPI_Bcast(&flag, 1, MPI_INT, 0, comm);
  if (!flag)
    return;
  int len = static_cast<int>(what_on_root.size());
  MPI_Bcast(&len, 1, MPI_INT, 0, comm);
  std::string what = what_on_root;
  what.resize(len);
  MPI_Bcast(what.data(), len, MPI_CHAR, 0, comm);
  make(what);
}

/// @brief The MumpsError for MUMPS's global status INFOG(1) < 0 after `phase`.
[[noreturn]] void throw_mumps_error(const char* phase, int infog1, int infog2);

/// @brief The SingularStiffnessError for `n` > 0 null pivots (INFOG(28)); nothing if n = 0.
void throw_if_null_pivots(int n);
} // namespace flexcontact
