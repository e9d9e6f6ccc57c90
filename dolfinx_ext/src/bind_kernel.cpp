// Copyright flexcontact developers. MIT licence.

/// @file bind_kernel.cpp
/// @brief Thin Python bindings of the kernel (kernel/include/flexcontact), numpy in and out.

#include "bindings.h"

#include <flexcontact/increment.hpp>
#include <flexcontact/pairs.hpp>
#include <flexcontact/problem.hpp>
#include <flexcontact/problem_file.hpp>
#include <flexcontact/residual.hpp>
#include <flexcontact/solvers.hpp>

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace py = pybind11;
using namespace flexcontact;

namespace
{
using IntArray = py::array_t<int, py::array::c_style | py::array::forcecast>;

/// @brief Pair states as a numpy int array (PairState's values: 1 open, 2 stick, 3 slip).
py::array_t<int> states_to_array(const std::vector<PairState>& s)
{
  py::array_t<int> a(s.size());
  for (std::size_t i = 0; i < s.size(); ++i)
    a.mutable_at(i) = static_cast<int>(s[i]);
  return a;
}

/// @brief Pair states from a numpy int array or None (empty).
std::vector<PairState> states_from(const std::optional<IntArray>& a)
{
  std::vector<PairState> s;
  if (!a)
    return s;
  for (py::ssize_t i = 0; i < a->size(); ++i)
  {
    int v = a->data()[i];
    if (v < static_cast<int>(PairState::open) or v > static_cast<int>(PairState::slip))
      throw std::invalid_argument("pair state " + std::to_string(v)
                                  + " is not 1 (open), 2 (stick) or 3 (slip)");
    s.push_back(static_cast<PairState>(v));
  }
  return s;
}

/// @brief Check the sizes of one local problem u = W λ + q with friction μ.
void check_problem(int dim, const Matrix& W, const Vector& q, const Vector& mu,
                   const Vector& lambda0, std::size_t n_states = 0)
{
  if (dim != 2 and dim != 3)
    throw std::invalid_argument("dim must be 2 or 3, got " + std::to_string(dim));
  const auto n = q.size();
  if (n != dim * mu.size())
    throw std::invalid_argument("q has " + std::to_string(n) + " entries, expected dim·m = "
                                + std::to_string(dim * mu.size()));
  if (W.rows() != n or W.cols() != n)
    throw std::invalid_argument("W is " + std::to_string(W.rows()) + "x"
                                + std::to_string(W.cols()) + ", expected " + std::to_string(n)
                                + "x" + std::to_string(n));
  if (lambda0.size() != 0 and lambda0.size() != n)
    throw std::invalid_argument("lambda0 has " + std::to_string(lambda0.size())
                                + " entries, expected 0 or " + std::to_string(n));
  if (n_states != 0 and n_states != static_cast<std::size_t>(mu.size()))
    throw std::invalid_argument("states0 has " + std::to_string(n_states)
                                + " entries, expected 0 or m = " + std::to_string(mu.size()));
}

Vector or_empty(const std::optional<Vector>& v) { return v ? *v : Vector(); }

/// @brief B as COO triplets (rows, cols, vals) and its shape.
py::tuple triplets(const Eigen::SparseMatrix<double>& B)
{
  std::vector<std::int64_t> rows, cols;
  std::vector<double> vals;
  for (int k = 0; k < B.outerSize(); ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(B, k); it; ++it)
    {
      rows.push_back(it.row());
      cols.push_back(it.col());
      vals.push_back(it.value());
    }
  return py::make_tuple(py::array_t<std::int64_t>(rows.size(), rows.data()),
                        py::array_t<std::int64_t>(cols.size(), cols.data()),
                        py::array_t<double>(vals.size(), vals.data()),
                        py::make_tuple(B.rows(), B.cols()));
}

/// @brief B from COO triplets (duplicates summed).
Eigen::SparseMatrix<double> from_triplets(const py::array_t<std::int64_t>& rows,
                                          const py::array_t<std::int64_t>& cols,
                                          const py::array_t<double>& vals,
                                          std::pair<std::int64_t, std::int64_t> shape)
{
  if (rows.size() != cols.size() or rows.size() != vals.size())
    throw std::invalid_argument("rows, cols and vals must have the same length");
  std::vector<Eigen::Triplet<double>> t;
  for (py::ssize_t i = 0; i < rows.size(); ++i)
  {
    auto r = rows.data()[i], c = cols.data()[i];
    if (r < 0 or r >= shape.first or c < 0 or c >= shape.second)
      throw std::invalid_argument("triplet (" + std::to_string(r) + ", " + std::to_string(c)
                                  + ") outside the shape");
    t.emplace_back(r, c, vals.data()[i]);
  }
  Eigen::SparseMatrix<double> B(shape.first, shape.second);
  B.setFromTriplets(t.begin(), t.end());
  return B;
}

std::string report_repr(const SolveReport& r)
{
  std::ostringstream s;
  s << "SolveReport(solver='" << r.solver << "', converged=" << (r.converged ? "True" : "False")
    << ", iterations=" << r.iterations << ", state_changes=" << r.state_changes
    << ", residual=" << r.residual << ", cycled=" << (r.cycled ? "True" : "False")
    << ", pairs=" << r.states.size() << ")";
  return s.str();
}

/// @brief ConvergenceError, raised with the best report as its attribute `report`.
void bind_errors(py::module& m)
{
  static py::exception<ConvergenceError> convergence_error(m, "ConvergenceError",
                                                           m.attr("SolveError"));
  py::register_local_exception_translator(
      [](std::exception_ptr p)
      {
        try
        {
          if (p)
            std::rethrow_exception(p);
        }
        catch (const ConvergenceError& e)
        {
          // The exception carries the best report as attribute `report`.
          py::object type = py::reinterpret_borrow<py::object>(convergence_error.ptr());
          const SavedProblem saved = save_failed_problem(e);
          py::object inst = type(std::string(e.what()) + saved.note);
          inst.attr("report") = py::cast(e.report);
          inst.attr("problem_path") = saved.path;
          PyErr_SetObject(convergence_error.ptr(), inst.ptr());
        }
      });
}

} // namespace

