// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file distributed_schur.h
/// @brief K factored by one MUMPS instance driven directly on K's communicator, with a
/// Schur complement on the contact DOFs centralised on rank 0, and the solves through it.
///
/// F* comes from here on any number of ranks: PETSc refuses a Schur complement with MUMPS on
/// several, and on one it would run its own analysis only to have it redone for the
/// requested ordering (the METIS ordering's PERM_IN goes to the first analysis here). MUMPS
/// reads each rank's rows of K (distributed assembled input, ICNTL(18) = 3: the
/// upper triangle of the local rows as 1-based triplets, SYM = 2 as PETSc's serial Cholesky),
/// computes K*_cc = K_cc − K_ci K_ii⁻¹ K_ic on the host (ICNTL(19) = 1: for a symmetric
/// matrix its lower triangle by rows), and F* = (K*_cc)⁻¹ is kept there block by block as
/// Cholesky factors (block_flexibility.hpp). Solves go through MUMPS's condensation (ICNTL(26) = 1: b̃_c = b_c − K_ci K_ii⁻¹
/// b_i) and expansion (ICNTL(26) = 2: u from u_c), with u_c = F* b̃_c for a full solve.
///
/// On several ranks the right-hand side and the solution stay distributed by default (ICNTL(20) = 10: each
/// rank hands MUMPS its own rows of b; ICNTL(21) = 1: each rank gets back the rows MUMPS
/// eliminated there, scattered into x by one VecScatter built at the first expansion), so
/// an increment moves no N-vector through rank 0; only b̃_c and u_c (n_c values) live on
/// the host. The centralised variant (ICNTL(20) = ICNTL(21) = 0: b gathered on rank 0, the
/// solution scattered back from it) stays selectable (set_distributed_io) and is taken
/// automatically if MUMPS refuses the distributed one (its INFOG(1) in io_refusal()).
///
/// On one rank the factor can be written to files (save(), MUMPS's JOB=7) and read back in
/// another process (restore(), JOB=8) with its Schur split: the restored instance condenses
/// and expands as the one that factored (docs/architecture.md §7, "A factor kept on disk").

#include "flexcontact/block_flexibility.hpp"

#include <Eigen/Dense>
#include <dmumps_c.h>
#include <memory>
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

/// @brief Wall times (s, this rank's) of the last condense() and expand().
struct DistributedSolveTimes
{
  double gather_s = 0;    ///< b to MUMPS: the gather to rank 0, or the copy of the local rows
  double condense_s = 0;  ///< MUMPS's condensation (job 3, ICNTL(26) = 1)
  double expand_s = 0;    ///< MUMPS's expansion (job 3, ICNTL(26) = 2)
  double scatter_s = 0;   ///< the solution into x (from rank 0, or from each rank's rows)
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
  /// @brief The serial factor that save(dir, prefix) wrote for a matrix of n rows, on
  /// MPI_COMM_SELF, with its Schur complement on `schur` (the rows it was factored with, in
  /// that order) and F* (n_c × n_c) for the full solves. The factorization is not redone.
  /// @throws MumpsError naming the files, std::invalid_argument if the files hold another
  ///   size or Schur size
  static std::shared_ptr<DistributedSchur> restore(const std::string& dir,
                                                   const std::string& prefix, PetscInt n,
                                                   const std::vector<PetscInt>& schur,
                                                   const Eigen::MatrixXd& F);
  DistributedSchur(const DistributedSchur&) = delete;
  DistributedSchur& operator=(const DistributedSchur&) = delete;

  /// @brief Free MUMPS's instance (job = -2) and the PETSc objects; collective; idempotent.
  void release();

  /// @brief Write the factor as MUMPS's files `<dir>/<prefix>_*` (JOB=7). One rank only.
  void save(const std::string& dir, const std::string& prefix);

  const DistributedFactorStats& stats() const { return stats_; }
  int n_schur() const { return n_c_; }
  PetscInt size() const { return n_; }

  /// @brief Rank 0: K*_cc as a dense column-major n_c × n_c array (both triangles).
  const double* schur_complement();

  /// @brief Rank 0: keep F* (n_c × n_c) for the full solves (it replaces K*_cc).
  void set_flexibility(const Eigen::MatrixXd& F);

  /// @brief Rank 0: F* by block, shared, for the full solves.
  void set_flexibility(std::shared_ptr<const BlockFlexibility> F);

  /// @brief x = K⁻¹ b (collective; b and x laid out as K's rows).
  void solve(Vec b, Vec x);

  /// @brief Rank 0: b̃_c = b_c − K_ci K_ii⁻¹ b_i in the order of `schur` (empty elsewhere).
  /// Collective. The condensed system stays in this object for expand().
  std::vector<double> condense(Vec b);

