// Copyright flexcontact developers. MIT licence.

/// @file bind_convert.cpp
/// @brief Kernel results as NumPy arrays and dicts, shared by the step bindings.

#include "bindings.h"

#include <flexcontact/condensed.hpp>

#include <pybind11/stl.h>

#include <cstring>

namespace py = pybind11;

namespace flexcontact
{
py::array_t<double> rows_of(const Vector& v, Eigen::Index cols)
{
  const Eigen::Index m = cols ? v.size() / cols : 0;
  py::array_t<double> a({static_cast<py::ssize_t>(m), static_cast<py::ssize_t>(cols)});
  if (v.size())
    std::memcpy(a.mutable_data(), v.data(), sizeof(double) * v.size());
  return a;
}

py::array_t<int> states_array(const std::vector<PairState>& s)
{
  py::array_t<int> a(static_cast<py::ssize_t>(s.size()));
  for (std::size_t i = 0; i < s.size(); ++i)
    a.mutable_at(i) = static_cast<int>(s[i]);
  return a;
}

py::array_t<double> frames_array(const std::vector<ContactPair>& pairs, int dim)
{
  const auto m = static_cast<py::ssize_t>(pairs.size());
  py::array_t<double> a({m, static_cast<py::ssize_t>(dim), static_cast<py::ssize_t>(dim)});
  auto v = a.mutable_unchecked<3>();
  for (py::ssize_t k = 0; k < m; ++k)
    for (int i = 0; i < dim; ++i)
      for (int j = 0; j < dim; ++j)
        v(k, i, j) = pairs[static_cast<std::size_t>(k)].frame(i, j);
  return a;
}

py::dict report_dict(const SolveReport& r)
{
  py::dict d;
  d["solver"] = r.solver;
  d["converged"] = r.converged;
  d["iterations"] = r.iterations;
  d["state_changes"] = r.state_changes;
  d["work_gflop"] = r.work_gflop;
  d["residual"] = r.residual;
  d["cycled"] = r.cycled;
  d["attempts"] = r.attempts;
  if (r.alpha.size())
  {
    // Bordered problems: the best iterate, read by the no-equilibrium diagnosis.
    d["lambda"] = py::array_t<double>(r.lambda.size(), r.lambda.data());
    d["alpha"] = py::array_t<double>(r.alpha.size(), r.alpha.data());
  }
  return d;
}

std::vector<bool> flags(const std::optional<BoolArray>& a)
{
  if (!a)
    return {};
  return std::vector<bool>(a->data(), a->data() + a->size());
}

void raise_convergence_error(py::handle cls, const ConvergenceError& e)
{
  const SavedProblem saved = save_failed_problem(e);
  py::object error = cls(std::string(e.what()) + saved.note);
  error.attr("report") = report_dict(e.report);
  error.attr("problem_path") = saved.path;
  PyErr_SetObject(cls.ptr(), error.ptr());
  throw py::error_already_set();
}

py::dict condensed_step_dict(const CondensedStep& r, int dim)
{
  py::dict d;
  d["lambda"] = rows_of(r.lambda, dim);
  d["gap"] = rows_of(r.gap, dim);
  d["slip"] = rows_of(r.slip, dim - 1);
  d["states"] = states_array(r.states);
  d["reaction"] = py::array_t<double>(r.reaction.size(), r.reaction.data());
  d["local_q"] = py::array_t<double>(r.local_q.size(), r.local_q.data());
  d["solution_c"] = py::array_t<double>(r.solution_c.size(), r.solution_c.data());
  d["normal_force"] = r.normal_force;
  d["tangential_force"] = py::array_t<double>(r.tangential_force.size(),
                                              r.tangential_force.data());
  d["max_penetration"] = r.max_penetration;
  if (r.crush_depth.size() > 0)
  {
    d["crush_depth"] = py::array_t<double>(r.crush_depth.size(), r.crush_depth.data());
    d["crush_work"] = r.crush_work;
  }
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> t
      = r.pair_tangential;
  d["pair_tangential"] = py::array_t<double>({t.rows(), t.cols()}, t.data());
  d["report"] = report_dict(r.report);
  d["alpha"] = py::array_t<double>(r.alpha.size(), r.alpha.data());
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> n
      = r.undetermined;
  d["undetermined"] = py::array_t<double>({n.rows(), n.cols()}, n.data());
  return d;
}
} // namespace flexcontact