py::handle flexcontact::bind_error_bases(py::module& m)
{
  // The classes live in Python (flexcontact/errors.py), so that the package's own errors
  // and the compiled ones share one base; the module holds them for its lifetime.
  py::module_ errors = py::module_::import("flexcontact.errors");
  m.attr("SolveError") = errors.attr("SolveError");
  m.attr("InputError") = errors.attr("InputError");
  // Local to this module: a global translator would also turn other pybind11 modules'
  // errors (DOLFINx's, matplotlib's, and pybind11's own builtin exceptions, which are
  // std::runtime_errors) into flexcontact's.
  py::register_local_exception_translator(
      [](std::exception_ptr p)
      {
        try
        {
          if (p)
            std::rethrow_exception(p);
        }
        catch (const py::builtin_exception&)
        {
          throw; // pybind11's own (value_error, index_error, ...): its default translation
        }
        catch (const std::invalid_argument& e)
        {
          py::object cls = py::module_::import("flexcontact._cpp").attr("InputError");
          PyErr_SetString(cls.ptr(), e.what());
        }
        catch (const std::runtime_error& e)
        {
          py::object cls = py::module_::import("flexcontact._cpp").attr("SolveError");
          PyErr_SetString(cls.ptr(), e.what());
        }
        catch (const std::logic_error& e)
        {
          py::object cls = py::module_::import("flexcontact._cpp").attr("SolveError");
          PyErr_SetString(cls.ptr(), e.what());
        }
      });
  return m.attr("SolveError");
}

