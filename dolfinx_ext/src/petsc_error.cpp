// Copyright flexcontact developers. MIT licence.

#include "petsc_error.h"

using namespace flexcontact;

PetscErrorScope::PetscErrorScope() { PetscPushErrorHandler(&PetscErrorScope::handler, this); }

PetscErrorScope::~PetscErrorScope() { PetscPopErrorHandler(); }

PetscErrorCode PetscErrorScope::handler(MPI_Comm, int line, const char* func, const char* file,
                                        PetscErrorCode n, PetscErrorType p, const char* mess,
                                        void* ctx)
{
  auto* self = static_cast<PetscErrorScope*>(ctx);
  // The first call of a chain is the origin (PETSC_ERROR_INITIAL); the rest is traceback.
  if (!self->recorded_)
  {
    const char* text = nullptr;
    PetscErrorMessage(n, &text, nullptr);
    self->message_ = std::string(text ? text : "PETSc error") + ": "
                     + std::string(mess ? mess : "") + " (in " + std::string(func ? func : "?")
                     + ", " + std::string(file ? file : "?") + ":" + std::to_string(line) + ")";
    self->recorded_ = true;
  }
  (void)p;
  return n;
}

void PetscErrorScope::check(PetscErrorCode ierr, const char* call)
{
  if (ierr == 0)
    return;
  std::string what = std::string(call) + " failed: "
                     + (recorded_ ? message_ : "PETSc error code " + std::to_string(ierr));
  message_.clear();
  recorded_ = false;
  throw PetscError(what, ierr);
}
