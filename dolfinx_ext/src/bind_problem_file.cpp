// Copyright flexcontact developers. MIT licence.

/// @file bind_problem_file.cpp
/// @brief problem_file.hpp in Python: a failing local problem saved as a file, read back
/// and re-run (flexcontact.load_problem).

#include "bindings.h"

#include <flexcontact/increment.hpp>
#include <flexcontact/problem_file.hpp>
#include <flexcontact/solvers.hpp>

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <string>

namespace py = pybind11;

namespace flexcontact
{
SavedProblem save_failed_problem(const ConvergenceError& e)
{
  SavedProblem saved{"", py::none()};
  if (!e.problem)
    return saved;
  try
  {
    const std::string bytes = local_problem_bytes(*e.problem);
    saved.path = py::module_::import("flexcontact.problem_files")
                     .attr("save_failed")(py::bytes(bytes));
    const std::string path = py::str(saved.path).cast<std::string>();
    saved.note = "\nThe local problem is saved in " + path
                 + ": flexcontact.load_problem(path).solve() re-runs it (attach the file to "
                   "a bug report).";
  }
  catch (py::error_already_set& err)
  {
    saved.note = std::string("\n(The local problem could not be saved: ") + err.what() + ")";
  }
  catch (const std::exception& err)
  {
    saved.note = std::string("\n(The local problem could not be saved: ") + err.what() + ")";
  }
  return saved;
}

void bind_problem_file(py::module& m)
{
  py::class_<LocalProblem>(m, "LocalProblem",
                           "One local problem u = W lambda + q as solve() was given it: W, q, "
                           "mu, the caps, the start and the options (docs/solvers.md)")
      .def_readonly("dim", &LocalProblem::dim)
      .def_readonly("W", &LocalProblem::W)
      .def_readonly("q", &LocalProblem::q)
      .def_readonly("mu", &LocalProblem::mu)
      .def_property_readonly("cap",
                             [](const LocalProblem& p) -> py::object
                             { return p.cap.size() ? py::cast(p.cap) : py::none(); })
      .def_readonly("lambda_start", &LocalProblem::lambda_start)
      .def_property_readonly("states_start",
                             [](const LocalProblem& p) { return states_array(p.states_start); })
      .def_readonly("options", &LocalProblem::options)
      .def_readonly("source", &LocalProblem::source)
      .def_property_readonly("pairs", &LocalProblem::pairs)
      .def(
          "solve",
          [](const LocalProblem& p)
          {
            py::gil_scoped_release release;
            return solve(p);
          },
          "solve() from the stored start with the stored options; returns a SolveReport")
      .def("__repr__",
           [](const LocalProblem& p)
           {
             return "LocalProblem(dim=" + std::to_string(p.dim) + ", pairs="
                    + std::to_string(p.pairs()) + ", caps=" + (p.cap.size() ? "yes" : "no")
                    + ", source='" + p.source + "')";
           });
  m.def(
      "read_local_problem",
      [](const std::string& path)
      {
        try
        {
          return read_local_problem(path);
        }
        catch (const std::runtime_error& e)
        {
          throw py::value_error(e.what());
        }
      },
      py::arg("path"), "Reads a local-problem file (formats 2 and 3 of docs/solvers.md)");
}
} // namespace flexcontact
