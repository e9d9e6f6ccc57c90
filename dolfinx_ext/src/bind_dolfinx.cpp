// Copyright flexcontact developers. MIT licence.

/// @file bind_dolfinx.cpp
/// @brief Python bindings of the DOLFINx/PETSc bridge: flexibility, surface_nodes,
/// set_nodal_values.

#include "bindings.h"
#include "compat.h"
#include "flexibility.h"
#include "petsc_error.h"
#include "surface_nodes.h"
#include "writeback.h"

#include <dolfinx/wrappers/caster_petsc.h>
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

namespace py = pybind11;

namespace
{
/// @brief numpy array of shape (rows, cols) copied from a row-major buffer.
template <class T>
py::array_t<T> as_array(const std::vector<T>& v, std::size_t rows, std::size_t cols)
{
  py::array_t<T> a({rows, cols});
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}
} // namespace

void flexcontact::bind_dolfinx(py::module& m)
{
  py::register_exception<SingularStiffnessError>(m, "SingularStiffnessError",
                                                 PyExc_RuntimeError);
  py::register_exception<MumpsError>(m, "MumpsError", PyExc_RuntimeError);
  py::register_exception<PetscError>(m, "PetscError", PyExc_RuntimeError);

  m.def(
      "flexibility",
      [](Mat K, py::array_t<std::int64_t, py::array::c_style | py::array::forcecast> contact_dofs,
         const std::string& method)
      {
        std::span<const std::int64_t> dofs(contact_dofs.data(), contact_dofs.size());
        Flexibility r;
        {
          py::gil_scoped_release release;
          r = flexibility(K, dofs, method);
        }
        py::dict info;
        info["method"] = r.method;
        info["n_contact_dofs"] = r.n_contact_dofs;
        info["null_pivots"] = r.null_pivots;
        info["factorizations"] = r.factorizations;
        info["factorization_retries"] = r.factorization_retries;
        info["factorization_s"] = r.factorization_s;
        info["schur_s"] = r.schur_s;
        info["inverse_s"] = r.inverse_s;
        py::object factor = py::cast(r.factor, py::return_value_policy::take_ownership);
        py::array_t<double> F = py::cast(r.F);
        return py::make_tuple(F, factor, info);
      },
      py::arg("K"), py::arg("contact_dofs"), py::arg("method") = "schur",
      R"(Flexibility F* = (K^-1)_cc on the contact DOFs from one MUMPS Cholesky factorization.

Parameters: K (petsc4py Mat, symmetric, Dirichlet rows/columns = identity); contact_dofs
(int64 global row indices, on rank 0, empty elsewhere); method "schur" (MUMPS Schur
complement K*_cc inside the factorization, then F* = inv(K*_cc) by dense Cholesky),
"inverse_entries" (MUMPS computes the requested entries of inv(K), ICNTL(30)) or
"matmatsolve" (solve K X = E_c for the contact unit vectors). PETSc cannot solve with a
Schur factor in parallel, so there "schur" runs as "inverse_entries"; info["method"] tells.
Returns (F, factor, info): F (n_c x n_c, order of contact_dofs) on rank 0, (0, 0) elsewhere;
factor: the MUMPS factor of K for factor.solve(b, x), the one factorization made; info:
method (the one used), n_contact_dofs, null_pivots, factorizations (1), factorization_retries (redone after MUMPS ran out of
workspace), factorization_s,
schur_s (Schur extraction / inverse-entries solve / multi-RHS solve), inverse_s.
Raises SingularStiffnessError (a RuntimeError) if K is singular, MumpsError/PetscError on
solver failures, ValueError on bad arguments. Collective.)");

  m.def(
      "surface_nodes",
      [](py::object V, py::object facet_tags, int value)
      {
        auto Vc = compat::unwrap<compat::FunctionSpace>(V, "a dolfinx FunctionSpace");
        auto tags = compat::unwrap<compat::MeshTags>(facet_tags, "dolfinx MeshTags (int32)");
        SurfaceNodes s = surface_nodes(*Vc, *tags, value);
        const std::size_t n = s.size();
        py::dict out;
        out["x"] = as_array(s.x, n, s.gdim);
        out["dofs"] = as_array(s.dofs, n, s.bs);
        out["normal"] = as_array(s.normal, n, s.gdim);
        out["area"] = py::array_t<double>(n, s.area.data());
        return out;
      },
      py::arg("V"), py::arg("facet_tags"), py::arg("value"),
      R"(Nodes of the facets tagged `value`, gathered and merged on rank 0.

Returns a dict (rank 0; empty arrays elsewhere), nodes sorted by coordinates:
"x" (n, gdim) coordinates; "dofs" (n, bs) global DOF indices block*bs + component;
"normal" (n, gdim) unit outward normals (facet-measure-weighted); "area" (n,) tributary
length (2D) or area (3D). V: P1 space (Python or C++ object); facet_tags: int32 facet
MeshTags. Raises ValueError if no facet carries `value` (listing the values present).
Collective.)");

  m.def(
      "set_nodal_values",
      [](py::object u, py::array_t<std::int64_t, py::array::c_style | py::array::forcecast> dofs,
         py::array_t<double, py::array::c_style | py::array::forcecast> values)
      {
        auto uc = compat::unwrap<compat::Function>(u, "a dolfinx Function");
        set_nodal_values(*uc, std::span<const std::int64_t>(dofs.data(), dofs.size()),
                         std::span<const double>(values.data(), values.size()));
      },
      py::arg("u"), py::arg("dofs"), py::arg("values"),
      R"(Set DOFs of a distributed Function from rank 0's arrays, then update ghosts.

dofs: global DOF indices (block*bs + component; for a scalar space the global node index),
any shape, on rank 0 (empty elsewhere); values: same number of float64. DOFs not listed keep
their values. Collective.)");
}
