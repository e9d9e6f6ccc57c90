// Copyright flexcontact developers. MIT licence.

#include "writeback.h"

#include <mpi.h>
#include <stdexcept>
#include <string>
#include <vector>

using namespace flexcontact;

void flexcontact::set_nodal_values(compat::Function& u, std::span<const std::int64_t> dofs,
                                   std::span<const double> values)
{
  auto V = u.function_space();
  auto dofmap = V->dofmap();
  auto index_map = dofmap->index_map;
  const int bs = dofmap->index_map_bs();
  MPI_Comm comm = index_map->comm();
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  const std::int64_t n_global = index_map->size_global() * bs;

  // Validate on rank 0, decide together.
  std::string bad;
  if (rank == 0)
  {
    if (dofs.size() != values.size())
      bad = "set_nodal_values: " + std::to_string(dofs.size()) + " DOF indices but "
            + std::to_string(values.size()) + " values";
    else
      for (std::int64_t g : dofs)
        if (g < 0 or g >= n_global)
        {
          bad = "set_nodal_values: DOF index " + std::to_string(g) + " out of range [0, "
                + std::to_string(n_global) + ")";
          break;
        }
  }
  int fail = bad.empty() ? 0 : 1;
  MPI_Bcast(&fail, 1, MPI_INT, 0, comm);
  if (fail)
  {
    int len = static_cast<int>(bad.size());
    MPI_Bcast(&len, 1, MPI_INT, 0, comm);
    bad.resize(len);
    MPI_Bcast(bad.data(), len, MPI_CHAR, 0, comm);
    throw std::invalid_argument(bad);
  }

  // Everyone gets the (surface-sized) lists and keeps what it owns.
  std::uint64_t n = rank == 0 ? dofs.size() : 0;
  MPI_Bcast(&n, 1, MPI_UINT64_T, 0, comm);
  std::vector<std::int64_t> g(n);
  std::vector<double> v(n);
  if (rank == 0)
  {
    std::copy(dofs.begin(), dofs.end(), g.begin());
    std::copy(values.begin(), values.end(), v.begin());
  }
  MPI_Bcast(g.data(), static_cast<int>(n), MPI_INT64_T, 0, comm);
  MPI_Bcast(v.data(), static_cast<int>(n), MPI_DOUBLE, 0, comm);

  const auto range = index_map->local_range();
  std::span<double> x = compat::function_array(u);
  for (std::size_t i = 0; i < n; ++i)
  {
    const std::int64_t block = g[i] / bs;
    if (block >= range[0] and block < range[1])
      x[(block - range[0]) * bs + g[i] % bs] = v[i];
  }
  compat::scatter_forward(u);
}
