// Copyright flexcontact developers. MIT licence.

/// @file bind_petsc.cpp
/// @brief Python bindings of the PETSc/MUMPS side: the flexibility F* and its errors.
///
/// Only petsc4py objects and NumPy arrays cross here (petsc_caster.h), never a DOLFINx type:
/// the Python layer of DOLFINx 0.9 is built with nanobind, whose objects pybind11 cannot take.

#include "bindings.h"
#include "collective.h"
#include "distributed_schur.h"
#include "flexibility.h"
#include "petsc_caster.h"
#include "petsc_error.h"
#include "ordering.h"
#include "saved_factor.h"

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <memory>

namespace py = pybind11;
using namespace flexcontact;

namespace
{
/// @brief x = K⁻¹ b by a factor, without the GIL (a solve may wait in MPI collectives).
template <class Factor>
void solve_without_gil(Factor& f, Vec b, Vec x)
{
  py::gil_scoped_release release;
  f.solve(b, x);
}

/// @brief The factor's condensation of b, computed without the GIL, as a NumPy array.
template <class Factor>
py::array_t<double> condense_without_gil(Factor& f, Vec b)
{
  std::vector<double> c;
  {
    py::gil_scoped_release release;
    c = f.condense(b);
  }
  return py::array_t<double>(static_cast<py::ssize_t>(c.size()), c.data());
}

void bind_saved_factor(py::module& m)
{
  py::class_<SavedFactor>(
      m, "SavedFactor",
      "A serial MUMPS LDL^T factor of a symmetric matrix that MUMPS writes to files (save) "
      "and reads back in another process (SavedFactor.restore): a body factored once is "
      "never refactored. Use flexcontact.saved_factor, which checks the files first.")
      .def(py::init<Mat>(), py::arg("A"),
           "Factor the serial symmetric matrix A (its upper triangle is read)")
      .def_static(
          "restore",
          [](const std::string& dir, const std::string& prefix, PetscInt n)
          { return std::make_unique<SavedFactor>(dir, prefix, n); },
          py::arg("dir"), py::arg("prefix"), py::arg("n"),
          "The factor of n rows that save(dir, prefix) wrote (MUMPS JOB=8)")
      .def("save", &SavedFactor::save, py::arg("dir"), py::arg("prefix"),
           "Write the factor as MUMPS's files <dir>/<prefix>_* (JOB=7)")
      .def("solve", &solve_without_gil<SavedFactor>, py::arg("b"), py::arg("x"),
           "x = A^-1 b: one back-substitution")
      .def(
          "solve_many",
          [](SavedFactor& f, const Eigen::Ref<const Eigen::MatrixXd>& B)
          {
            py::gil_scoped_release release;
            return f.solve_many(B);
          },
          py::arg("B"),
          "X = A^-1 B for the k columns of B (n x k) in one MUMPS call that reads the "
          "factor once")
      .def_property_readonly("size", &SavedFactor::size)
      .def_property_readonly("factor_entries", &SavedFactor::factor_entries)
      .def("destroy", &SavedFactor::release, "Release the factor");
}
} // namespace

