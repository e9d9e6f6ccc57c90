// Copyright flexcontact developers. MIT licence.

#include "saved_factor.h"
#include "collective.h"
#include "flexibility.h"
#include "mumps_instance.h"
#include "petsc_error.h"

#include <mpi.h>

#include <algorithm>
#include <limits>
#include <stdexcept>

using namespace flexcontact;

namespace
{
int& icntl(DMUMPS_STRUC_C& id, int i) { return id.icntl[i - 1]; }
int infog(const DMUMPS_STRUC_C& id, int i) { return id.infog[i - 1]; }
} // namespace

void SavedFactor::init()
{
  id_.job = -1;
  id_.par = 1;
  id_.sym = 2; // symmetric LDLᵀ with pivoting: Ŵ and K need not be definite on held rows
  id_.comm_fortran = static_cast<int>(MPI_Comm_c2f(MPI_COMM_SELF));
  dmumps_c(&id_);
  if (infog(id_, 1) < 0)
    throw_mumps_error("initialization", infog(id_, 1), infog(id_, 2));
  alive_ = true;
  icntl(id_, 1) = icntl(id_, 2) = icntl(id_, 3) = -1; // no printing
  icntl(id_, 4) = 0;
  icntl(id_, 5) = 0;  // assembled
  icntl(id_, 18) = 0; // centralised triplets
  icntl(id_, 20) = 0; // dense right-hand side
  icntl(id_, 21) = 0; // centralised solution
  icntl(id_, 24) = 1; // detect null pivots instead of dividing by ~0
}

SavedFactor::SavedFactor(Mat A)
{
  PetscErrorScope err;
  PetscInt rows = 0, cols = 0;
  err.check(MatGetSize(A, &rows, &cols), "MatGetSize");
  int size = 1;
  MPI_Comm_size(PetscObjectComm(reinterpret_cast<PetscObject>(A)), &size);
  if (size != 1)
    throw std::invalid_argument("SavedFactor: the matrix is distributed over "
                                + std::to_string(size) + " processes; it must be serial");
  if (rows != cols or rows < 1 or rows > std::numeric_limits<int>::max() - 1)
    throw std::invalid_argument("SavedFactor: a square matrix of 1 to 2^31 - 2 rows is needed, "
                                "not " + std::to_string(rows) + " x " + std::to_string(cols));
  n_ = rows;
  upper_triplets(A, irn_, jcn_, a_);
  init();
  try
  {
    id_.n = static_cast<int>(n_);
    id_.nnz = static_cast<MUMPS_INT8>(a_.size());
    id_.nz = a_.size() <= static_cast<std::size_t>(std::numeric_limits<int>::max())
                 ? static_cast<int>(a_.size()) : 0;
    id_.irn = irn_.data();
    id_.jcn = jcn_.data();
    id_.a = a_.data();
    call(1, "analysis");
    factorize_growing_workspace(id_);
    throw_if_null_pivots(infog(id_, 28));
  }
  catch (...)
  {
    release();
    throw;
  }
  // MUMPS holds the factor; the triplets are not needed for solves.
  std::vector<int>().swap(irn_);
  std::vector<int>().swap(jcn_);
  std::vector<double>().swap(a_);
  id_.irn = id_.jcn = nullptr;
  id_.a = nullptr;
}

SavedFactor::SavedFactor(const std::string& dir, const std::string& prefix, PetscInt n)
{
  if (n < 1 or n > std::numeric_limits<int>::max() - 1)
    throw std::invalid_argument("SavedFactor: n=" + std::to_string(n) + " rows is not a size");
  n_ = n;
  init();
  try
  {
    set_save_files(id_, dir, prefix, "SavedFactor");
    call(8, "restoration of '" + dir + "/" + prefix + "'");
    if (id_.n != static_cast<int>(n_))
      throw std::invalid_argument("SavedFactor: the files at '" + dir + "/" + prefix
                                  + "' hold a factor of " + std::to_string(id_.n)
                                  + " rows, not " + std::to_string(n_));
  }
  catch (...)
  {
    release();
    throw;
  }
}

SavedFactor::~SavedFactor() { release(); }

void SavedFactor::release()
{
  end_instance(id_, alive_);
}

void SavedFactor::save(const std::string& dir, const std::string& prefix)
{
  if (!alive_)
    throw std::runtime_error("SavedFactor: the factor was released");
  set_save_files(id_, dir, prefix, "SavedFactor");
  call(7, "save to '" + dir + "/" + prefix + "'");
}

void SavedFactor::solve(Vec b, Vec x)
{
  if (!alive_)
    throw std::runtime_error("SavedFactor: the factor was released");
  PetscErrorScope err;
  PetscInt nb = 0, nx = 0;
  err.check(VecGetSize(b, &nb), "VecGetSize(b)");
  err.check(VecGetSize(x, &nx), "VecGetSize(x)");
  if (nb != n_ or nx != n_)
    throw std::invalid_argument("SavedFactor.solve: b has " + std::to_string(nb) + " and x "
                                + std::to_string(nx) + " entries; the factor has "
                                + std::to_string(n_) + " rows");
  rhs_.resize(n_);
  const PetscScalar* pb = nullptr;
  err.check(VecGetArrayRead(b, &pb), "VecGetArrayRead");
  std::copy(pb, pb + n_, rhs_.begin());
  err.check(VecRestoreArrayRead(b, &pb), "VecRestoreArrayRead");
  id_.nrhs = 1;
  id_.lrhs = static_cast<int>(n_);
  id_.rhs = rhs_.data();
  call(3, "solve");
  PetscScalar* px = nullptr;
  err.check(VecGetArray(x, &px), "VecGetArray");
  std::copy(rhs_.begin(), rhs_.end(), px);
  err.check(VecRestoreArray(x, &px), "VecRestoreArray");
}

Eigen::MatrixXd SavedFactor::solve_many(const Eigen::Ref<const Eigen::MatrixXd>& B)
{
  if (!alive_)
    throw std::runtime_error("SavedFactor: the factor was released");
  if (B.rows() != n_ or B.cols() < 1)
    throw std::invalid_argument("SavedFactor.solve_many: B has " + std::to_string(B.rows())
                                + " rows and " + std::to_string(B.cols()) + " columns; the "
                                "factor has " + std::to_string(n_) + " rows, and at least "
                                "one column is needed");
  Eigen::MatrixXd X = B;
  id_.nrhs = static_cast<int>(X.cols());
  id_.lrhs = static_cast<int>(n_);
  id_.rhs = X.data();
  try
  {
    call(3, "solve of several right-hand sides");
  }
  catch (...)
  {
    id_.nrhs = 1;
    throw;
  }
  id_.nrhs = 1;
  return X;
}

double SavedFactor::factor_entries() const
{
  const int e = infog(id_, 29) != 0 ? infog(id_, 29) : infog(id_, 20);
  return e >= 0 ? e : -static_cast<double>(e) * 1e6;
}

void SavedFactor::call(int job, const std::string& phase)
{
  id_.job = job;
  dmumps_c(&id_);
  if (infog(id_, 1) < 0)
    throw_mumps_error(phase.c_str(), infog(id_, 1), infog(id_, 2));
}
