// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file petsc_error.h
/// @brief PETSc errors as C++ exceptions, with PETSc's own message, never an abort.

#include <petscsys.h>
#include <stdexcept>
#include <string>

namespace flexcontact
{
/// @brief Thrown for a failing PETSc call; what() holds PETSc's message.
class PetscError : public std::runtime_error
{
public:
  PetscError(const std::string& what, PetscErrorCode code)
      : std::runtime_error(what), code(code) {}
  PetscErrorCode code; ///< the PETSc error code
};

/// @brief While alive, PETSc errors are recorded (first message kept) instead of printed,
/// so that check() can raise them. Push/pop are scoped; nests with other handlers.
class PetscErrorScope
{
public:
  PetscErrorScope();
  ~PetscErrorScope();
  PetscErrorScope(const PetscErrorScope&) = delete;
  PetscErrorScope& operator=(const PetscErrorScope&) = delete;

  /// @brief Throw PetscError if ierr is nonzero, naming the call and PETSc's reason.
  void check(PetscErrorCode ierr, const char* call);

private:
  static PetscErrorCode handler(MPI_Comm comm, int line, const char* func, const char* file,
                                PetscErrorCode n, PetscErrorType p, const char* mess,
                                void* ctx);
  std::string message_;
  bool recorded_ = false;
};
} // namespace flexcontact
