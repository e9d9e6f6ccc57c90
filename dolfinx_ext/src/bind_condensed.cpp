// Copyright flexcontact developers. MIT licence.

/// @file bind_condensed.cpp
/// @brief Python binding of the condensed contact problem (kernel/.../condensed.hpp).
///
/// An increment crosses the binding once: step() takes NumPy in and hands back a plain dict
/// of NumPy arrays and numbers, so that the Python side reads no attribute of a C++ object.

#include "bindings.h"

#include <flexcontact/block_flexibility.hpp>
#include <flexcontact/condensed.hpp>
#include <flexcontact/pairs.hpp>

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <optional>

namespace py = pybind11;
using namespace flexcontact;

namespace
{
using IntArray = py::array_t<int, py::array::c_style | py::array::forcecast>;
using RealArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// @brief Node–node or node–segment pairs with frames from the masters' normals, built in
/// one call: slave (m), masters (m × j), weights (m × j), normals (m × d), offsets (m or none).
std::vector<ContactPair> pairs_from_normals(const IntArray& slave, const IntArray& masters,
                                            const RealArray& weights, const RealArray& normals,
                                            const std::optional<RealArray>& offsets)
{
  const py::ssize_t m = slave.size();
  if (offsets and offsets->size() != m)
    throw std::invalid_argument("offsets has " + std::to_string(offsets->size())
                                + " entries but there are " + std::to_string(m) + " pairs");
  if (masters.ndim() != 2 or weights.ndim() != 2 or normals.ndim() != 2)
    throw std::invalid_argument("masters, weights and normals must be 2-D arrays");
  if (masters.shape(0) != m or weights.shape(0) != m or normals.shape(0) != m)
    throw std::invalid_argument("slave, masters, weights and normals must have one row per "
                                "pair (" + std::to_string(m) + ")");
  if (masters.shape(1) != weights.shape(1))
    throw std::invalid_argument("masters has " + std::to_string(masters.shape(1))
                                + " columns but weights " + std::to_string(weights.shape(1)));
  const py::ssize_t j = masters.shape(1), d = normals.shape(1);
  std::vector<ContactPair> pairs(m);
  for (py::ssize_t k = 0; k < m; ++k)
  {
    ContactPair& p = pairs[k];
    p.slave = slave.data()[k];
    p.masters.assign(masters.data() + k * j, masters.data() + (k + 1) * j);
    p.weights.assign(weights.data() + k * j, weights.data() + (k + 1) * j);
    p.frame = frame_from_normal(Eigen::Map<const Vector>(normals.data() + k * d, d));
    if (offsets)
      p.offset = offsets->data()[k];
  }
  return pairs;
}
} // namespace