  /// @brief x = the solution whose contact part is u_c (rank 0's values, n_c of them) from
  /// the last condense(). Collective.
  void expand(std::span<const double> u_c, Vec x);

  /// @brief One rank: the condensations of k right-hand sides (the columns of B, n × k) in
  /// one call, so that MUMPS reads its factor once for all of them: b̃ (n_c × k). Scenarios
  /// stepped side by side share a dam this way (docs/architecture.md §7, "Several
  /// right-hand sides at once"). They stay here for expand_many().
  /// @throws std::logic_error on several ranks, std::invalid_argument on B's row count
  Eigen::MatrixXd condense_many(const Eigen::Ref<const Eigen::MatrixXd>& B);

  /// @brief One rank: the solutions (n × k) whose contact rows are the columns of U_c, for
  /// the right-hand sides of the last condense_many().
  /// @throws std::runtime_error without that condensation, std::invalid_argument on U_c's
  ///   size
  Eigen::MatrixXd expand_many(const Eigen::Ref<const Eigen::MatrixXd>& U_c);

  /// @brief Distributed (true, the default on several ranks) or centralised (the default on
  /// one) right-hand side and solution;
  /// the same value on every rank. Takes effect at the next condense().
  void set_distributed_io(bool on);
  bool distributed_io() const { return distributed_io_; }
  /// @brief MUMPS's INFOG(1) if it refused the distributed right-hand side or solution
  /// (then centralised ones are used), else 0.
  int io_refusal() const { return io_refusal_; }
  const DistributedSolveTimes& last_times() const { return times_; }

private:
  DistributedSchur() = default; // restore()'s
  void init_instance();
  void call(int job, const char* phase);
  void factorize();
  void scatter_back(const double* host, Vec x);
  void condense_centralised(Vec b);
  void condense_distributed(Vec b);
  void expand_distributed(std::span<const double> u_c, Vec x);
  void allocate_distributed_solution();
  void build_solution_scatter(Vec x);
  void host_reduced_rhs();

  MPI_Comm comm_ = MPI_COMM_NULL;
  int rank_ = 0;
  int size_ = 1;
  DMUMPS_STRUC_C id_{};
  bool alive_ = false;
  int n_c_ = 0;
  PetscInt n_ = 0;
  std::vector<int> irn_, jcn_, listvar_, perm_in_;
  std::vector<double> a_, schur_, redrhs_, rhs_, condensed_rhs_;
  bool schur_is_inverse_ = false;
  bool schur_symmetric_ = false; ///< F* exactly symmetric: a product reads its lower half
  std::shared_ptr<const BlockFlexibility> factors_; ///< F* by block, when kept so
  bool condensed_ = false;
  int batch_k_ = 0;              ///< right-hand sides of the last condense_many (0: none)
  std::vector<double> batch_rhs_, batch_redrhs_; ///< their n × k and n_c × k arrays
  VecScatter to_zero_ = nullptr; ///< K's row layout → all on rank 0
  Vec host_ = nullptr;           ///< the N values on rank 0 (0 elsewhere)
  DistributedFactorStats stats_;
  DistributedSolveTimes times_;

  // distributed right-hand side and solution
  bool distributed_io_ = true;
  bool condensed_distributed_ = false; ///< how the last condense() ran
  int io_refusal_ = 0;
  PetscInt rstart_ = 0, rend_ = 0;     ///< this rank's rows of K
  std::vector<PetscInt> schur_rows_;   ///< `schur`, 0-based, every rank
  std::vector<int> irhs_loc_;          ///< rstart_+1 … rend_ (1-based)
  std::vector<double> rhs_loc_;        ///< this rank's rows of the last b
  int n_sol_loc_ = 0;                  ///< INFO(23): the rows MUMPS returns here
  std::vector<int> isol_loc_;          ///< their global indices (1-based), ≥ 1 entry
  std::vector<double> sol_buf_;        ///< sol_loc, then u_c on rank 0: sol_seq_'s array
  std::vector<double> host_rhs_stub_;  ///< rank 0: the N-array MUMPS's expansion needs
  Vec sol_seq_ = nullptr;
  VecScatter sol_scatter_ = nullptr;   ///< sol_seq_ → x, built at the first expansion
};

struct Flexibility;

/// @brief flexibility()'s "schur" on several ranks: F* on rank 0 from the host's Schur
/// complement of a DistributedSchur factor, inverted by `blocks` (rank 0's, contact_blocks.h)
/// as in serial; the factor in Flexibility::distributed. `ordering` resolved ("auto" is not
/// taken); "metis" orders the nodal graph gathered on rank 0. Collective.
Flexibility distributed_flexibility(Mat K, const std::vector<PetscInt>& dofs,
                                    const std::string& ordering,
                                    const std::vector<std::vector<int>>& blocks,
                                    bool factors);
} // namespace flexcontact
