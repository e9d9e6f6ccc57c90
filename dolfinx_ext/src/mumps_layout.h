// Copyright flexcontact developers. MIT licence.
#pragma once

#include <dmumps_c.h>
#include <petsc/private/matimpl.h>
#include <petscversion.h>

namespace flexcontact
{
/// @brief The MUMPS structure that PETSc's MUMPS factor `F` passes to dmumps_c, or null.
///
/// PETSc keeps its MUMPS data first in the factor's data (Mat_MUMPS). Up to PETSc 3.23 that
/// data begins with MUMPS's own DMUMPS_STRUC_C, whose first field is SYM (0, 1 or 2). Later
/// PETSc, which can run MUMPS in another precision, begins it with a precision-neutral
/// wrapper: the precision (PetscPrecision, where PETSC_PRECISION_DOUBLE is 4 in PETSc 3.25)
/// then a pointer to the DMUMPS_STRUC_C it calls MUMPS with; its own copies of the call
/// fields are copied into that structure before each of its calls, and the fixed arrays
/// (ICNTL, INFOG, ...) are shared. The first int tells the two apart. Callers check what they
/// read (N, SYM, PAR, INFOG against PETSc's public queries) before they use it.
inline DMUMPS_STRUC_C* mumps_struct(Mat F)
{
  if (!F or !F->data)
    return nullptr;
  const int first = *static_cast<const int*>(F->data);
  if (first == 0 or first == 1 or first == 2)
    return static_cast<DMUMPS_STRUC_C*>(F->data);
#if PETSC_VERSION_GE(3, 24, 0)
  struct Wrapper
  {
    int precision;
    void* internal_id;
  };
  if (first == static_cast<int>(PETSC_PRECISION_DOUBLE))
    return static_cast<DMUMPS_STRUC_C*>(static_cast<const Wrapper*>(F->data)->internal_id);
#endif
  return nullptr; // MUMPS in another precision, or a layout this code does not know
}
} // namespace flexcontact