namespace
{
/// @brief u_c (rank 0's n_c values; anything elsewhere) checked on every rank.
std::vector<double> contact_values(MPI_Comm comm, int n_c, const py::object& u_c)
{
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  std::vector<double> v;
  std::string bad;
  if (rank == 0)
  {
    auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(u_c);
    if (!a or a.ndim() != 1 or a.shape(0) != n_c)
      bad = "expand: u_c must hold the " + std::to_string(n_c) + " contact values on rank 0";
    else
      v.assign(a.data(), a.data() + n_c);
  }
  flexcontact::throw_collective_if(comm, !bad.empty(), bad,
                                   [](const std::string& w) { throw std::invalid_argument(w); });
  return v;
}

void bind_distributed_schur(py::module& m)
{
  using flexcontact::DistributedSchur;
  py::class_<DistributedSchur, std::shared_ptr<DistributedSchur>>(
      m, "DistributedSchur",
      R"(K factored by MUMPS on several ranks with a Schur complement on the contact DOFs
(returned by flexibility(K, dofs, "schur") there). Every method is collective.)")
      .def_property_readonly("has_condense", [](const DistributedSchur&) { return true; })
      .def_property_readonly("size", &DistributedSchur::size, "Rows of K")
      .def_property_readonly("n_schur", &DistributedSchur::n_schur, "Schur (contact) rows")
      .def("save", &DistributedSchur::save, py::arg("dir"), py::arg("prefix"),
           "Write the serial factor as MUMPS's files <dir>/<prefix>_* (JOB=7). Use "
           "flexcontact.saved_factor, which records and checks the files.")
      .def_static(
          "restore",
          [](const std::string& dir, const std::string& prefix, PetscInt n,
             const std::vector<PetscInt>& schur, const Eigen::MatrixXd& F)
          { return DistributedSchur::restore(dir, prefix, n, schur, F); },
          py::arg("dir"), py::arg("prefix"), py::arg("n"), py::arg("schur"), py::arg("F"),
          "The serial factor of n rows that save(dir, prefix) wrote (MUMPS JOB=8), with its "
          "Schur split on the rows `schur` and F* (their flexibility) for the full solves")
      .def("solve", &solve_without_gil<DistributedSchur>, py::arg("b"), py::arg("x"),
           "x = K^-1 b (b, x laid out as K's rows).")
      .def("condense", &condense_without_gil<DistributedSchur>, py::arg("b"),
           "Reduced right-hand side b_c - K_ci K_ii^-1 b_i on the contact DOFs, in the order "
           "given to flexibility, on rank 0 (empty elsewhere).")
      .def(
          "expand",
          [](DistributedSchur& f, const py::object& u_c, Vec x)
          {
            MPI_Comm comm = PetscObjectComm(reinterpret_cast<PetscObject>(x));
            std::vector<double> v = contact_values(comm, f.n_schur(), u_c);
            py::gil_scoped_release release;
            f.expand(v, x);
          },
          py::arg("u_c"), py::arg("x"),
          "x = the solution whose contact values are u_c (rank 0), for the right-hand side "
          "of the last condense().")
      .def(
          "condense_many",
          [](DistributedSchur& f, const Eigen::Ref<const Eigen::MatrixXd>& B)
          {
            py::gil_scoped_release release;
            return f.condense_many(B);
          },
          py::arg("B"),
          "One rank: the reduced right-hand sides of the k columns of B (n x k, an F-ordered "
          "array avoids a copy) in one MUMPS call that reads the factor once: n_c x k.")
      .def(
          "expand_many",
          [](DistributedSchur& f, const Eigen::Ref<const Eigen::MatrixXd>& U_c)
          {
            py::gil_scoped_release release;
            return f.expand_many(U_c);
          },
          py::arg("U_c"),
          "One rank: the solutions (n x k) whose contact values are the columns of U_c "
          "(n_c x k), for the right-hand sides of the last condense_many().")
      .def_property(
          "distributed_io", &DistributedSchur::distributed_io,
          &DistributedSchur::set_distributed_io,
          "True (the default on several ranks): b handed to MUMPS by each rank's rows and "
          "the solution returned to them (ICNTL(20) = 10, ICNTL(21) = 1); False (the default "
          "on one): b gathered on rank 0 and the solution scattered from it (ICNTL(20) = "
          "ICNTL(21) = 0). Set it on every rank.")
      .def_property_readonly("io_refusal", &DistributedSchur::io_refusal,
                             "MUMPS's INFOG(1) if it refused the distributed right-hand side "
                             "or solution (the centralised ones are then used), else 0")
      .def_property_readonly(
          "last_times",
          [](const DistributedSchur& f)
          {
            const auto& t = f.last_times();
            py::dict d;
            d["gather_s"] = t.gather_s;
            d["condense_s"] = t.condense_s;
            d["expand_s"] = t.expand_s;
            d["scatter_s"] = t.scatter_s;
            return d;
          },
          "This rank's wall times (s) of the last condense and expand: b to MUMPS, MUMPS's "
          "condensation, its expansion, the solution into x")
      .def("destroy", &DistributedSchur::release,
           "Free the MUMPS instance now (otherwise when the object goes).");
}

/// @brief flexibility()'s `info` dict without the factor's entry (condense), which goes
/// with the factor object.
py::dict flexibility_info(const Flexibility& r)
{
  py::dict info;
  info["method"] = r.method;
  info["n_contact_dofs"] = r.n_contact_dofs;
  info["null_pivots"] = r.null_pivots;
  info["factorizations"] = r.factorizations;
  info["factorization_retries"] = r.factorization_retries;
  info["factorization_s"] = r.factorization_s;
  info["schur_s"] = r.schur_s;
  info["inverse_s"] = r.inverse_s;
  info["ordering"] = r.ordering;
  info["mumps_ordering"] = r.mumps_ordering;
  info["ordering_fallback"] = r.ordering_fallback;
  info["ordering_s"] = r.ordering_s;
  info["analysis_s"] = r.analysis_s;
  info["factor_entries"] = r.factor_entries;
  info["factor_flops"] = r.factor_flops;
  info["factor_memory_mb"] = r.factor_memory_mb;
  info["n_blocks"] = r.n_blocks;
  info["block_sizes"] = r.block_sizes;
  info["blocks_s"] = r.blocks_s;
  return info;
}

/// @brief flexibility(): F* and the factor of K from one factorization.
void bind_flexibility(py::module& m)
{
  m.def(
      "flexibility",
      [](Mat K, py::array_t<std::int64_t, py::array::c_style | py::array::forcecast> contact_dofs,
         const std::string& method, const std::string& ordering, bool per_body, bool factors)
      {
        std::span<const std::int64_t> dofs(contact_dofs.data(), contact_dofs.size());
        Flexibility r;
        {
          py::gil_scoped_release release;
          r = flexibility(K, dofs, method, ordering, per_body, factors);
        }
        py::dict info = flexibility_info(r);
        info["condense"] = static_cast<bool>(r.distributed);
        py::object factor = r.distributed
                                ? py::cast(r.distributed)
                                : py::cast(r.factor, py::return_value_policy::take_ownership);
        info["form"] = r.factors ? "factors" : "dense";
        py::object F = r.factors ? py::cast(r.factors) : py::cast(r.F);
        return py::make_tuple(F, factor, info);
      },
      py::arg("K"), py::arg("contact_dofs"), py::arg("method") = "schur",
      py::arg("ordering") = "auto", py::arg("per_body") = true, py::arg("factors") = false,
      R"(Flexibility F* = (K^-1)_cc on the contact DOFs from one MUMPS Cholesky factorization.

Parameters: K (petsc4py Mat, symmetric, Dirichlet rows/columns = identity); contact_dofs
(int64 global row indices, on rank 0, empty elsewhere); method "schur" (MUMPS Schur
complement K*_cc inside the factorization, then F* = inv(K*_cc) by dense Cholesky),
"inverse_entries" (MUMPS computes the requested entries of inv(K), ICNTL(30)) or
"matmatsolve" (solve K X = E_c for the contact unit vectors). With contact DOFs, "schur"
drives MUMPS directly (DistributedSchur) on any number of processes: PETSc cannot solve with
a Schur factor in parallel, and in serial its own analysis would be redone for the ordering.
ordering: MUMPS's fill-reducing ordering, "auto" (the default: "metis" for K of block size
3, 3D elasticity; "mumps" otherwise), "metis" (METIS nested dissection of the nodal graph
handed to MUMPS), "mumps" (MUMPS's automatic choice; Debian's MUMPS has AMD, AMF, PORD,
QAMD), or one of "amd", "amf", "pord", "qamd"; on several ranks the methods other than
"schur" use MUMPS's automatic choice (info["ordering"] tells the one asked of MUMPS, "auto"
resolved).
per_body (default True): the contact DOFs that K's graph connects form a block (one per body
touching contact); F* is block-diagonal by them and only the blocks are computed ("schur":
each block of K*_cc inverted on its own; "inverse_entries": only entries within blocks asked
of MUMPS). False: one block of all contact DOFs (the same F* up to rounding).
factors (default False; "schur" only): F* kept as each block's Cholesky factor, returned as a
BlockFlexibility on rank 0 (W is then formed per body by the cheaper route, with no dense
inverse where the triangular route wins); info["form"] is "factors" or "dense".
Returns (F, factor, info): F (n_c x n_c, order of contact_dofs) on rank 0, (0, 0) elsewhere;
factor: the MUMPS factor of K for factor.solve(b, x), the one factorization made; with
"schur" and contact DOFs a DistributedSchur (factor.has_condense: factor.condense(b) and
factor.expand(u_c, x) split a solve in two halves), else a petsc4py Mat; info:
method (the one used), n_contact_dofs, null_pivots, factorizations (1), factorization_retries (redone after MUMPS ran out of
workspace), factorization_s,
schur_s (Schur extraction / inverse-entries solve / multi-RHS solve), inverse_s, ordering
(requested), mumps_ordering (used, INFOG(7)), ordering_fallback (why "auto" kept MUMPS's own
ordering: this PETSc's MUMPS factor cannot take ours; empty otherwise), ordering_s (METIS and the redone analysis,
part of factorization_s), analysis_s (MUMPS's first analysis, part of factorization_s),
factor_entries (INFOG(29)), factor_flops (RINFOG(3)),
factor_memory_mb (INFOG(22)), n_blocks, block_sizes (contact DOFs per block, rank 0),
blocks_s (finding the blocks), condense (factor is a DistributedSchur).
Raises SingularStiffnessError (a RuntimeError) if K is singular, MumpsError/PetscError on
solver failures, ValueError on bad arguments. Collective.)");
}

