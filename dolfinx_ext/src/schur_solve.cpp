// Copyright flexcontact developers. MIT licence.

#include "schur_solve.h"
#include "flexibility.h"
#include "mumps_layout.h"
#include "ordering.h"
#include "petsc_error.h"

#include <algorithm>
#include <stdexcept>
#include <string>

using namespace flexcontact;

namespace
{
const char* kLayout = "cannot split solves with this PETSc's MUMPS factor into condensation and "
                      "expansion (its MUMPS structure is not laid out as expected)";

/// @brief F's MUMPS structure if it is what PETSc's serial Cholesky factor with a Schur
/// complement on `dofs` must hold (where PETSc keeps it: mumps_layout.h),
/// checked against PETSc's public queries; else MumpsLayoutError. Reads the Schur list only
/// once the scalar fields agree.
DMUMPS_STRUC_C* checked_mumps(Mat F, PetscInt N, std::span<const PetscInt> dofs)
{
  if (!F)
    throw std::logic_error("the MUMPS factor was destroyed");
  PetscErrorScope err;
  PetscInt infog1 = -1, infog7 = -1, icntl19 = 0, icntl26 = 0;
  err.check(MatMumpsGetInfog(F, 1, &infog1), "MatMumpsGetInfog(1)");
  err.check(MatMumpsGetInfog(F, 7, &infog7), "MatMumpsGetInfog(7)");
  err.check(MatMumpsGetIcntl(F, 19, &icntl19), "MatMumpsGetIcntl(19)");
  err.check(MatMumpsGetIcntl(F, 26, &icntl26), "MatMumpsGetIcntl(26)");
  DMUMPS_STRUC_C* id = mumps_struct(F);
  const auto n_c = static_cast<PetscInt>(dofs.size());
  bool ok = id and id->n == N and (id->sym == 1 or id->sym == 2) and id->par == 1
            and (id->job == 2 or id->job == 3) and infog1 >= 0 and id->infog[0] == infog1
            and id->infog[6] == infog7 and icntl19 != 0 and id->icntl[18] == icntl19
            and icntl26 == -1 and id->icntl[25] == -1 and id->size_schur == n_c
            and id->listvar_schur and F->factorerrortype == MAT_FACTOR_NOERROR;
  for (PetscInt k = 0; ok and k < n_c; ++k)
    ok = id->listvar_schur[k] == dofs[k] + 1;
  if (!ok)
    throw MumpsLayoutError(kLayout);
  return id;
}

/// @brief Throws unless v has K's N rows; `what` names the call and the vector ("condense: b").
void check_rows(PetscErrorScope& err, Vec v, PetscInt N, const char* what)
{
  PetscInt n = 0;
  err.check(VecGetSize(v, &n), "VecGetSize");
  if (n != N)
    throw std::invalid_argument(std::string(what) + " has " + std::to_string(n)
                                + " entries, K has " + std::to_string(N) + " rows");
}
} // namespace

SchurSolve::SchurSolve(Mat F, std::span<const PetscInt> dofs)
{
  PetscErrorScope err;
  PetscMPIInt size = 1;
  MPI_Comm_size(PetscObjectComm(reinterpret_cast<PetscObject>(F)), &size);
  if (size != 1)
    throw MumpsLayoutError("condensation and expansion are serial only (PETSc cannot solve "
                           "with a Schur factor on several processes)");
  err.check(MatGetSize(F, &N_, nullptr), "MatGetSize");
  checked_mumps(F, N_, dofs);
  n_c_ = static_cast<PetscInt>(dofs.size());
  err.check(PetscObjectReference(reinterpret_cast<PetscObject>(F)), "PetscObjectReference");
  F_ = F;
  // The Schur list is checked once here; later phases check the scalar fields again.
  dofs_.assign(dofs.begin(), dofs.end());
}

SchurSolve::~SchurSolve()
{
  if (F_)
    MatDestroy(&F_);
}

void SchurSolve::destroy()
{
  if (F_)
    MatDestroy(&F_);
  condensed_ = false;
}

void SchurSolve::solve(Vec b, Vec x)
{
  if (!F_)
    throw std::logic_error("the MUMPS factor was destroyed");
  condensed_ = false; // PETSc's solve replaces MUMPS's kept forward elimination
  PetscErrorScope err;
  err.check(MatSolve(F_, b, x), "MatSolve");
}

void SchurSolve::run_phase(int phase)
{
  DMUMPS_STRUC_C* id = checked_mumps(F_, N_, dofs_);
  // What PETSc owns (REDRHS) or sets itself before each of its solves is put back after.
  double* rhs = id->rhs;
  double* redrhs = id->redrhs;
  const int lredrhs = id->lredrhs, nrhs = id->nrhs, lrhs = id->lrhs;
  const int icntl20 = id->icntl[19], icntl21 = id->icntl[20];
  id->rhs = rhs_.data();
  id->redrhs = redrhs_.data();
  id->lredrhs = static_cast<int>(n_c_);
  id->nrhs = 1;
  id->lrhs = static_cast<int>(N_);
  id->icntl[19] = 0; // dense centralised right-hand side
  id->icntl[20] = 0; // centralised solution, in RHS
  id->icntl[25] = phase;
  id->job = 3;
  dmumps_c(id);
  const int infog1 = id->infog[0], infog2 = id->infog[1];
  id->rhs = rhs;
  id->redrhs = redrhs;
  id->lredrhs = lredrhs;
  id->nrhs = nrhs;
  id->lrhs = lrhs;
  id->icntl[19] = icntl20;
  id->icntl[20] = icntl21;
  id->icntl[25] = -1; // PETSc's mark: its MatSolve runs both halves and the Schur solve
  if (infog1 < 0)
    throw MumpsError(std::string("MUMPS failed in the ") + (phase == 1 ? "condensation" : "expansion")
                         + " of a solve: INFOG(1)=" + std::to_string(infog1)
                         + ", INFOG(2)=" + std::to_string(infog2),
                     infog1);
}

std::vector<double> SchurSolve::condense(Vec b)
{
  PetscErrorScope err;
  check_rows(err, b, N_, "condense: b");
  condensed_ = false;
  rhs_.resize(static_cast<std::size_t>(N_));
  redrhs_.assign(static_cast<std::size_t>(n_c_), 0.0);
  const PetscScalar* a = nullptr;
  err.check(VecGetArrayRead(b, &a), "VecGetArrayRead");
  std::copy(a, a + N_, rhs_.begin());
  err.check(VecRestoreArrayRead(b, &a), "VecRestoreArrayRead");
  run_phase(1);
  condensed_ = true;
  return redrhs_;
}

void SchurSolve::expand(std::span<const double> u_c, Vec x)
{
  if (!condensed_)
    throw std::logic_error("expand: no condense() before it (each condensation serves one "
                           "expansion; a solve in between replaces it)");
  if (static_cast<PetscInt>(u_c.size()) != n_c_)
    throw std::invalid_argument("expand: u_c has " + std::to_string(u_c.size())
                                + " entries, expected n_c = " + std::to_string(n_c_));
  PetscErrorScope err;
  check_rows(err, x, N_, "expand: x");
  std::copy(u_c.begin(), u_c.end(), redrhs_.begin());
  condensed_ = false;
  run_phase(2);
  PetscScalar* a = nullptr;
  err.check(VecGetArrayWrite(x, &a), "VecGetArrayWrite");
  std::copy(rhs_.begin(), rhs_.end(), a);
  err.check(VecRestoreArrayWrite(x, &a), "VecRestoreArrayWrite");
}
