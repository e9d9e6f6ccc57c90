// Copyright flexcontact developers. MIT licence.

#include "bindings.h"

PYBIND11_MODULE(_cpp, m)
{
  m.doc() = "flexcontact C++ kernel and DOLFINx/PETSc bridge";
  flexcontact::bind_error_bases(m);
  flexcontact::bind_kernel(m);
  flexcontact::bind_petsc(m);
  flexcontact::bind_operator(m);
}