/// @brief factor_analysis(): what a factorization would cost, from MUMPS's analysis.
void bind_factor_analysis(py::module& m)
{
  m.def(
      "factor_analysis",
      [](Mat K, py::array_t<std::int64_t, py::array::c_style | py::array::forcecast> contact_dofs,
         const std::string& ordering)
      {
        std::span<const std::int64_t> dofs(contact_dofs.data(), contact_dofs.size());
        Flexibility r;
        {
          py::gil_scoped_release release;
          r = factor_analysis(K, dofs, ordering);
        }
        py::dict info;
        info["ordering"] = r.ordering;
        info["mumps_ordering"] = r.mumps_ordering;
        info["n_contact_dofs"] = r.n_contact_dofs;
        info["estimated_entries"] = r.factor_entries;
        info["estimated_flops"] = r.factor_flops;
        info["estimated_memory_mb"] = r.factor_memory_mb;
        info["analysis_s"] = r.factorization_s;
        info["ordering_s"] = r.ordering_s;
        return info;
      },
      py::arg("K"), py::arg("contact_dofs"), py::arg("ordering") = "auto",
      R"(MUMPS's analysis alone (one process): what factoring K with `ordering` (as in
flexibility) and a Schur complement on contact_dofs (none if empty) would cost. Returns a
dict: ordering, mumps_ordering (INFOG(7)), n_contact_dofs, estimated_entries (INFOG(20)),
estimated_flops (RINFOG(1)), estimated_memory_mb (INFOG(17)), analysis_s, ordering_s.)");
}
} // namespace

void flexcontact::bind_petsc(py::module& m)
{
  bind_saved_factor(m);
  m.attr("mumps_version") = MUMPS_VERSION;
  py::handle base = m.attr("SolveError");
  py::register_local_exception<SingularStiffnessError>(m, "SingularStiffnessError", base);
  py::register_local_exception<MumpsError>(m, "MumpsError", base);
  py::register_local_exception<PetscError>(m, "PetscError", base);

  bind_distributed_schur(m);
  bind_flexibility(m);
  bind_factor_analysis(m);
}
