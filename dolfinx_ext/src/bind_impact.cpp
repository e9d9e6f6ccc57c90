// Copyright flexcontact developers. MIT licence.

/// @file bind_impact.cpp
/// @brief Python binding of the Moreau–Jean contact step (kernel/.../impact.hpp).
///
/// A time step crosses the binding once: step() takes the contact-DOF values of u⁻, v⁻ and
/// v_free (step_condensed(): u⁻, v⁻ and the condensed right-hand side) and hands back a
/// plain dict of NumPy arrays and numbers.

#include "bindings.h"
#include "factor_operator.h"

#include <flexcontact/dense_blocks.hpp>
#include <flexcontact/impact.hpp>
#include <flexcontact/increment.hpp>

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
py::dict step_dict(const ImpactStep& r, int dim)
{
  py::dict d;
  d["impulse"] = rows_of(r.impulse, dim);
  d["velocity"] = rows_of(r.velocity, dim);
  d["velocity_before"] = rows_of(r.velocity_before, dim);
  d["gap"] = rows_of(r.gap, dim);
  py::array_t<bool> active(static_cast<py::ssize_t>(r.active.size()));
  for (std::size_t i = 0; i < r.active.size(); ++i)
    active.mutable_at(i) = r.active[i];
  d["states"] = states_array(r.states);
  d["active"] = active;
  d["reaction"] = py::array_t<double>(r.reaction.size(), r.reaction.data());
  d["normal_impulse"] = r.normal_impulse;
  d["slave_impulse"] = py::array_t<double>(r.slave_impulse.size(), r.slave_impulse.data());
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> t
      = r.pair_tangential;
  d["pair_tangential"] = py::array_t<double>({t.rows(), t.cols()}, t.data());
  d["friction_work"] = r.friction_work;
  d["contact_work"] = r.contact_work;
  d["max_penetration"] = r.max_penetration;
  d["crush_work"] = r.crush_work;
  if (r.crush_depth.size() > 0)
    d["crush_depth"] = py::array_t<double>(r.crush_depth.size(), r.crush_depth.data());
  d["active_pairs"] = r.active_pairs;
  d["report"] = report_dict(r.report);
  if (r.velocity_change_c.size() > 0)
  {
    d["velocity_change_c"]
        = py::array_t<double>(r.velocity_change_c.size(), r.velocity_change_c.data());
    d["velocity_c"] = py::array_t<double>(r.velocity_c.size(), r.velocity_c.data());
  }
  return d;
}

using DofArray = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>;

/// @brief The factor path's impact object with the PETSc operator it calls, kept alive
/// together (dense_blocks: the blocks are kept alive by the operator itself).
struct FactorImpact
{
  std::shared_ptr<FactorFlexibility> flexibility;
  std::unique_ptr<ImpactContact> contact;
};

std::shared_ptr<FactorFlexibility> factor_flexibility(std::uintptr_t factor_handle,
                                                      std::uintptr_t A_handle,
                                                      const DofArray& dofs, int n_virtual)
{
  // petsc4py's handles (Mat.handle), as for FactorContact.
  std::vector<PetscInt> d(dofs.data(), dofs.data() + dofs.size());
  return std::make_shared<FactorFlexibility>(reinterpret_cast<Mat>(factor_handle),
                                             reinterpret_cast<Mat>(A_handle), std::move(d),
                                             n_virtual);
}
} // namespace

