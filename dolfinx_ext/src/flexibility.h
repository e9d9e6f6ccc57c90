// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file flexibility.h
/// @brief The flexibility F* = (K⁻¹)_cc on the contact DOFs from one MUMPS factorization
/// (the seed's eqs. 4 and 6), without ever inverting K.

#include "flexcontact/block_flexibility.hpp"

#include <Eigen/Dense>
#include <cstdint>
#include <memory>
#include <petscmat.h>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace flexcontact
{
class DistributedSchur;

/// @brief K is singular (MUMPS found null pivots, or the condensed stiffness on the contact
/// DOFs is singular): a body has rigid-body modes that no boundary condition removes.
class SingularStiffnessError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

/// @brief MUMPS reported an error (INFOG(1) < 0); what() holds INFOG(1) and INFO(2).
class MumpsError : public std::runtime_error
{
public:
  MumpsError(const std::string& what, int infog1)
      : std::runtime_error(what), infog1(infog1) {}
  int infog1; ///< MUMPS error code INFOG(1)
};

/// @brief F*, the factor of K that stays usable for solves, and what it cost.
struct Flexibility
{
  /// (K⁻¹)_cc, n_c×n_c, rows/columns in the order of the given contact DOFs, symmetrised;
  /// on rank 0 only (0×0 elsewhere).
  Eigen::MatrixXd F;
  /// F* as each block's Cholesky factor (rank 0, "schur" with `factors` asked; F is then
  /// empty). The directly driven factor on several ranks shares it for its full solves.
  std::shared_ptr<BlockFlexibility> factors;
  /// MUMPS Cholesky factor of K; MatSolve(factor, b, x) gives x = K⁻¹ b. The caller owns
  /// one reference (MatDestroy).
  Mat factor = nullptr;
  /// "schur" on several ranks: the directly driven MUMPS factor (distributed_schur.h) that
  /// serves the solves instead of `factor` (then null)
  std::shared_ptr<DistributedSchur> distributed;
  std::string method;            ///< method actually used: "schur", "inverse_entries" or "matmatsolve"
  int n_contact_dofs = 0;        ///< n_c
  int null_pivots = 0;           ///< MUMPS INFOG(28)
  int factorizations = 0;        ///< sparse factorizations kept (always 1)
  /// factorizations redone because MUMPS ran out of its estimated workspace (INFOG(1) = -8/-9;
  /// happens now and then in parallel, where MUMPS's dynamic scheduling follows the load)
  int factorization_retries = 0;
  double factorization_s = 0;    ///< analysis + numerical factorization (all factorizations)
  double schur_s = 0;            ///< extracting K*_cc (schur), the selected-inverse solve
                                 ///< (inverse_entries) or the multi-RHS solve (matmatsolve)
  double inverse_s = 0;          ///< the Cholesky factor of each block of K*_cc, and its
                                 ///< dense inverse unless kept as factors (schur only)
  std::string ordering;          ///< ordering requested of MUMPS, "auto" resolved ("mumps" on
                                 ///< several ranks but for "schur")
  std::string mumps_ordering;    ///< ordering MUMPS used, from INFOG(7) ("metis" for ours)
  bool ordering_auto = false;    ///< "auto" was asked: MUMPS's own choice if ours cannot be set
  std::string ordering_fallback; ///< why "auto" fell back to MUMPS's own ordering (else empty)
  double ordering_s = 0;         ///< METIS and the redone analysis (within factorization_s)
  double analysis_s = 0;         ///< PETSc's own MUMPS analysis (within factorization_s)
  int n_blocks = 0;              ///< blocks F* is block-diagonal by (bodies with contact DOFs)
  std::vector<int> block_sizes;  ///< contact DOFs per block, in block order (rank 0)
  double blocks_s = 0;           ///< finding the blocks (contact_blocks.h)
  std::int64_t factor_entries = 0; ///< entries in the factor, INFOG(29)
  double factor_flops = 0;       ///< flops of the elimination, RINFOG(3)
  int factor_memory_mb = 0;      ///< MUMPS memory of the factorization (all ranks), INFOG(22)
};

/// @brief Compute the flexibility on the contact DOFs from a MUMPS Cholesky factorization.
///
/// K must be symmetric (it is flagged MAT_SYMMETRIC); rows/columns of Dirichlet DOFs hold
/// the identity, as DOLFINx assembles them.
///
/// Every method makes exactly one sparse factorization, and the returned factor is it.
///
/// Per body (`per_body`, contact_blocks.h): the contact DOFs are split into the blocks that
/// K's graph connects (one per body touching contact); F* is block-diagonal by them, with
/// exact zeros between blocks, and only the blocks are computed: "schur" inverts each
/// block of K*_cc on its own, "inverse_entries" asks MUMPS only for the entries within
/// blocks. With `per_body` false all contact DOFs form one block (F* equal up to rounding).
///
/// * "schur": MUMPS computes the Schur complement K*_cc = K_cc − K_cr K_rr⁻¹ K_rc inside the
///   factorization (centralised on rank 0), and F* = (K*_cc)⁻¹ is kept as each block's
///   Cholesky factor (dpotrf; the dense F* by dpotri unless `factors`). With contact DOFs,
///   on any number of ranks, MUMPS is driven directly (distributed_schur.h: PETSc cannot
///   solve with a Schur factor in parallel, and in serial would analyse twice for our
///   ordering): the factor is Flexibility::distributed, whose solves run MUMPS's
///   condensation and expansion around F*, and `factor` is null.
/// * "inverse_entries": one plain factorization, then MUMPS computes the n_c² requested
///   entries of K⁻¹ directly (ICNTL(30), PETSc's MatMumpsGetInverse), exploiting the sparsity
///   of the unit right-hand sides. Serial and parallel.
/// * "matmatsolve": one plain factorization and K X = E_c with the unit vectors of the
///   contact DOFs as dense right-hand side; F* = X_c.
///
/// Collective on the communicator of K.
/// @param K assembled stiffness (MATAIJ family)
/// @param contact_dofs global row indices of the contact DOFs, on rank 0 (ignored elsewhere)
/// @param method "schur", "inverse_entries" or "matmatsolve"
/// @param ordering fill-reducing ordering (ordering.h): "auto" ("metis" for 3D elasticity,
///   "mumps" otherwise), "metis" (nested dissection of the nodal graph, the Schur variables
///   last), "mumps" (MUMPS's automatic choice), "amd", "amf", "pord" or "qamd"; on several
///   ranks "schur" takes it too (METIS on the nodal graph gathered on rank 0), the other
///   methods MUMPS's automatic choice
/// @param per_body condense each block (body) on its own (default); false: one block
/// @param factors "schur" only: keep F* as each block's Cholesky factor
///   (Flexibility::factors, F then empty), so that W is formed by the cheaper route per
///   body (block_flexibility.hpp); the other methods give F* dense regardless
/// @throws std::invalid_argument on an unknown method or contact DOFs out of range/repeated
/// @throws SingularStiffnessError if K is singular (null pivots or singular K*_cc)
/// @throws MumpsError on a MUMPS failure, PetscError on a PETSc failure
Flexibility flexibility(Mat K, std::span<const std::int64_t> contact_dofs,
                        const std::string& method = "schur",
                        const std::string& ordering = "auto", bool per_body = true,
                        bool factors = false);

/// @brief MUMPS's analysis only (serial): what the factorization of K with `ordering` and a
/// Schur complement on `contact_dofs` (none if empty) would cost, without factorizing. In the
/// returned value factor_entries is INFOG(20), factor_flops RINFOG(1), factor_memory_mb
/// INFOG(17) (MUMPS's estimates), factorization_s the analysis time; F and factor are empty.
Flexibility factor_analysis(Mat K, std::span<const std::int64_t> contact_dofs,
                            const std::string& ordering);
} // namespace flexcontact
