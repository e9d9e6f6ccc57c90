// Copyright flexcontact developers. MIT licence.

/// @file bind_operator.cpp
/// @brief Python binding of the condensed contact problem whose W is applied through the
/// factor of K (kernel/.../operator_contact.hpp with factor_operator.h's F*).
///
/// The object is built on every rank: each F* product is a collective MatSolve, and every
/// rank runs the same iteration on the same replicated contact vectors.

#include "bindings.h"
#include "factor_operator.h"

#include <flexcontact/condensed.hpp>
#include <flexcontact/operator_contact.hpp>

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <memory>
#include <optional>

namespace py = pybind11;
using namespace flexcontact;

namespace
{
using DofArray = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>;

/// @brief The kernel object with the PETSc operator it calls, kept alive together.
struct FactorContact
{
  std::shared_ptr<FactorFlexibility> flexibility;
  std::unique_ptr<OperatorContact> contact;
};
} // namespace

void flexcontact::bind_operator(py::module& m)
{
  const py::handle convergence_error = m.attr("ConvergenceError");
  py::class_<FactorContact>(
      m, "FactorContact",
      "The condensed contact problem with W x = B (K^-1 B^T x)_c applied through the factor "
      "of K, one back-substitution per product; neither F* nor W is formed. Collective: "
      "build and step it on every rank with the same arguments.")
      .def(py::init(
               [](int dim, std::uintptr_t factor_handle, std::uintptr_t K_handle,
                  const DofArray& dofs, int n_virtual, Matrix X,
                  std::vector<ContactPair> pairs, Vector mu,
                  const std::optional<BoolArray>& constrained, const SolverOptions& options,
                  double working_set_bytes)
               {
                 // petsc4py's handles (Mat.handle), not its C API: petsc_caster.h's import
                 // state belongs to the one translation unit that loads it.
                 Mat factor = reinterpret_cast<Mat>(factor_handle);
                 Mat K = reinterpret_cast<Mat>(K_handle);
                 std::vector<PetscInt> d(dofs.data(), dofs.data() + dofs.size());
                 auto F = std::make_shared<FactorFlexibility>(factor, K, std::move(d),
                                                              n_virtual);
                 FactorContact c;
                 c.flexibility = F;
                 c.contact = std::make_unique<OperatorContact>(
                     dim, [F](const Vector& r) { return (*F)(r); }, std::move(X),
                     std::move(pairs), std::move(mu), flags(constrained), options);
                 SameOnAllRanks same;
                 int size = 1;
                 MPI_Comm_size(PetscObjectComm(reinterpret_cast<PetscObject>(K)), &size);
                 if (size > 1)
                   same = [F](long v) { F->same_on_all_ranks(v); };
                 c.contact->use_working_set([F](const Matrix& R) { return F->block(R); },
                                            working_set_bytes, same);
                 return c;
               }),
           py::arg("dim"), py::arg("factor"), py::arg("K"), py::arg("dofs"),
           py::arg("n_virtual"), py::arg("X"), py::arg("pairs"), py::arg("mu"),
           py::arg("constrained") = py::none(), py::arg("options") = SolverOptions(),
           py::arg("working_set_bytes") = 0.0,
           "factor, K: petsc4py Mat.handle of the factored K and of K (for its layout); "
           "dofs: global indices of the real contact DOFs (the same on every rank); "
           "n_virtual: trailing contact DOFs with no PETSc DOF; "
           "X, pairs, mu, constrained, options as CondensedContact; "
           "working_set_bytes: memory for W's columns of the pairs in contact (the working-set "
           "solve, by blocks of right-hand sides); 0: the matrix-free iteration only. The "
           "same value on every rank.")
      .def(
          "step",
          [convergence_error](FactorContact& c, const Vector& up_c)
          {
            const CondensedStep r
                = step_or_raise(convergence_error, [&] { return c.contact->step(up_c); });
            return condensed_step_dict(r, c.contact->dim());
          },
          py::arg("up_c"),
          "One increment from the contact-DOF values of u_p = K^-1 p; the dict of "
          "CondensedContact.step. Raises ConvergenceError (history unchanged). Collective.")
      .def(
          "set_pairs",
          [](FactorContact& c, std::vector<ContactPair> pairs, Vector mu, Vector cap)
          {
            py::gil_scoped_release release;
            c.contact->set_pairs(std::move(pairs), std::move(mu), std::move(cap));
          },
          py::arg("pairs"), py::arg("mu"), py::arg("cap") = Vector(),
          "New pairs: B, x0 and the scales rebuilt; cap: the new pairs' normal force caps of "
          "a crushable interface (empty: none). Collective.")
      .def(
          "set_crushing", [](FactorContact& c, Vector cap) { c.contact->set_crushing(cap); },
          py::arg("cap"),
          "Caps of the pairs' normal forces [N; N/m in 2D] (inf: none, empty: no crushing). "
          "Collective: every rank's object takes the same caps.")
      .def_property_readonly(
          "node_crush_depth", [](const FactorContact& c) { return c.contact->node_crush_depth(); },
          "Crush depth of every contact node [m]")
      .def(
          "apply_W",
          [](FactorContact& c, const Vector& x)
          {
            py::gil_scoped_release release;
            return c.contact->apply_W(x);
          },
          py::arg("x"), "W x (one back-substitution). Collective.")
      .def_property_readonly(
          "B", [](const FactorContact& c)
          { return Eigen::SparseMatrix<double, Eigen::RowMajor>(c.contact->B()); })
      .def_property_readonly("x0", [](const FactorContact& c) { return c.contact->x0(); })
      .def_property_readonly("mu", [](const FactorContact& c) { return c.contact->mu(); })
      .def_property_readonly(
          "frames", [](const FactorContact& c)
          { return frames_array(c.contact->contact_pairs(), c.contact->dim()); })
      .def(
          "W_columns",
          [](FactorContact& c, std::vector<int> pairs)
          {
            py::gil_scoped_release release;
            return c.contact->W_columns(pairs);
          },
          py::arg("pairs"),
          "W[:, pairs] (m·d × d·len(pairs)) by one block of back-substitutions. Collective.")
      .def_property_readonly("block_columns",
                             [](const FactorContact& c) { return c.contact->block_columns(); },
                             "columns F* was applied to in blocks so far")
      .def_property_readonly("block_products",
                             [](const FactorContact& c) { return c.contact->block_products(); },
                             "block products (each one or a few multi-RHS solves) so far")
      .def_property_readonly("cached_pairs",
                             [](const FactorContact& c) { return c.contact->cached_pairs(); },
                             "pairs whose columns of W are held now")
      .def_property_readonly("applications",
                             [](const FactorContact& c) { return c.contact->applications(); },
                             "F* products (back-substitutions) so far")
      .def_property_readonly(
          "scales",
          [](const FactorContact& c)
          {
            const OperatorScales& s = c.contact->scales();
            py::dict d;
            d["lipschitz"] = s.lipschitz;
            d["mean_normal"] = s.mean_normal;
            d["applications"] = s.applications;
            return d;
          },
          "The estimates of the current pairs: lipschitz (>= ||W||), mean_normal (mean W_nn)")
      .def("pairs", [](const FactorContact& c) { return c.contact->pairs(); })
      .def("contact_dofs", [](const FactorContact& c) { return c.contact->contact_dofs(); })
      .def("dim", [](const FactorContact& c) { return c.contact->dim(); });
}
