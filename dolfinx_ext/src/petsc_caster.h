// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file petsc_caster.h
/// @brief petsc4py Mat <-> PETSc Mat for pybind11, through petsc4py's own C API.
///
/// DOLFINx ships such casters for pybind11 up to 0.7 and for nanobind from 0.8 on, so the
/// module carries its own: the binding then takes petsc4py objects whatever DOLFINx
/// generation made them, and no DOLFINx type crosses it.

#include <petsc4py/petsc4py.h>
#include <petscmat.h>
#include <pybind11/pybind11.h>

#include <stdexcept>

namespace flexcontact
{
/// @brief Load petsc4py's C API once (import_petsc4py); throws if petsc4py is missing.
inline void require_petsc4py()
{
  static const bool loaded = []
  {
    if (import_petsc4py() != 0)
      throw std::runtime_error("flexcontact: cannot import petsc4py's C API");
    return true;
  }();
  (void)loaded;
}
} // namespace flexcontact

namespace pybind11::detail
{
template <>
class type_caster<_p_Mat>
{
public:
  PYBIND11_TYPE_CASTER(Mat, const_name("petsc4py.PETSc.Mat"));

  bool load(handle src, bool)
  {
    flexcontact::require_petsc4py();
    if (PyObject_TypeCheck(src.ptr(), &PyPetscMat_Type) == 0)
      return false;
    value = PyPetscMat_Get(src.ptr());
    return true;
  }

  /// With take_ownership the C++ side's reference passes to the new Python object
  /// (petsc4py adds one of its own).
  static handle cast(Mat src, return_value_policy policy, handle parent)
  {
    flexcontact::require_petsc4py();
    PyObject* obj = PyPetscMat_New(src);
    if (policy == return_value_policy::take_ownership)
      PetscObjectDereference(reinterpret_cast<PetscObject>(src));
    else if (policy == return_value_policy::reference_internal)
      keep_alive_impl(obj, parent);
    return handle(obj);
  }

  operator Mat() { return value; }
};

/// petsc4py Vec -> PETSc Vec (arguments only: no Vec is handed back).
template <>
class type_caster<_p_Vec>
{
public:
  PYBIND11_TYPE_CASTER(Vec, const_name("petsc4py.PETSc.Vec"));
  bool load(handle src, bool)
  {
    flexcontact::require_petsc4py();
    if (PyObject_TypeCheck(src.ptr(), &PyPetscVec_Type) == 0)
      return false;
    value = PyPetscVec_Get(src.ptr());
    return true;
  }
  static handle cast(Vec, return_value_policy, handle)
  {
    throw cast_error("flexcontact: a PETSc Vec is not returned to Python");
  }
  operator Vec() { return value; }
};
} // namespace pybind11::detail