namespace
{
/// @brief problem.hpp: PairState, SolverOptions, SolveReport.
void bind_problem(py::module& m)
{
  py::enum_<PairState>(m, "PairState",
                       "Contact state of a pair, one coding end to end (flexcontact.states)")
      .value("none", PairState::none)
      .value("open", PairState::open)
      .value("stick", PairState::stick)
      .value("slip", PairState::slip)
      .value("crush", PairState::crush);

  py::class_<SolverOptions>(m, "SolverOptions", "Options shared by every local solver")
      .def(py::init<>())
      .def(py::init(
               [](double tolerance, int max_iterations, std::vector<std::string> chain,
                  bool verbose, double work_budget_gflop)
               {
                 if (!(work_budget_gflop >= 0.0) || !std::isfinite(work_budget_gflop))
                   throw std::invalid_argument("SolverOptions: work_budget_gflop = "
                                               + std::to_string(work_budget_gflop)
                                               + "; it must be 0 (automatic) or positive");
                 SolverOptions o;
                 o.tolerance = tolerance;
                 o.max_iterations = max_iterations;
                 o.chain = std::move(chain);
                 o.verbose = verbose;
                 o.work_budget_gflop = work_budget_gflop;
                 return o;
               }),
           py::arg("tolerance") = 1e-10, py::arg("max_iterations") = 100,
           py::arg("chain") = std::vector<std::string>(), py::arg("verbose") = false,
           py::arg("work_budget_gflop") = 0.0)
      .def_readwrite("tolerance", &SolverOptions::tolerance)
      .def_readwrite("max_iterations", &SolverOptions::max_iterations)
      .def_readwrite("chain", &SolverOptions::chain)
      .def_readwrite("verbose", &SolverOptions::verbose)
      .def_readwrite("work_budget_gflop", &SolverOptions::work_budget_gflop,
                     "Work limit in Gflop, estimated from the sizes of the dense kernels (not "
                     "time: the same answer under any load). A solver alone stops at it (0: "
                     "none); the chain shares it among its attempts (0: "
                     "chain_work_budget_gflop(n))")
      .def("__repr__",
           [](const SolverOptions& o)
           {
             std::ostringstream s;
             s << "SolverOptions(tolerance=" << o.tolerance
               << ", max_iterations=" << o.max_iterations << ", chain=[";
             for (std::size_t i = 0; i < o.chain.size(); ++i)
               s << (i ? ", " : "") << "'" << o.chain[i] << "'";
             s << "], verbose=" << (o.verbose ? "True" : "False")
               << ", work_budget_gflop=" << o.work_budget_gflop << ")";
             return s.str();
           });

  py::class_<SolveReport>(m, "SolveReport", "What a local solver did and found")
      .def(py::init<>())
      .def_readonly("lambda_", &SolveReport::lambda)
      .def_property_readonly("lambda", [](const SolveReport& r) { return r.lambda; })
      .def_readonly("u", &SolveReport::u)
      .def_property_readonly("states", [](const SolveReport& r) { return states_to_array(r.states); })
      .def_readonly("solver", &SolveReport::solver)
      .def_readonly("iterations", &SolveReport::iterations)
      .def_readonly("state_changes", &SolveReport::state_changes)
      .def_readonly("work_gflop", &SolveReport::work_gflop,
                    "Estimated work done (Gflop): this solver's, or the whole chain's")
      .def_readonly("residual", &SolveReport::residual)
      .def_readonly("converged", &SolveReport::converged)
      .def_readonly("cycled", &SolveReport::cycled)
      .def_readonly("attempts", &SolveReport::attempts)
      .def("__repr__", &report_repr);
}

/// @brief pairs.hpp: ContactPair, frames, the gap operator B, x0 and W.
void bind_pairs(py::module& m)
{
  py::class_<ContactPair>(m, "ContactPair", "One slave node against a master point")
      .def(py::init<>())
      .def(py::init(
               [](int slave, std::vector<int> masters, std::vector<double> weights,
                  const Matrix& frame)
               {
                 ContactPair p;
                 p.slave = slave;
                 p.masters = std::move(masters);
                 p.weights = std::move(weights);
                 p.frame = frame;
                 return p;
               }),
           py::arg("slave"), py::arg("masters"), py::arg("weights"), py::arg("frame"))
      .def_readwrite("slave", &ContactPair::slave)
      .def_readwrite("masters", &ContactPair::masters)
      .def_readwrite("weights", &ContactPair::weights)
      .def_readwrite("frame", &ContactPair::frame)
      .def_readwrite("offset", &ContactPair::offset,
                     "Normal distance of the master surface from the master point [m]");

  m.def(
      "frame_from_normal", [](const Vector& n) { return frame_from_normal(n); }, py::arg("n"),
      "Local frame (rows n, t[, t2]) from a unit outward normal");

  m.def(
      "gap_operator",
      [](int dim, int n_nodes, const std::vector<ContactPair>& pairs)
      { return triplets(gap_operator(dim, n_nodes, pairs)); },
      py::arg("dim"), py::arg("n_nodes"), py::arg("pairs"),
      "B as (rows, cols, vals, shape) COO triplets; row block k is T_k (e_s - sum_j w_j e_j)");

  m.def(
      "initial_gap",
      [](const std::vector<ContactPair>& pairs, const Matrix& X) { return initial_gap(pairs, X); },
      py::arg("pairs"), py::arg("X"), "x0_k = T_k (X_s - sum_j w_j X_j); X is n_nodes x d");

  m.def(
      "delassus",
      [](const std::vector<ContactPair>& pairs, int n_nodes, int dim, const Matrix& F)
      { return delassus(gap_operator(dim, n_nodes, pairs), F); },
      py::arg("pairs"), py::arg("n_nodes"), py::arg("dim"), py::arg("F"),
      "W = B F* B^T (symmetrised) with B built from the pairs");
  m.def(
      "delassus",
      [](const py::array_t<std::int64_t>& rows, const py::array_t<std::int64_t>& cols,
         const py::array_t<double>& vals, std::pair<std::int64_t, std::int64_t> shape,
         const Matrix& F)
      {
        if (F.rows() != shape.second or F.cols() != shape.second)
          throw std::invalid_argument("F is " + std::to_string(F.rows()) + "x"
                                      + std::to_string(F.cols()) + ", B has "
                                      + std::to_string(shape.second) + " columns");
        return delassus(from_triplets(rows, cols, vals, shape), F);
      },
      py::arg("rows"), py::arg("cols"), py::arg("vals"), py::arg("shape"), py::arg("F"),
      "W = B F* B^T (symmetrised) with B given as COO triplets");
}

/// @brief The caps of a problem's normal forces (problem.hpp) as a view's pointer: null for
/// none; checked to have one entry per pair, each > 0 (+inf: no cap).
const double* cap_pointer(const std::optional<Vector>& cap, const Vector& q, int dim)
{
  if (!cap || cap->size() == 0)
    return nullptr;
  if (cap->size() * dim != q.size())
    throw std::invalid_argument("cap has " + std::to_string(cap->size())
                                + " entries; it needs one per pair (" + std::to_string(q.size() / dim)
                                + ")");
  for (Eigen::Index k = 0; k < cap->size(); ++k)
    if (!((*cap)[k] > 0.0))
      throw std::invalid_argument("cap[" + std::to_string(k) + "] is "
                                  + std::to_string((*cap)[k])
                                  + "; a normal force cap must be > 0 (inf: no cap)");
  return cap->data();
}

/// @brief residual.hpp: the cone projection, the natural-map residual and the states.
void bind_residual(py::module& m)
{
  m.def(
      "project_on_cone",
      [](Vector r, double mu)
      {
        const int dim = static_cast<int>(r.size());
        if (dim != 2 and dim != 3)
          throw std::invalid_argument("a pair force has 2 or 3 entries");
        project_on_cone(r.data(), dim, mu);
        return r;
      },
      py::arg("r"), py::arg("mu"), "Projection of one pair's force onto the Coulomb cone");

  m.def(
      "project_on_truncated_cone",
      [](Vector r, double mu, double cap)
      {
        const int dim = static_cast<int>(r.size());
        if (dim != 2 and dim != 3)
          throw std::invalid_argument("a pair force has 2 or 3 entries");
        project_on_truncated_cone(r.data(), dim, mu, cap);
        return r;
      },
      py::arg("r"), py::arg("mu"), py::arg("cap"),
      "Projection of one pair's force onto the Coulomb cone truncated at r_n <= cap");

  m.def(
      "natural_map_residual",
      [](int dim, const Matrix& W, const Vector& q, const Vector& mu, const Vector& lambda,
         const std::optional<Vector>& cap)
      {
        check_problem(dim, W, q, mu, lambda);
        if (lambda.size() != q.size())
          throw std::invalid_argument("lambda must have as many entries as q");
        ProblemView p{dim, W, q, mu, cap_pointer(cap, q, dim)};
        return natural_map_residual(p, lambda);
      },
      py::arg("dim"), py::arg("W"), py::arg("q"), py::arg("mu"), py::arg("lam"),
      py::arg("cap") = py::none(),
      "Relative natural-map residual of lambda for u = W lambda + q (0 for a solution)");

  m.def(
      "classify_states",
      [](int dim, const Matrix& W, const Vector& q, const Vector& mu, const Vector& lambda,
         double tol, const std::optional<Vector>& cap)
      {
        check_problem(dim, W, q, mu, lambda);
        if (lambda.size() != q.size())
          throw std::invalid_argument("lambda must have as many entries as q");
        ProblemView p{dim, W, q, mu, cap_pointer(cap, q, dim)};
        Vector u = W * lambda + q;
        return states_to_array(classify_states(p, lambda, u, tol));
      },
      py::arg("dim"), py::arg("W"), py::arg("q"), py::arg("mu"), py::arg("lam"),
      py::arg("tol") = 1e-8, py::arg("cap") = py::none(),
      "Pair states (1 open, 2 stick, 3 slip, 4 crush) read from lambda");
}

/// @brief solvers.hpp: the chain and each local solver alone.
void bind_solvers(py::module& m)
{
  // Every solver takes the same Python arguments (states0 is ignored by those that do not
  // use states), checked once here, and runs without the GIL.
  auto def_solver = [&m](const char* name, auto solver, const char* doc)
  {
    m.def(
        name,
        [solver](int dim, const Matrix& W, const Vector& q, const Vector& mu,
                 const std::optional<Vector>& lambda0, const std::optional<IntArray>& states0,
                 const SolverOptions& options, const std::optional<Vector>& cap)
        {
          Vector l0 = or_empty(lambda0);
          auto s0 = states_from(states0);
          check_problem(dim, W, q, mu, l0, s0.size());
          ProblemView p{dim, W, q, mu, cap_pointer(cap, q, dim)};
          py::gil_scoped_release release;
          return solver(p, l0, s0, options);
        },
        py::arg("dim"), py::arg("W"), py::arg("q"), py::arg("mu"),
        py::arg("lambda0") = py::none(), py::arg("states0") = py::none(),
        py::arg("options") = SolverOptions(), py::arg("cap") = py::none(), doc);
  };
  using States = std::vector<PairState>;
  def_solver(
      "solve",
      [](const ProblemView& p, const Vector& l0, const States& s0, const SolverOptions& o)
      { return solve(p, l0, s0, o); },
      "Try the solvers of options.chain in order until one converges; returns a SolveReport");
  def_solver(
      "solve_active_set",
      [](const ProblemView& p, const Vector& l0, const States& s0, const SolverOptions& o)
      { return solve_active_set(p, l0, s0, o); },
      "Feng-Touzot active-set method (stick/slip/open rows)");
  def_solver(
      "solve_projection",
      [](const ProblemView& p, const Vector& l0, const States&, const SolverOptions& o)
      { return solve_projection(p, l0, o); },
      "De Saxce-Feng bi-potential projection (Gauss-Seidel over pairs)");
  def_solver(
      "solve_newton_ac",
      [](const ProblemView& p, const Vector& l0, const States&, const SolverOptions& o)
      { return solve_newton_ac(p, l0, o); },
      "Semi-smooth Newton on the Alart-Curnier formulation");

  m.def(
      "write_local_problem",
      [](const std::string& path, int dim, const Matrix& W, const Vector& q, const Vector& mu,
         const std::optional<Vector>& lambda_start, const std::optional<IntArray>& states_start,
         const SolverOptions& options, const std::optional<Vector>& cap,
         const std::string& source)
      {
        LocalProblem p{dim, W, q, mu, or_empty(cap), or_empty(lambda_start),
                       states_from(states_start), options, source};
        check_problem(dim, W, q, mu, p.lambda_start, p.states_start.size());
        cap_pointer(cap, q, dim);
        write_local_problem(path, p);
      },
      py::arg("path"), py::arg("dim"), py::arg("W"), py::arg("q"), py::arg("mu"),
      py::arg("lambda_start") = py::none(), py::arg("states_start") = py::none(),
      py::arg("options") = SolverOptions(), py::arg("cap") = py::none(),
      py::arg("source") = "",
      "Writes one local problem in format 3 of docs/solvers.md");
  m.def("solver_names", &solver_names, "Names accepted in SolverOptions.chain");
  m.def("default_chain", &default_chain, "Default solver order, most robust first");
  m.def("chain_work_budget_gflop", &chain_work_budget_gflop, py::arg("n"),
        "The chain's work budget (Gflop) for n unknowns when work_budget_gflop is 0 "
        "(docs/solvers.md)");
}

/// @brief increment.hpp: the incremental driver.
void bind_increment(py::module& m)
{
  py::class_<IncrementalSolver>(m, "IncrementalSolver",
                                "Incremental driver: W, mu and the history between increments")
      .def(py::init<int, Matrix, Vector, SolverOptions>(), py::arg("dim"), py::arg("W"),
           py::arg("mu"), py::arg("options") = SolverOptions())
      .def(
          "step",
          [](IncrementalSolver& s, const Vector& q)
          {
            py::gil_scoped_release release;
            return s.step(q);
          },
          py::arg("q"),
          "Solve one increment for the total q = B u_p + x0; returns a SolveReport. Raises "
          "ConvergenceError (history unchanged) if no solver converges")
      .def("local_q", &IncrementalSolver::local_q, py::arg("q"),
           "q' of the local problem u = W lambda + q' that step(q) solves next")
      .def("set_initial_gap", &IncrementalSolver::set_initial_gap, py::arg("x0"),
           "Gap before the first increment; the first increment's slip is measured from it")
      .def("gap", [](const IncrementalSolver& s) { return s.gap(); }, "Total gap x of the last increment")
      .def("force", [](const IncrementalSolver& s) { return s.force(); }, "lambda of the last increment")
      .def("states", [](const IncrementalSolver& s) { return states_to_array(s.states()); },
           "Pair states of the last increment (1 open, 2 stick, 3 slip, 4 crush)")
      .def("last", [](const IncrementalSolver& s) { return s.last(); }, "Report of the last increment")
      .def("set_crushing", &IncrementalSolver::set_crushing, py::arg("cap"),
           py::arg("crush_depth"),
           "Caps of the pairs' normal forces (inf: none) and their crush depths so far [m]")
      .def_property_readonly("crush_depth",
                             [](const IncrementalSolver& s) { return s.crush_depth(); })
      .def_property_readonly("crush_work", &IncrementalSolver::crush_work)
      .def("pairs", &IncrementalSolver::pairs)
      .def("dim", &IncrementalSolver::dim)
      .def_property_readonly("W", [](const IncrementalSolver& s) { return s.W(); });
}
} // namespace

void flexcontact::bind_kernel(py::module& m)
{
  bind_errors(m);
  bind_problem(m);
  bind_pairs(m);
  bind_residual(m);
  bind_solvers(m);
  bind_increment(m);
  bind_condensed(m);
  bind_impact(m);
  bind_problem_file(m);
  bind_split_cholesky(m);
}
