// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file distributed_schur.h
/// @brief K factored by one MUMPS instance driven directly on K's communicator, with a
/// Schur complement on the contact DOFs centralised on rank 0, and the solves through it.
///
/// PETSc refuses a Schur complement with MUMPS on several ranks, so there F* comes from
/// here: MUMPS reads each rank's rows of K (distributed assembled input, ICNTL(18) = 3: the
/// upper triangle of the local rows as 1-based triplets, SYM = 2 as PETSc's serial Cholesky),
/// computes K*_cc = K_cc − K_ci K_ii⁻¹ K_ic on the host (ICNTL(19) = 1: for a symmetric
/// matrix its lower triangle by rows), and F* = (K*_cc)⁻¹ is inverted block by block there as
/// in serial. Solves go through MUMPS's condensation (ICNTL(26) = 1: b̃_c = b_c − K_ci K_ii⁻¹
/// b_i) and expansion (ICNTL(26) = 2: u from u_c), with u_c = F* b̃_c for a full solve. The
/// right-hand side and solution are centralised on the host (ICNTL(20) = ICNTL(21) = 0).

#include <Eigen/Dense>
#include <dmumps_c.h>
#include <mpi.h>
#include <petscmat.h>

#include <span>
#include <string>
#include <vector>

namespace flexcontact
{
/// @brief What the factorization cost and found (global MUMPS INFOG/RINFOG).
struct DistributedFactorStats
{
  double analysis_s = 0;      ///< MUMPS analysis (job 1)
  double factorization_s = 0; ///< numerical factorization (job 2), retries included
  int retries = 0;            ///< factorizations redone with a larger ICNTL(14)
  int null_pivots = 0;        ///< INFOG(28)
  int infog7 = 0;             ///< ordering used
  std::int64_t factor_entries = 0; ///< INFOG(29)
  double factor_flops = 0;    ///< RINFOG(3)
  int factor_memory_mb = 0;   ///< INFOG(22)
};

class DistributedSchur
{
public:
  /// @brief Analyse and factor K (collective on its communicator).
  /// @param schur global rows of the Schur variables, the same on every rank (may be empty:
  ///   a plain factorization)
  /// @param icntl7 MUMPS's ordering (ordering.h's mumps_icntl7)
  /// @param perm_in PERM_IN on rank 0 when icntl7 = 1 (the Schur rows last), else empty
  /// @throws MumpsError, SingularStiffnessError (null pivots), on every rank
  DistributedSchur(Mat K, const std::vector<PetscInt>& schur, int icntl7,
                   std::vector<int> perm_in);
  ~DistributedSchur();
  DistributedSchur(const DistributedSchur&) = delete;
  DistributedSchur& operator=(const DistributedSchur&) = delete;

  /// @brief Free MUMPS's instance (job = -2) and the PETSc objects; collective; idempotent.
  void release();

  const DistributedFactorStats& stats() const { return stats_; }
  int n_schur() const { return n_c_; }

  /// @brief Rank 0: K*_cc as a dense column-major n_c × n_c array (both triangles).
  const double* schur_complement();

  /// @brief Rank 0: keep F* (n_c × n_c) for the full solves (it replaces K*_cc).
  void set_flexibility(const Eigen::MatrixXd& F);

  /// @brief x = K⁻¹ b (collective; b and x laid out as K's rows).
  void solve(Vec b, Vec x);

  /// @brief Rank 0: b̃_c = b_c − K_ci K_ii⁻¹ b_i in the order of `schur` (empty elsewhere).
  /// Collective. The condensed system stays in this object for expand().
  std::vector<double> condense(Vec b);

  /// @brief x = the solution whose contact part is u_c (rank 0's values, n_c of them) from
  /// the last condense(). Collective.
  void expand(std::span<const double> u_c, Vec x);

private:
  void call(int job, const char* phase);
  void factorize();
  void scatter_back(const double* host, Vec x);

  MPI_Comm comm_ = MPI_COMM_NULL;
  int rank_ = 0;
  DMUMPS_STRUC_C id_{};
  bool alive_ = false;
  int n_c_ = 0;
  PetscInt n_ = 0;
  std::vector<int> irn_, jcn_, listvar_, perm_in_;
  std::vector<double> a_, schur_, redrhs_, rhs_, condensed_rhs_;
  bool schur_is_inverse_ = false;
  bool condensed_ = false;
  VecScatter to_zero_ = nullptr; ///< K's row layout → all on rank 0
  Vec host_ = nullptr;           ///< the N values on rank 0 (0 elsewhere)
  DistributedFactorStats stats_;
};

struct Flexibility;

/// @brief flexibility()'s "schur" on several ranks: F* on rank 0 from the host's Schur
/// complement of a DistributedSchur factor, inverted by `blocks` (rank 0's, contact_blocks.h)
/// as in serial; the factor in Flexibility::distributed. `ordering` resolved ("auto" is not
/// taken); "metis" orders the nodal graph gathered on rank 0. Collective.
Flexibility distributed_flexibility(Mat K, const std::vector<PetscInt>& dofs,
                                    const std::string& ordering,
                                    const std::vector<std::vector<int>>& blocks);
} // namespace flexcontact
