// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file collective.h
/// @brief Errors raised on every rank: a condition decided on rank 0 (or by MUMPS's global
/// INFOG, the same everywhere) must not leave the other ranks waiting in a collective call.

#include <mpi.h>
#include <numeric>
#include <string>
#include <vector>

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

/// @brief All ranks' `local` concatenated in rank order on rank 0 (empty elsewhere); `type`
/// is T's MPI datatype (MPI_INT64_T, MPI_DOUBLE).
template <class T>
std::vector<T> gather_on_root(MPI_Comm comm, const std::vector<T>& local, MPI_Datatype type)
{
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  int count = static_cast<int>(local.size());
  std::vector<int> counts(size), offsets(size + 1, 0);
  MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, comm);
  std::partial_sum(counts.begin(), counts.end(), offsets.begin() + 1);
  std::vector<T> all(rank == 0 ? offsets.back() : 0);
  MPI_Gatherv(local.data(), count, type, all.data(), counts.data(), offsets.data(), type, 0,
              comm);
  return all;
}

/// @brief The MumpsError for MUMPS's global status INFOG(1) < 0 after `phase`.
[[noreturn]] void throw_mumps_error(const char* phase, int infog1, int infog2);

/// @brief The SingularStiffnessError for `n` > 0 null pivots (INFOG(28)); nothing if n = 0.
void throw_if_null_pivots(int n);
} // namespace flexcontact
