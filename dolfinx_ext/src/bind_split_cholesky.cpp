// Copyright flexcontact developers. MIT licence.

/// @file bind_split_cholesky.cpp
/// @brief Python binding of the sparse split Cholesky factor (kernel/.../split_cholesky.hpp):
/// NumPy in and out, the solution written into the caller's array (a PETSc Vec's own).

#include "bindings.h"

#include <flexcontact/split_cholesky.hpp>

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

namespace py = pybind11;
using namespace flexcontact;

namespace
{
using IntArray = py::array_t<int, py::array::c_style | py::array::forcecast>;
using RealArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

template <class T>
std::span<const T> span_of(const py::array_t<T, py::array::c_style | py::array::forcecast>& a)
{
  return {a.data(), static_cast<std::size_t>(a.size())};
}
} // namespace

void flexcontact::bind_split_cholesky(py::module& m)
{
  py::class_<SplitCholesky>(
      m, "SplitCholesky",
      "A small body's sparse Cholesky factor, contact rows pivoted last, with the condense / "
      "expand / solve of a Schur factor and no per-call set-up (split_cholesky.hpp).")
      .def(py::init(
               [](int n, const IntArray& indptr, const IntArray& indices, const RealArray& values,
                  std::vector<int> schur)
               {
                 py::gil_scoped_release release;
                 return SplitCholesky(n, span_of(indptr), span_of(indices), span_of(values),
                                      std::move(schur));
               }),
           py::arg("n"), py::arg("indptr"), py::arg("indices"), py::arg("values"),
           py::arg("schur"),
           "Order (AMD on the interior, the contact rows `schur` last) and factor the SPD "
           "matrix given by its CSR arrays, both triangles stored.")
      .def(py::init(
               [](std::vector<int> order, Eigen::Index n_schur, const IntArray& indptr,
                  const IntArray& indices, const RealArray& values)
               {
                 const auto n = static_cast<Eigen::Index>(order.size());
                 if (indptr.size() != n + 1 || indices.size() != values.size())
                   throw std::invalid_argument("SplitCholesky: the saved factor's arrays do not "
                                               "match its " + std::to_string(n) + " pivots");
                 Eigen::Map<const Eigen::SparseMatrix<double>> L(
                     n, n, static_cast<Eigen::Index>(values.size()), indptr.data(),
                     indices.data(), values.data());
                 return SplitCholesky(std::move(order), n_schur, Eigen::SparseMatrix<double>(L));
               }),
           py::arg("order"), py::arg("n_schur"), py::arg("indptr"), py::arg("indices"),
           py::arg("values"), "The factor from the parts of arrays(): no factorization.")
      .def_property_readonly("size", &SplitCholesky::size)
      .def_property_readonly("schur_size", &SplitCholesky::schur_size)
      .def_property_readonly("factor_entries", &SplitCholesky::factor_entries)
      .def("condense",
           [](SplitCholesky& f, const RealArray& b)
           {
             Eigen::Map<const Vector> v(b.data(), b.size());
             return Vector(f.condense(v));
           },
           py::arg("b"), "b̃_c = b_c − A_ci A_ii⁻¹ b_i (contact rows in their order).")
      .def("expand",
           [](SplitCholesky& f, const RealArray& u_c, Eigen::Ref<Vector> x)
           {
             Eigen::Map<const Vector> u(u_c.data(), u_c.size());
             f.expand(u, x);
           },
           py::arg("u_c"), py::arg("x").noconvert(),
           "x (written in place) from the contact values u_c and the last condense().")
      .def("solve",
           [](const SplitCholesky& f, const RealArray& b, Eigen::Ref<Vector> x)
           {
             Eigen::Map<const Vector> v(b.data(), b.size());
             f.solve(v, x);
           },
           py::arg("b"), py::arg("x").noconvert(), "x = A⁻¹ b, written in place.")
      .def("flexibility", &SplitCholesky::flexibility,
           "F* = S⁻¹ on the contact rows, dense, symmetrised.")
      .def(
          "arrays",
          [](const SplitCholesky& f)
          {
            const auto& L = f.L();
            const auto n = L.cols();
            py::array_t<int> indptr(n + 1), indices(L.nonZeros());
            py::array_t<double> values(L.nonZeros());
            std::copy_n(L.outerIndexPtr(), n + 1, indptr.mutable_data());
            std::copy_n(L.innerIndexPtr(), L.nonZeros(), indices.mutable_data());
            std::copy_n(L.valuePtr(), L.nonZeros(), values.mutable_data());
            return py::dict(py::arg("order") = f.order(), py::arg("n_schur") = f.schur_size(),
                            py::arg("indptr") = indptr, py::arg("indices") = indices,
                            py::arg("values") = values);
          },
          "The pivot order and L's CSC arrays, to rebuild the factor without factoring.");
}
