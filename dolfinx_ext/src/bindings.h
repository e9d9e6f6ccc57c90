// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file bindings.h
/// @brief Declarations of the parts of the `flexcontact._cpp` module.

#include <flexcontact/increment.hpp>
#include <flexcontact/pairs.hpp>
#include <flexcontact/problem.hpp>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <optional>
#include <vector>

namespace flexcontact
{
/// @brief The Python base of the module's runtime errors, flexcontact.errors.SolveError
/// (a FlexcontactError and a RuntimeError), and the translation of the kernel's other
/// exceptions: std::invalid_argument to InputError (a ValueError), std::runtime_error and
/// std::logic_error to SolveError, for this module's functions only. Called first, so that
/// the specific errors registered later (also local) are tried before it.
pybind11::handle bind_error_bases(pybind11::module& m);

/// @brief The flexibility F* from one MUMPS factorization, and the PETSc/MUMPS exceptions.
void bind_petsc(pybind11::module& m);

/// @brief The kernel: pairs, frames, gap operator, W, local solvers, incremental driver.
void bind_kernel(pybind11::module& m);

/// @brief The condensed contact problem (called by bind_kernel, after ConvergenceError).
void bind_condensed(pybind11::module& m);

/// @brief The condensed contact problem with W applied through the factor of K
/// (kernel/.../operator_contact.hpp, factor_operator.h); after bind_kernel and bind_petsc.
void bind_operator(pybind11::module& m);

/// @brief The Moreau–Jean contact step (kernel/.../impact.hpp).
void bind_impact(pybind11::module& m);
/// @brief problem_file.hpp: LocalProblem, read_local_problem.
void bind_problem_file(pybind11::module& m);
/// @brief split_cholesky.hpp: a small body's sparse split factor.
void bind_split_cholesky(pybind11::module& m);

// Conversions shared by the step bindings (bind_convert.cpp): what crosses back to Python is
// plain NumPy and dicts, picklable so that rank 0 can broadcast it.

/// @brief A pair-by-pair vector (m·cols entries) as an m × cols array.
pybind11::array_t<double> rows_of(const Vector& v, Eigen::Index cols);

/// @brief Pair states as an int array (PairState's values: 1 open, 2 stick, 3 slip).
pybind11::array_t<int> states_array(const std::vector<PairState>& s);

/// @brief The pairs' local frames T_k as an m × d × d array (rows n, t (, t2)).
pybind11::array_t<double> frames_array(const std::vector<ContactPair>& pairs, int dim);

/// @brief One increment of the condensed problem as a dict of NumPy arrays and numbers.
pybind11::dict condensed_step_dict(const struct CondensedStep& r, int dim);

/// @brief What a solver did, as a dict.
pybind11::dict report_dict(const SolveReport& r);

/// @brief A failing problem saved (flexcontact.problem_files.save_failed): the text added to
/// the error's message (empty if the error carries no problem), and the path (None if
/// none was saved).
struct SavedProblem
{
  std::string note;
  pybind11::object path;
};
SavedProblem save_failed_problem(const ConvergenceError& e);

/// @brief Raises `e` in Python as the module's ConvergenceError `cls`, its report attached as
/// a plain dict (attribute `report`), like a step's result.
[[noreturn]] void raise_convergence_error(pybind11::handle cls, const ConvergenceError& e);

/// @brief Runs one step of a contact object, `step()`, without the GIL (a step takes long and
/// may wait in MPI collectives), raising a ConvergenceError as the module's `cls`.
template <class Step>
auto step_or_raise(pybind11::handle cls, const Step& step) -> decltype(step())
{
  try
  {
    pybind11::gil_scoped_release release;
    return step();
  }
  catch (const ConvergenceError& e)
  {
    raise_convergence_error(cls, e);
  }
}

/// @brief Flags from Python (NumPy booleans, anything NumPy casts to them).
using BoolArray = pybind11::array_t<bool, pybind11::array::c_style | pybind11::array::forcecast>;

/// @brief The contact objects' `constrained` flags: None for none held.
std::vector<bool> flags(const std::optional<BoolArray>& a);
} // namespace flexcontact