void flexcontact::bind_condensed(py::module& m)
{
  // Registered by bind_kernel; the module keeps it alive.
  const py::handle convergence_error = m.attr("ConvergenceError");

  m.def("pairs_from_normals", &pairs_from_normals, py::arg("slave"), py::arg("masters"),
        py::arg("weights"), py::arg("normals"), py::arg("offsets") = py::none(),
        "ContactPairs with frames from the masters' outward normals, in one call: slave (m), "
        "masters (m x j), weights (m x j), normals (m x d), offsets (m, normal distance of the "
        "master surface from the master point [m]; None: 0)");

  py::class_<BlockFlexibility, std::shared_ptr<BlockFlexibility>>(
      m, "BlockFlexibility",
      "F* held by body as each block's Cholesky factor S_b = L_b L_b^T (F*_b = S_b^-1): W = "
      "B F* B^T is formed per body by the cheaper of the inverse route (2/3 n^3) and the "
      "triangular one (n^2 r + n r^2), n the body's contact DOFs and r the rows of B on them")
      .def(py::init<Matrix>(), py::arg("F"), "F* given dense (one block, its inverse known)")
      .def(py::init<Eigen::Index, std::vector<std::vector<int>>, std::vector<Matrix>>(),
           py::arg("n"), py::arg("blocks"), py::arg("L"),
           "n contact DOFs; blocks: the positions of each block's DOFs; L: each block's lower "
           "Cholesky factor (a DOF in no block has zero flexibility)")
      .def(
          "extended",
          [](const BlockFlexibility& F, Eigen::Index n)
          {
            BlockFlexibility G = F;
            G.extend(n);
            return G;
          },
          py::arg("n"), "A copy with n >= rows DOFs, the new ones without flexibility")
      .def("apply", &BlockFlexibility::apply, py::arg("v"), "F* v")
      .def("delassus", &BlockFlexibility::delassus, py::arg("B"),
           "W = B F* B^T by the cheaper route per block (routes)")
      .def("dense", &BlockFlexibility::dense, "F* as a dense matrix")
      .def_property_readonly("rows", &BlockFlexibility::rows)
      .def_property_readonly("block_sizes", &BlockFlexibility::block_sizes)
      .def_property_readonly("routes", &BlockFlexibility::routes,
                             "Per block, the route of the last delassus: inverse, "
                             "triangular, none (no row of B on it) or dense")
      .def_property_readonly("flops_taken", &BlockFlexibility::flops_taken,
                             "Flop estimate of the last delassus, routes as taken")
      .def_property_readonly("flops_inverse", &BlockFlexibility::flops_inverse,
                             "Flop estimate of the last delassus, all by the inverse route");

  py::class_<CondensedContact>(
      m, "CondensedContact",
      "The condensed contact problem x = W lambda + q: pairs, B, x0, W = B F* B^T and the "
      "incremental driver. Contact DOFs are node-major (contact node a owns a*d + c).")
      .def(py::init(
               [](int dim, Matrix F, Matrix X, std::vector<ContactPair> pairs, Vector mu,
                  const std::optional<BoolArray>& constrained, const SolverOptions& options)
               {
                 return CondensedContact(dim, std::move(F), std::move(X), std::move(pairs),
                                         std::move(mu), flags(constrained), options);
               }),
           py::arg("dim"), py::arg("F"), py::arg("X"), py::arg("pairs"), py::arg("mu"),
           py::arg("constrained") = py::none(), py::arg("options") = SolverOptions(),
           "F (n_c x n_c) flexibility; X (n_nodes x dim) contact node coordinates; mu per "
           "pair; constrained: n_c flags of Dirichlet-held contact DOFs (None: none)")
      .def(py::init(
               [](int dim, const BlockFlexibility& F, Matrix X, std::vector<ContactPair> pairs,
                  Vector mu, const std::optional<BoolArray>& constrained,
                  const SolverOptions& options)
               {
                 return CondensedContact(dim, F, std::move(X), std::move(pairs), std::move(mu),
                                         flags(constrained), options);
               }),
           py::arg("dim"), py::arg("F"), py::arg("X"), py::arg("pairs"), py::arg("mu"),
           py::arg("constrained") = py::none(), py::arg("options") = SolverOptions(),
           "As above with F* a BlockFlexibility (copied): W per body by the cheaper route")
      .def(
          "step",
          [convergence_error](CondensedContact& c, const Vector& up_c,
                              const std::optional<Vector>& e)
          {
            const CondensedStep r = step_or_raise(
                convergence_error, [&] { return e ? c.step(up_c, *e) : c.step(up_c); });
            return condensed_step_dict(r, c.dim());
          },
          py::arg("up_c"), py::arg("e") = py::none(),
          "One increment from the contact-DOF values of u_p = K^-1 p (K^+ p with rigid modes, "
          "e = -R^T p then: the loads along them). Returns a dict: lambda, "
          "gap (m x d, local frames), slip (m x d-1, this increment), states (1 open, 2 "
          "stick, 3 slip), reaction (n_c, B^T lambda, zero on constrained DOFs), local_q, "
          "solution_c (n_c, u_p,c + F* r_c: the contact values of K^-1 (p + B^T lambda)), "
          "normal_force, tangential_force (d, global), max_penetration, pair_tangential "
          "(m x d, global), alpha (rigid-mode amplitudes), undetermined (k x r directions of "
          "alpha no contact resists), report (dict). Raises ConvergenceError with .report (a dict); the "
          "history is then unchanged")
      .def(
          "step_condensed",
          [convergence_error](CondensedContact& c, const Vector& b_c,
                              const std::optional<Vector>& e)
          {
            const CondensedStep r = step_or_raise(
                convergence_error, [&]
                { return c.step_condensed(b_c, e ? *e : Vector::Zero(c.rigid_modes().cols())); });
            return condensed_step_dict(r, c.dim());
          },
          py::arg("b_c"), py::arg("e") = py::none(),
          "One increment from the condensed load b_c = p_c - K_ci K_ii^-1 p_i on the contact "
          "DOFs (DistributedSchur.condense; constrained and rigid-target DOFs: their prescribed "
          "values): u_p,c = F* b_c, then as step. The dict's solution_c (u_p,c + F* r_c) "
          "expands to K^-1 (p + B^T lambda)")
      .def("set_flexibility", &CondensedContact::set_flexibility, py::arg("F"),
           "New F* (e.g. another time step): W is rebuilt, pairs and history kept")
      .def("set_pairs", &CondensedContact::set_pairs, py::arg("pairs"), py::arg("mu"),
           py::arg("cap") = Vector(),
           "New pairs: B, x0, W rebuilt from the stored F*; history reset, slip measured from "
           "the new pairs' gap at the last contact displacement; cap: the new pairs' normal "
           "force caps of a crushable interface (empty: none)")
      .def("set_crushing", &CondensedContact::set_crushing, py::arg("cap"),
           "Caps of the pairs' normal forces [N; N/m in 2D] (inf: none, empty: no crushing)")
      .def_property_readonly("node_crush_depth",
                             [](const CondensedContact& c) { return c.node_crush_depth(); },
                             "Crush depth of every contact node [m]")
      .def("set_rigid_modes", &CondensedContact::set_rigid_modes, py::arg("Rc"),
           "Rigid modes of the bodies held only by contact at the contact DOFs (n_c x k); "
           "G = B R_c borders the local problem")
      .def_property_readonly("border", [](const CondensedContact& c) { return c.border(); },
                             "G = B R_c (m*d x k)")
      .def("local_q", &CondensedContact::local_q, py::arg("q"),
           "q' of the local problem u = W lambda + q' that step solves next for this total q")
      .def_property_readonly("B", [](const CondensedContact& c)
                             { return Eigen::SparseMatrix<double, Eigen::RowMajor>(c.B()); },
                             "Gap operator (scipy CSR, m*d x n_c)")
      .def_property_readonly("x0", [](const CondensedContact& c) { return c.x0(); })
      .def_property_readonly("W", [](const CondensedContact& c) { return c.W(); })
      .def_property_readonly("F", [](const CondensedContact& c) { return c.flexibility(); },
                             "F* with the constrained DOFs' rows and columns zeroed")
      .def_property_readonly("delassus_routes",
                             [](const CondensedContact& c) { return c.delassus_routes(); },
                             "Per body, how the last W was formed: inverse, triangular, none "
                             "or dense (F* given dense)")
      .def_property_readonly("delassus_flops",
                             [](const CondensedContact& c)
                             {
                               const BlockFlexibility& F = c.block_flexibility();
                               return py::make_tuple(F.flops_taken(), F.flops_inverse());
                             },
                             "Flop estimates of the last W: (as taken, all by inverse)")
      .def_property_readonly("mu", [](const CondensedContact& c) { return c.mu(); })
      .def_property_readonly("last_q", [](const CondensedContact& c) { return c.last_q(); },
                             "q = B up_c + x0 of the last step call, also a failed one")
      .def_property_readonly(
          "frames",
          [](const CondensedContact& c) { return frames_array(c.contact_pairs(), c.dim()); },
          "Local frames T_k (m x d x d), rows n, t (, t2)")
      .def_property_readonly("contact_pairs",
                             [](const CondensedContact& c) { return c.contact_pairs(); })
      .def("pairs", &CondensedContact::pairs, "Number of pairs m")
      .def("contact_dofs", &CondensedContact::contact_dofs, "Number of contact DOFs n_c")
      .def("dim", &CondensedContact::dim);
}