void flexcontact::bind_impact(py::module& m)
{
  const py::handle convergence_error = m.attr("ConvergenceError");
  py::class_<ImpactContact>(
      m, "ImpactContact",
      "The contact part of a Moreau-Jean time step: B, x0, W_eff = B Fhat B^T with "
      "Fhat = (What^-1)_cc, What = M + h theta C + h^2 theta^2 K; restitution e.")
      .def(py::init(
               [](int dim, Matrix F, Matrix X, std::vector<ContactPair> pairs, Vector mu,
                  double e, double dt, double theta, const std::optional<BoolArray>& held,
                  const SolverOptions& options)
               {
                 return ImpactContact(dim, std::move(F), std::move(X), std::move(pairs),
                                      std::move(mu), e, dt, theta, flags(held), options);
               }),
           py::arg("dim"), py::arg("F"), py::arg("X"), py::arg("pairs"), py::arg("mu"),
           py::arg("restitution"), py::arg("dt_s"), py::arg("theta") = 0.5,
           py::arg("constrained") = py::none(), py::arg("options") = SolverOptions())
      .def(
          "step",
          [convergence_error](ImpactContact& c, const Vector& u_c, const Vector& v_c,
                              const Vector& vfree_c)
          {
            const ImpactStep r
                = step_or_raise(convergence_error, [&] { return c.step(u_c, v_c, vfree_c); });
            return step_dict(r, c.dim());
          },
          py::arg("u_c"), py::arg("v_c"), py::arg("vfree_c"),
          "Contact impulses of one step from the contact-DOF values of u-, v- and the free "
          "velocity. Returns a dict: impulse, velocity (U+), velocity_before (U-), gap (m x d, "
          "local frames), states, active, reaction (n_c, B^T P), normal_impulse, "
          "slave_impulse (d, global), pair_tangential, friction_work, contact_work, "
          "max_penetration, crush_work, crush_depth (with caps), active_pairs, report")
      .def(
          "step_condensed",
          [convergence_error](ImpactContact& c, const Vector& u_c, const Vector& v_c,
                              const Vector& b_c)
          {
            const ImpactStep r = step_or_raise(
                convergence_error, [&] { return c.step_condensed(u_c, v_c, b_c); });
            return step_dict(r, c.dim());
          },
          py::arg("u_c"), py::arg("v_c"), py::arg("b_c"),
          "The step from the condensed right-hand side b_c - What_ci What_ii^-1 b_i "
          "(DistributedSchur.condense of b = h [f - C v- - K (u- + h theta v-)]): the free "
          "velocity v_c + Fhat b_c, then as step(). The dict also holds velocity_change_c "
          "(n_c, Fhat (b_c + r_c): its expansion by the factor is the whole step's "
          "velocity change) and velocity_c (v+ on the contact DOFs)")
      .def("set_flexibility", &ImpactContact::set_flexibility, py::arg("F"), py::arg("dt_s"),
           "New F-hat (another time step): W_eff rebuilt, pairs kept")
      .def("set_pairs", &ImpactContact::set_pairs, py::arg("pairs"), py::arg("mu"),
           py::arg("cap") = Vector(),
           "New pairs on the same contact nodes: B, x0, W_eff rebuilt from the stored F-hat; "
           "pair k keeps its last impulse and state as warm start; cap: the new pairs' "
           "force caps of a crushable interface (empty: none)")
      .def("set_crushing", &ImpactContact::set_crushing, py::arg("cap"),
           "Caps of the pairs' normal contact forces [N; N/m in 2D] (inf: none, empty: no "
           "crushing); the impulse is capped at cap*dt and the surface crushes beyond it")
      .def_property_readonly("node_crush_depth",
                             [](const ImpactContact& c) { return c.node_crush_depth(); },
                             "Crush depth of every contact node [m]")
      .def_property_readonly("B", [](const ImpactContact& c)
                             { return Eigen::SparseMatrix<double, Eigen::RowMajor>(c.B()); })
      .def_property_readonly("x0", [](const ImpactContact& c) { return c.x0(); })
      .def_property_readonly("W", [](const ImpactContact& c) { return c.W(); })
      .def_property_readonly("F", [](const ImpactContact& c) { return c.flexibility(); })
      .def_property_readonly("mu", [](const ImpactContact& c) { return c.mu(); })
      .def_property_readonly(
          "frames",
          [](const ImpactContact& c) { return frames_array(c.contact_pairs(), c.dim()); })
      .def_property_readonly("restitution", &ImpactContact::restitution)
      .def_property_readonly("dt_s", &ImpactContact::dt)
      .def_property_readonly("theta", &ImpactContact::theta)
      .def("pairs", &ImpactContact::pairs)
      .def("contact_dofs", &ImpactContact::contact_dofs)
      .def("dim", &ImpactContact::dim);

  py::class_<DenseBlock, std::shared_ptr<DenseBlock>>(
      m, "DenseBlock",
      "One body's dense flexibility block F (n x n), held once and shared by the runs that "
      "use it (FactorImpact.dense_blocks): a sweep's dam face, or a log in its own frame.")
      .def(py::init(
               [](py::array_t<double, py::array::f_style | py::array::forcecast> F)
               {
                 if (F.ndim() != 2 || F.shape(0) != F.shape(1))
                 {
                   std::string shape;
                   for (py::ssize_t i = 0; i < F.ndim(); ++i)
                     shape += (i ? ", " : "") + std::to_string(F.shape(i));
                   throw std::invalid_argument(
                       "flexcontact: DenseBlock: F must be a square 2-D array, got shape ("
                       + shape + ")");
                 }
                 // The block reads F where it is (a copy only if F was not Fortran-ordered
                 // float64) and keeps it alive; F is made read-only, since the block's
                 // symmetry and products assume values that never change.
                 F.attr("setflags")(py::arg("write") = false);
                 const py::ssize_t n = F.shape(0);
                 const double* data = F.data();
                 std::shared_ptr<const void> keeper(new py::object(std::move(F)),
                                                    [](const py::object* o)
                                                    {
                                                      py::gil_scoped_acquire gil;
                                                      delete o;
                                                    });
                 return std::make_shared<DenseBlock>(data, n, std::move(keeper));
               }),
           py::arg("F"),
           "F: n x n; read in place (and made read-only) when it is a Fortran-ordered float64 "
           "array, else copied once")
      .def_property_readonly(
          "matrix",
          [](py::object self)
          {
            const auto& b = self.cast<const DenseBlock&>();
            py::array_t<double> a({b.rows(), b.rows()},
                                  {sizeof(double), sizeof(double) * b.rows()},
                                  b.matrix().data(), self);
            a.attr("setflags")(py::arg("write") = false);
            return a;
          },
          "F as a read-only view (no copy)")
      .def_property_readonly("rows", &DenseBlock::rows)
      .def_property_readonly("symmetric", &DenseBlock::symmetric,
                             "True: a product with one whole column reads the lower triangle only")
      .def(
          "product",
          [](const DenseBlock& b, const Matrix& X)
          {
            py::gil_scoped_release release;
            return b.product(X);
          },
          py::arg("X"),
          "F X for X of n rows (k columns at once: F is read once for all of them)");

  py::class_<FactorImpact>(
      m, "FactorImpact",
      "The factor path of the Moreau-Jean contact step: Fhat applied through the factor of "
      "What by blocks of right-hand sides (or through shared DenseBlocks: dense_blocks), "
      "W_eff's columns of the index set fetched and held; "
      "neither Fhat nor W_eff is formed. Collective: build and step it on every rank with the "
      "same arguments.")
      .def(py::init(
               [](int dim, std::uintptr_t factor, std::uintptr_t What, const DofArray& dofs,
                  int n_virtual, Matrix X, std::vector<ContactPair> pairs, Vector mu, double e,
                  double dt, double theta, const std::optional<BoolArray>& held,
                  const SolverOptions& options, double max_bytes)
               {
                 FactorImpact c;
                 c.flexibility = factor_flexibility(factor, What, dofs, n_virtual);
                 auto F = c.flexibility;
                 c.contact = std::make_unique<ImpactContact>(
                     dim, [F](const Matrix& R) { return F->block(R); }, std::move(X),
                     std::move(pairs), std::move(mu), e, dt, theta, flags(held), options,
                     max_bytes);
                 return c;
               }),
           py::arg("dim"), py::arg("factor"), py::arg("What"), py::arg("dofs"),
           py::arg("n_virtual"), py::arg("X"), py::arg("pairs"), py::arg("mu"),
           py::arg("restitution"), py::arg("dt_s"), py::arg("theta") = 0.5,
           py::arg("constrained") = py::none(), py::arg("options") = SolverOptions(),
           py::arg("working_set_bytes") = 0.0,
           "factor, What: petsc4py Mat.handle of the factored What and of What (for its "
           "layout); dofs: global indices of the real contact DOFs (the same on every rank); "
           "working_set_bytes: memory for W_eff's columns of the index set")
      .def_static(
          "dense_blocks",
          [](int dim, std::vector<std::shared_ptr<DenseBlock>> blocks,
             std::vector<std::optional<Matrix>> rotations, Matrix X,
             std::vector<ContactPair> pairs, Vector mu, double e, double dt, double theta,
             const SolverOptions& options, double max_bytes)
          {
            std::vector<Matrix> turn;
            for (auto& q : rotations)
              turn.push_back(q ? *q : Matrix());
            auto F = std::make_shared<const SharedBlocks>(
                dim, std::vector<std::shared_ptr<const DenseBlock>>(blocks.begin(), blocks.end()),
                std::move(turn));
            FactorImpact c;
            c.contact = std::make_unique<ImpactContact>(
                dim, [F](const Matrix& R) { return F->apply(R); }, std::move(X),
                std::move(pairs), std::move(mu), e, dt, theta, std::vector<bool>(), options,
                max_bytes);
            return c;
          },
          py::arg("dim"), py::arg("blocks"), py::arg("rotations"), py::arg("X"),
          py::arg("pairs"), py::arg("mu"), py::arg("restitution"), py::arg("dt_s"),
          py::arg("theta") = 0.5, py::arg("options") = SolverOptions(),
          py::arg("working_set_bytes") = 0.0,
          "The factor path with Fhat = diag(Q_b F_b Q_b^T) over shared DenseBlocks (Q_b: a "
          "d x d rotation of the block's nodes into the run's frame, or None): neither Fhat "
          "nor W_eff is formed, W_eff's columns of the index set are fetched from the "
          "blocks. step() takes v_free = v + Fhat b from the caller. Serial.")
      .def(
          "step",
          [convergence_error](FactorImpact& c, const Vector& u_c, const Vector& v_c,
                              const Vector& vfree_c)
          {
            const ImpactStep r = step_or_raise(convergence_error,
                                               [&] { return c.contact->step(u_c, v_c, vfree_c); });
            return step_dict(r, c.contact->dim());
          },
          py::arg("u_c"), py::arg("v_c"), py::arg("vfree_c"),
          "As ImpactContact.step (v_free from a full solve). Collective.")
      .def(
          "set_flexibility",
          [](FactorImpact& c, std::uintptr_t factor, std::uintptr_t What, const DofArray& dofs,
             int n_virtual, double dt)
          {
            auto F = factor_flexibility(factor, What, dofs, n_virtual);
            c.contact->set_block_flexibility([F](const Matrix& R) { return F->block(R); }, dt);
            c.flexibility = F;
          },
          py::arg("factor"), py::arg("What"), py::arg("dofs"), py::arg("n_virtual"),
          py::arg("dt_s"),
          "The new time step's factored What: W_eff's held columns are dropped. Collective.")
      .def(
          "set_pairs",
          [](FactorImpact& c, std::vector<ContactPair> pairs, Vector mu, Vector cap)
          { c.contact->set_pairs(std::move(pairs), std::move(mu), std::move(cap)); },
          py::arg("pairs"), py::arg("mu"), py::arg("cap") = Vector(),
          "New pairs on the same contact nodes: B and x0 rebuilt, held columns dropped; "
          "warm start kept. Collective.")
      .def(
          "set_crushing", [](FactorImpact& c, Vector cap) { c.contact->set_crushing(cap); },
          py::arg("cap"), "As ImpactContact.set_crushing. Collective.")
      .def_property_readonly("node_crush_depth",
                             [](const FactorImpact& c) { return c.contact->node_crush_depth(); })
      .def_property_readonly("B", [](const FactorImpact& c)
                             { return Eigen::SparseMatrix<double, Eigen::RowMajor>(c.contact->B()); })
      .def_property_readonly("x0", [](const FactorImpact& c) { return c.contact->x0(); })
      .def_property_readonly("mu", [](const FactorImpact& c) { return c.contact->mu(); })
      .def_property_readonly(
          "frames", [](const FactorImpact& c)
          { return frames_array(c.contact->contact_pairs(), c.contact->dim()); })
      .def_property_readonly("cached_pairs",
                             [](const FactorImpact& c) { return c.contact->cached_pairs(); })
      .def_property_readonly("block_products",
                             [](const FactorImpact& c) { return c.contact->block_products(); })
      .def_property_readonly("block_columns",
                             [](const FactorImpact& c) { return c.contact->block_columns(); })
      .def("pairs", [](const FactorImpact& c) { return c.contact->pairs(); })
      .def("contact_dofs", [](const FactorImpact& c) { return c.contact->contact_dofs(); })
      .def("dim", [](const FactorImpact& c) { return c.contact->dim(); });
}
