// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file bindings.h
/// @brief Declarations of the parts of the `flexcontact._cpp` module.

#include <pybind11/pybind11.h>

namespace flexcontact
{
/// @brief The flexibility F* from one MUMPS factorization, and the PETSc/MUMPS exceptions.
void bind_petsc(pybind11::module& m);

/// @brief The kernel: pairs, frames, gap operator, W, local solvers, incremental driver.
void bind_kernel(pybind11::module& m);

/// @brief The condensed contact problem (called by bind_kernel, after ConvergenceError).
void bind_condensed(pybind11::module& m);

/// @brief The Moreau–Jean contact step (kernel/.../impact.hpp).
void bind_impact(pybind11::module& m);
} // namespace flexcontact
