// Copyright flexcontact developers. MIT licence.

#include "mumps_instance.h"
#include "collective.h"
#include "petsc_error.h"

#include <mpi.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>

void flexcontact::upper_triplets(Mat K, std::vector<int>& irn, std::vector<int>& jcn,
                                 std::vector<double>& a)
{
  PetscErrorScope err;
  PetscInt rstart = 0, rend = 0;
  err.check(MatGetOwnershipRange(K, &rstart, &rend), "MatGetOwnershipRange");
  MatInfo info;
  err.check(MatGetInfo(K, MAT_LOCAL, &info), "MatGetInfo");
  const auto guess = static_cast<std::size_t>(info.nz_used / 2 + (rend - rstart));
  irn.clear(), jcn.clear(), a.clear();
  irn.reserve(guess), jcn.reserve(guess), a.reserve(guess);
  err.check(MatGetRowUpperTriangular(K), "MatGetRowUpperTriangular");
  for (PetscInt r = rstart; r < rend; ++r)
  {
    PetscInt ncols = 0;
    const PetscInt* cols = nullptr;
    const PetscScalar* vals = nullptr;
    err.check(MatGetRow(K, r, &ncols, &cols, &vals), "MatGetRow");
    for (PetscInt k = 0; k < ncols; ++k)
      if (cols[k] >= r)
      {
        irn.push_back(static_cast<int>(r + 1));
        jcn.push_back(static_cast<int>(cols[k] + 1));
        a.push_back(vals[k]);
      }
    err.check(MatRestoreRow(K, r, &ncols, &cols, &vals), "MatRestoreRow");
  }
  err.check(MatRestoreRowUpperTriangular(K), "MatRestoreRowUpperTriangular");
}

int flexcontact::factorize_growing_workspace(DMUMPS_STRUC_C& id)
{
  for (int retries = 0;; ++retries)
  {
    id.job = 2;
    dmumps_c(&id);
    const int e = id.infog[0];
    if ((e == -8 or e == -9) and retries < 5)
    {
      id.icntl[13] = std::max(2 * id.icntl[13], 50); // ICNTL(14)
      continue;
    }
    if (e < 0)
      throw_mumps_error("factorization", e, id.infog[1]);
    return retries;
  }
}

void flexcontact::set_save_files(DMUMPS_STRUC_C& id, const std::string& dir,
                                 const std::string& prefix, const std::string& who)
{
  if (dir.size() >= sizeof(id.save_dir) or prefix.size() >= sizeof(id.save_prefix))
    throw std::invalid_argument(who + ": the folder '" + dir + "' or the prefix '" + prefix
                                + "' is longer than MUMPS takes ("
                                + std::to_string(sizeof(id.save_dir) - 1) + " and "
                                + std::to_string(sizeof(id.save_prefix) - 1) + " characters)");
  std::memset(id.save_dir, 0, sizeof(id.save_dir));
  std::memset(id.save_prefix, 0, sizeof(id.save_prefix));
  std::memcpy(id.save_dir, dir.data(), dir.size());
  std::memcpy(id.save_prefix, prefix.data(), prefix.size());
}

void flexcontact::end_instance(DMUMPS_STRUC_C& id, bool& alive)
{
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (alive and !finalized)
  {
    id.job = -2;
    dmumps_c(&id);
  }
  alive = false;
}
