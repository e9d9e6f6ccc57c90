// Copyright flexcontact developers. MIT licence.

#include "distributed_schur.h"
#include "collective.h"
#include "contact_blocks.h"
#include "ordering.h"
#include "flexibility.h"
#include "mumps_instance.h"
#include "petsc_error.h"

#include <algorithm>
#include <cstring>
#include <limits>
#include <memory>

using namespace flexcontact;

namespace
{
/// @brief MUMPS's ICNTL(i), 1-based as in its guide.
int& icntl(DMUMPS_STRUC_C& id, int i) { return id.icntl[i - 1]; }
int infog(const DMUMPS_STRUC_C& id, int i) { return id.infog[i - 1]; }

} // namespace

DistributedSchur::DistributedSchur(Mat K, const std::vector<PetscInt>& schur, int icntl7,
                                   std::vector<int> perm_in)
{
  PetscErrorScope err;
  err.check(MatGetSize(K, &n_, nullptr), "MatGetSize");
  if (n_ > std::numeric_limits<int>::max() - 1)
    throw std::invalid_argument("K has " + std::to_string(n_) + " rows: more than MUMPS's "
                                "32-bit indices hold");
  n_c_ = static_cast<int>(schur.size());
  schur_rows_ = schur;
  upper_triplets(K, irn_, jcn_, a_);
  err.check(MatGetOwnershipRange(K, &rstart_, &rend_), "MatGetOwnershipRange");
  irhs_loc_.assign(std::max<std::size_t>(rend_ - rstart_, 1), 1); // never a null IRHS_loc
  for (PetscInt r = rstart_; r < rend_; ++r)
    irhs_loc_[r - rstart_] = static_cast<int>(r + 1);
  rhs_loc_.assign(irhs_loc_.size(), 0.0);

  // MUMPS keeps the communicator until its termination, which may come after K and every
  // other PETSc object on K's communicator are gone (PETSc then frees its inner one; MUMPS 5.7
  // refuses the termination, INFO(1) = -3): this instance holds its own duplicate, freed by
  // release() (which every later failure of this constructor calls).
  MPI_Comm_dup(PetscObjectComm(reinterpret_cast<PetscObject>(K)), &comm_);
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &size_);
  // On one rank the centralised variant is a plain copy each way, while the distributed
  // one scatters the solution by MUMPS's elimination order (measured, 7,442 rows: 1.30
  // against 1.37 ms per condensation and expansion).
  distributed_io_ = size_ > 1;
  init_instance();
  try
  {
    icntl(id_, 5) = 0;  // assembled
    icntl(id_, 18) = 3; // distributed triplets
    icntl(id_, 20) = 0; // set per solve (condense_centralised / condense_distributed)
    icntl(id_, 21) = 0;
    icntl(id_, 24) = 1; // detect null pivots (INFOG(28)) instead of dividing by ~0
    icntl(id_, 28) = 1; // sequential analysis: takes PERM_IN (no ParMETIS/PT-SCOTCH here)
    icntl(id_, 7) = icntl7;
    id_.n = static_cast<int>(n_);
    id_.nnz_loc = static_cast<MUMPS_INT8>(a_.size());
    id_.nz_loc = a_.size() <= static_cast<std::size_t>(std::numeric_limits<int>::max())
                     ? static_cast<int>(a_.size()) : 0;
    id_.irn_loc = irn_.data();
    id_.jcn_loc = jcn_.data();
    id_.a_loc = a_.data();
    if (rank_ == 0 and icntl7 == 1)
    {
      perm_in_ = std::move(perm_in);
      id_.perm_in = perm_in_.data();
    }
    if (n_c_ > 0)
    {
      icntl(id_, 19) = 1; // Schur complement centralised on the host (by rows)
      id_.size_schur = n_c_;
      if (rank_ == 0)
      {
        listvar_.resize(n_c_);
        for (int k = 0; k < n_c_; ++k)
          listvar_[k] = static_cast<int>(schur[k] + 1);
        schur_.assign(static_cast<std::size_t>(n_c_) * n_c_, 0.0);
        id_.listvar_schur = listvar_.data();
        id_.schur = schur_.data();
        id_.schur_lld = n_c_;
      }
    }
    double t0 = MPI_Wtime();
    call(1, "analysis");
    stats_.analysis_s = MPI_Wtime() - t0;
    stats_.infog7 = infog(id_, 7);
    factorize();
    allocate_distributed_solution();
  }
  catch (...)
  {
    release();
    throw;
  }
}

void DistributedSchur::init_instance()
{
  id_.job = -1;
  id_.par = 1; // the host works too
  id_.sym = 2; // symmetric, LDLᵀ with pivoting, as PETSc's Cholesky of K in serial
  id_.comm_fortran = static_cast<int>(MPI_Comm_c2f(comm_));
  dmumps_c(&id_);
  if (infog(id_, 1) < 0)
  {
    release();
    throw_mumps_error("initialization", infog(id_, 1), infog(id_, 2));
  }
  alive_ = true;
  icntl(id_, 1) = icntl(id_, 2) = icntl(id_, 3) = -1; // no printing
  icntl(id_, 4) = 0;
}

std::shared_ptr<DistributedSchur> DistributedSchur::restore(const std::string& dir,
                                                            const std::string& prefix,
                                                            PetscInt n,
                                                            const std::vector<PetscInt>& schur,
                                                            const Eigen::MatrixXd& F)
{
  const std::string files = "'" + dir + "/" + prefix + "'";
  if (n < 1 or n > std::numeric_limits<int>::max() - 1)
    throw std::invalid_argument("DistributedSchur.restore: n=" + std::to_string(n)
                                + " rows is not a size");
  if (schur.empty())
    throw std::invalid_argument("DistributedSchur.restore: no Schur rows given for " + files);
  for (PetscInt r : schur)
    if (r < 0 or r >= n)
      throw std::invalid_argument("DistributedSchur.restore: Schur row " + std::to_string(r)
                                  + " is outside the " + std::to_string(n) + " rows");
  const auto n_c = static_cast<Eigen::Index>(schur.size());
  if (F.rows() != n_c or F.cols() != n_c)
    throw std::invalid_argument("DistributedSchur.restore: F* is " + std::to_string(F.rows())
                                + " x " + std::to_string(F.cols()) + " for "
                                + std::to_string(n_c) + " Schur rows");
  std::shared_ptr<DistributedSchur> f(new DistributedSchur());
  f->n_ = n;
  f->n_c_ = static_cast<int>(n_c);
  f->schur_rows_ = schur;
  f->rend_ = n;
  f->distributed_io_ = false; // one rank: the centralised solves are plain copies
  MPI_Comm_dup(MPI_COMM_SELF, &f->comm_);
  f->init_instance();
  set_save_files(f->id_, dir, prefix, "DistributedSchur");
  f->call(8, ("restoration of " + files).c_str());
  icntl(f->id_, 1) = icntl(f->id_, 2) = icntl(f->id_, 3) = -1; // the saved ones came back
  icntl(f->id_, 4) = 0;
  if (f->id_.n != static_cast<int>(n) or icntl(f->id_, 19) == 0
      or f->id_.size_schur != f->n_c_)
    throw std::invalid_argument(
        "DistributedSchur.restore: the files at " + files + " hold a factor of "
        + std::to_string(f->id_.n) + " rows with a Schur complement on "
        + std::to_string(icntl(f->id_, 19) == 0 ? 0 : f->id_.size_schur) + " of them, not "
        + std::to_string(n) + " rows and " + std::to_string(n_c));
  // MUMPS keeps the Schur variables' order from the analysis; the list is set again as the
  // constructor sets it, so the instance is in the state the factoring one was in.
  f->listvar_.resize(n_c);
  for (Eigen::Index k = 0; k < n_c; ++k)
    f->listvar_[k] = static_cast<int>(schur[k] + 1);
  f->id_.listvar_schur = f->listvar_.data();
  f->stats_.infog7 = infog(f->id_, 7);
  const int e20 = infog(f->id_, 20);
  f->stats_.factor_entries = e20 >= 0 ? e20 : -static_cast<std::int64_t>(e20) * 1000000;
  f->schur_.assign(static_cast<std::size_t>(n_c) * n_c, 0.0);
  f->set_flexibility(F);
  return f;
}

void DistributedSchur::save(const std::string& dir, const std::string& prefix)
{
  if (!alive_)
    throw std::runtime_error("DistributedSchur.save: the factor was released");
  if (size_ != 1)
    throw std::invalid_argument("DistributedSchur.save: the factor is distributed over "
                                + std::to_string(size_) + " processes; only a serial one "
                                "is saved");
  set_save_files(id_, dir, prefix, "DistributedSchur");
  call(7, ("save to '" + dir + "/" + prefix + "'").c_str());
}

void DistributedSchur::factorize()
{
  double t0 = MPI_Wtime();
  // As in serial (flexibility.cpp): the workspace may need to grow.
  stats_.retries = factorize_growing_workspace(id_);
  stats_.factorization_s = MPI_Wtime() - t0;
  stats_.null_pivots = infog(id_, 28);
  throw_if_null_pivots(stats_.null_pivots);
  const int e29 = infog(id_, 29);
  stats_.factor_entries = e29 >= 0 ? e29 : -static_cast<std::int64_t>(e29) * 1000000;
  stats_.factor_flops = id_.rinfog[2];
  stats_.factor_memory_mb = infog(id_, 22);
  // The Dirichlet rows and the values are not needed any more: MUMPS holds the factor.
  std::vector<int>().swap(irn_);
  std::vector<int>().swap(jcn_);
  std::vector<double>().swap(a_);
  id_.irn_loc = id_.jcn_loc = nullptr;
  id_.a_loc = nullptr;
  id_.nnz_loc = 0;
  id_.nz_loc = 0;
}

void DistributedSchur::call(int job, const char* phase)
{
  id_.job = job;
  dmumps_c(&id_);
  if (infog(id_, 1) < 0) // INFOG is global: every rank throws
    throw_mumps_error(phase, infog(id_, 1), infog(id_, 2));
}

DistributedSchur::~DistributedSchur() { release(); }

void DistributedSchur::release()
{
  end_instance(id_, alive_);
  condensed_ = false;
  batch_k_ = 0;
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (!finalized and comm_ != MPI_COMM_NULL)
    MPI_Comm_free(&comm_);
  if (!finalized and !PetscFinalizeCalled)
  {
    VecScatterDestroy(&to_zero_);
    VecDestroy(&host_);
    VecScatterDestroy(&sol_scatter_);
    VecDestroy(&sol_seq_);
  }
  std::vector<double>().swap(schur_);
  std::vector<double>().swap(rhs_);
  std::vector<double>().swap(condensed_rhs_);
  std::vector<double>().swap(batch_rhs_);
  std::vector<double>().swap(batch_redrhs_);
  std::vector<double>().swap(rhs_loc_);
  std::vector<double>().swap(sol_buf_);
  std::vector<double>().swap(host_rhs_stub_);
}

const double* DistributedSchur::schur_complement()
{
  if (rank_ != 0 or schur_is_inverse_ or n_c_ == 0)
    return nullptr;
  // MUMPS gives the lower triangle by rows, i.e. the upper one read by columns: mirror it.
  const std::size_t n = static_cast<std::size_t>(n_c_);
  for (std::size_t j = 0; j < n; ++j)
    for (std::size_t i = j + 1; i < n; ++i)
      schur_[i + j * n] = schur_[j + i * n];
  return schur_.data();
}

void DistributedSchur::set_flexibility(const Eigen::MatrixXd& F)
{
  if (rank_ == 0)
  {
    if (F.rows() != n_c_ or F.cols() != n_c_)
      throw std::invalid_argument("F* has the wrong size");
    std::memcpy(schur_.data(), F.data(), schur_.size() * sizeof(double));
    schur_symmetric_ = F == F.transpose(); // once per factor: the solves then read half
  }
  schur_is_inverse_ = true;
}

void DistributedSchur::set_flexibility(std::shared_ptr<const BlockFlexibility> F)
{
  if (rank_ == 0)
  {
    if (!F or F->rows() != n_c_)
      throw std::invalid_argument("F* has the wrong size");
    factors_ = std::move(F);
  }
  schur_is_inverse_ = true;
}

void DistributedSchur::scatter_back(const double* host, Vec x)
{
  PetscErrorScope err;
  if (size_ == 1) // x is whole here: no scatter
  {
    PetscScalar* h = nullptr;
    err.check(VecGetArray(x, &h), "VecGetArray");
    std::copy(host, host + n_, h);
    err.check(VecRestoreArray(x, &h), "VecRestoreArray");
    return;
  }
  if (rank_ == 0)
  {
    PetscScalar* h = nullptr;
    err.check(VecGetArray(host_, &h), "VecGetArray");
    std::copy(host, host + n_, h);
    err.check(VecRestoreArray(host_, &h), "VecRestoreArray");
  }
  err.check(VecScatterBegin(to_zero_, host_, x, INSERT_VALUES, SCATTER_REVERSE), "VecScatterBegin");
  err.check(VecScatterEnd(to_zero_, host_, x, INSERT_VALUES, SCATTER_REVERSE), "VecScatterEnd");
}

void DistributedSchur::allocate_distributed_solution()
{
  PetscErrorScope err;
  // INFO(23): the rows of the distributed solution this rank receives (the Schur variables
  // among them: rank 0 sets those from u_c, stored after them).
  n_sol_loc_ = std::max(id_.info[22], 0);
  const std::size_t n_loc = std::max(n_sol_loc_, 1); // never a null SOL_loc for MUMPS
  isol_loc_.assign(n_loc, 0);
  sol_buf_.assign(n_loc + (rank_ == 0 ? static_cast<std::size_t>(n_c_) : 0), 0.0);
  err.check(VecCreateSeqWithArray(PETSC_COMM_SELF, 1, static_cast<PetscInt>(sol_buf_.size()),
                                  sol_buf_.data(), &sol_seq_),
            "VecCreateSeqWithArray");
}

void DistributedSchur::set_distributed_io(bool on) { distributed_io_ = on; }

void DistributedSchur::host_reduced_rhs()
{
  if (rank_ != 0)
    return;
  redrhs_.assign(n_c_, 0.0);
  id_.redrhs = redrhs_.data();
  id_.lredrhs = std::max(n_c_, 1);
}

std::vector<double> DistributedSchur::condense(Vec b)
{
  if (!alive_)
    throw std::runtime_error("the MUMPS factor was destroyed");
  times_ = {};
  if (distributed_io_)
  {
    try
    {
      condense_distributed(b);
    }
    catch (const MumpsError& e)
    {
      // MUMPS checks a solve's parameters before any work (INFOG(1) is global: every rank
      // is here); the factor is intact, so the centralised variant takes over.
      io_refusal_ = e.infog1;
      distributed_io_ = false;
      condense_centralised(b);
    }
  }
  else
    condense_centralised(b);
  condensed_ = true;
  batch_k_ = 0;
  return rank_ == 0 ? redrhs_ : std::vector<double>();
}

void DistributedSchur::condense_centralised(Vec b)
{
  PetscErrorScope err;
  double t0 = MPI_Wtime();
  Vec whole = b; // on one rank b is whole: no gather, only its size to check
  if (size_ == 1)
  {
    PetscInt n_b = 0;
    err.check(VecGetSize(b, &n_b), "VecGetSize");
    if (n_b != n_)
      throw std::invalid_argument("condense: b has " + std::to_string(n_b) + " rows, K "
                                  + std::to_string(n_));
  }
  else // the gather checks b's layout, collectively
  {
    if (!to_zero_) // only this variant needs the N values on rank 0
      err.check(VecScatterCreateToZero(b, &to_zero_, &host_), "VecScatterCreateToZero");
    err.check(VecScatterBegin(to_zero_, b, host_, INSERT_VALUES, SCATTER_FORWARD),
              "VecScatterBegin");
    err.check(VecScatterEnd(to_zero_, b, host_, INSERT_VALUES, SCATTER_FORWARD), "VecScatterEnd");
    whole = host_;
  }
  if (rank_ == 0)
  {
    const PetscScalar* h = nullptr;
    err.check(VecGetArrayRead(whole, &h), "VecGetArrayRead");
    condensed_rhs_.assign(h, h + n_);
    err.check(VecRestoreArrayRead(whole, &h), "VecRestoreArrayRead");
    id_.rhs = condensed_rhs_.data();
    id_.lrhs = static_cast<int>(n_);
  }
  times_.gather_s = MPI_Wtime() - t0;
  host_reduced_rhs();
  icntl(id_, 20) = 0; // dense right-hand side on the host
  icntl(id_, 21) = 0; // solution on the host
  id_.nrhs = 1;
  icntl(id_, 26) = n_c_ > 0 ? 1 : 0;
  t0 = MPI_Wtime();
  call(3, "condensation");
  times_.condense_s = MPI_Wtime() - t0;
  condensed_distributed_ = false;
}

void DistributedSchur::condense_distributed(Vec b)
{
  PetscErrorScope err;
  double t0 = MPI_Wtime();
  PetscInt n_loc = 0;
  err.check(VecGetLocalSize(b, &n_loc), "VecGetLocalSize");
  if (n_loc != rend_ - rstart_)
    throw std::invalid_argument("condense: b has " + std::to_string(n_loc) + " rows on rank "
                                + std::to_string(rank_) + ", K " + std::to_string(rend_ - rstart_));
  // A copy: MUMPS keeps RHS_loc's address until the expansion, b may be gone by then.
  const PetscScalar* v = nullptr;
  err.check(VecGetArrayRead(b, &v), "VecGetArrayRead");
  std::copy(v, v + n_loc, rhs_loc_.begin());
  err.check(VecRestoreArrayRead(b, &v), "VecRestoreArrayRead");
  times_.gather_s = MPI_Wtime() - t0;
  host_reduced_rhs();
  icntl(id_, 20) = 10; // dense right-hand side, each rank its own rows
  icntl(id_, 21) = 1;  // solution left where MUMPS eliminated it
  id_.nloc_rhs = static_cast<int>(n_loc);
  id_.lrhs_loc = std::max(static_cast<int>(n_loc), 1);
  id_.irhs_loc = irhs_loc_.data();
  id_.rhs_loc = rhs_loc_.data();
  id_.lsol_loc = std::max(static_cast<int>(isol_loc_.size()), 1);
  id_.isol_loc = isol_loc_.data();
  id_.sol_loc = sol_buf_.data();
  id_.nrhs = 1;
  icntl(id_, 26) = n_c_ > 0 ? 1 : 0;
  t0 = MPI_Wtime();
  call(3, "condensation (distributed right-hand side)");
  times_.condense_s = MPI_Wtime() - t0;
  condensed_distributed_ = true;
}

Eigen::MatrixXd DistributedSchur::condense_many(const Eigen::Ref<const Eigen::MatrixXd>& B)
{
  if (!alive_)
    throw std::runtime_error("the MUMPS factor was destroyed");
  if (size_ != 1)
    throw std::logic_error("condense_many: the factor is distributed over "
                           + std::to_string(size_) + " processes; several right-hand sides "
                           "at once are served on one");
  if (B.rows() != n_ or B.cols() < 1)
    throw std::invalid_argument("condense_many: B has " + std::to_string(B.rows()) + " rows and "
                                + std::to_string(B.cols()) + " columns; K has "
                                + std::to_string(n_) + " rows, and at least one is needed");
  times_ = {};
  const int k = static_cast<int>(B.cols());
  batch_rhs_.assign(B.data(), B.data() + B.size());
  batch_redrhs_.assign(static_cast<std::size_t>(n_c_) * k, 0.0);
  id_.rhs = batch_rhs_.data();
  id_.lrhs = static_cast<int>(n_);
  id_.redrhs = batch_redrhs_.data();
  id_.lredrhs = std::max(n_c_, 1);
  icntl(id_, 20) = 0;
  icntl(id_, 21) = 0;
  id_.nrhs = k;
  icntl(id_, 26) = n_c_ > 0 ? 1 : 0;
  const double t0 = MPI_Wtime();
  try
  {
    call(3, "condensation of several right-hand sides");
  }
  catch (...)
  {
    id_.nrhs = 1;
    batch_k_ = 0;
    condensed_ = false;
    throw;
  }
  times_.condense_s = MPI_Wtime() - t0;
  id_.nrhs = 1;
  condensed_ = true;
  condensed_distributed_ = false;
  batch_k_ = k;
  return Eigen::Map<const Eigen::MatrixXd>(batch_redrhs_.data(), n_c_, k);
}

Eigen::MatrixXd DistributedSchur::expand_many(const Eigen::Ref<const Eigen::MatrixXd>& U_c)
{
  if (!condensed_ or batch_k_ == 0)
    throw std::runtime_error("expand_many: no condense_many since the last expansion or "
                             "solve (one expansion per condensation)");
  if (U_c.rows() != n_c_ or U_c.cols() != batch_k_)
    throw std::invalid_argument("expand_many: U_c is " + std::to_string(U_c.rows()) + " × "
                                + std::to_string(U_c.cols()) + "; the last condense_many "
                                "needs " + std::to_string(n_c_) + " × "
                                + std::to_string(batch_k_));
  const int k = batch_k_;
  condensed_ = false;
  batch_k_ = 0;
  std::copy(U_c.data(), U_c.data() + U_c.size(), batch_redrhs_.begin());
  id_.rhs = batch_rhs_.data();
  id_.lrhs = static_cast<int>(n_);
  id_.redrhs = batch_redrhs_.data();
  id_.lredrhs = std::max(n_c_, 1);
  id_.nrhs = k;
  icntl(id_, 26) = n_c_ > 0 ? 2 : 0;
  const double t0 = MPI_Wtime();
  try
  {
    if (n_c_ > 0) // else the condensation was the whole solve
      call(3, "expansion of several right-hand sides");
  }
  catch (...)
  {
    id_.nrhs = 1;
    throw;
  }
  times_.expand_s = MPI_Wtime() - t0;
  id_.nrhs = 1;
  Eigen::MatrixXd X = Eigen::Map<const Eigen::MatrixXd>(batch_rhs_.data(), n_, k);
  // The Schur rows are U_c itself: set them from it, as the single expansion's scatter does.
  for (int j = 0; j < k; ++j)
    for (int i = 0; i < n_c_; ++i)
      X(schur_rows_[i], j) = U_c(i, j);
  return X;
}

void DistributedSchur::expand(std::span<const double> u_c, Vec x)
{
  if (!condensed_)
    throw std::runtime_error("expand: no condense since the last expand or solve (one "
                             "expansion per condensation)");
  if (batch_k_ > 0)
    throw std::runtime_error("expand: the last condensation was condense_many; expand its "
                             "right-hand sides with expand_many");
  // The centralised variant overwrites the kept forward elimination with the solution.
  condensed_ = false;
  if (condensed_distributed_)
  {
    expand_distributed(u_c, x);
    return;
  }
  if (rank_ == 0)
  {
    std::copy(u_c.begin(), u_c.end(), redrhs_.begin());
    id_.rhs = condensed_rhs_.data();
    id_.redrhs = redrhs_.data();
  }
  id_.nrhs = 1;
  icntl(id_, 26) = n_c_ > 0 ? 2 : 0;
  double t0 = MPI_Wtime();
  if (n_c_ > 0)
    call(3, "expansion");
  times_.expand_s = MPI_Wtime() - t0;
  t0 = MPI_Wtime();
  scatter_back(condensed_rhs_.data(), x);
  times_.scatter_s = MPI_Wtime() - t0;
}

void DistributedSchur::expand_distributed(std::span<const double> u_c, Vec x)
{
  PetscErrorScope err;
  if (rank_ == 0)
  {
    std::copy(u_c.begin(), u_c.end(), redrhs_.begin());
    id_.redrhs = redrhs_.data();
    // the Schur rows of x are u_c: set from here, whatever SOL_loc holds for them
    std::copy(u_c.begin(), u_c.end(), sol_buf_.begin() + static_cast<std::ptrdiff_t>(isol_loc_.size()));
  }
  id_.nrhs = 1;
  if (rank_ == 0)
  {
    // MUMPS 5.5's expansion with a distributed solution still needs the host's centralised
    // RHS array to exist (a null one is a segfault), though it neither reads nor writes it
    // here (measured: it stays zero); allocated once, never filled.
    if (host_rhs_stub_.size() != static_cast<std::size_t>(n_))
      host_rhs_stub_.assign(static_cast<std::size_t>(n_), 0.0);
    id_.rhs = host_rhs_stub_.data();
    id_.lrhs = static_cast<int>(n_);
  }
  double t0 = MPI_Wtime();
  if (n_c_ > 0) // else the condensation was the whole solve
  {
    icntl(id_, 26) = 2;
    call(3, "expansion (distributed solution)");
  }
  times_.expand_s = MPI_Wtime() - t0;
  t0 = MPI_Wtime();
  if (!sol_scatter_) // ISOL_loc is known once MUMPS has returned a solution
    build_solution_scatter(x);
  // MUMPS and u_c were written behind the Vec's back: get/restore marks it changed
  PetscScalar* touched = nullptr;
  err.check(VecGetArray(sol_seq_, &touched), "VecGetArray");
  err.check(VecRestoreArray(sol_seq_, &touched), "VecRestoreArray");
  err.check(VecScatterBegin(sol_scatter_, sol_seq_, x, INSERT_VALUES, SCATTER_FORWARD),
            "VecScatterBegin");
  err.check(VecScatterEnd(sol_scatter_, sol_seq_, x, INSERT_VALUES, SCATTER_FORWARD),
            "VecScatterEnd");
  times_.scatter_s = MPI_Wtime() - t0;
}

void DistributedSchur::build_solution_scatter(Vec x)
{
  PetscErrorScope err;
  std::vector<PetscInt> sorted(schur_rows_);
  std::sort(sorted.begin(), sorted.end());
  const auto tail = static_cast<PetscInt>(isol_loc_.size()); // rank 0's u_c from there
  std::vector<PetscInt> from, to;
  from.reserve(isol_loc_.size() + n_c_), to.reserve(isol_loc_.size() + n_c_);
  for (PetscInt i = 0; i < n_sol_loc_; ++i)
  {
    const PetscInt g = isol_loc_[i] - 1;
    if (!std::binary_search(sorted.begin(), sorted.end(), g)) // rank 0's u_c sets those
      from.push_back(i), to.push_back(g);
  }
  if (rank_ == 0)
    for (int k = 0; k < n_c_; ++k)
      from.push_back(tail + k), to.push_back(schur_rows_[k]);
  // Every row of x from exactly one place, or x would keep stale values somewhere.
  long long covered = static_cast<long long>(from.size()), total = 0;
  MPI_Allreduce(&covered, &total, 1, MPI_LONG_LONG, MPI_SUM, comm_);
  if (total != static_cast<long long>(n_))
    throw std::logic_error("MUMPS's distributed solution covers " + std::to_string(total)
                           + " of " + std::to_string(n_) + " rows");
  IS is_from = nullptr, is_to = nullptr;
  err.check(ISCreateGeneral(PETSC_COMM_SELF, static_cast<PetscInt>(from.size()), from.data(),
                            PETSC_COPY_VALUES, &is_from), "ISCreateGeneral");
  err.check(ISCreateGeneral(PETSC_COMM_SELF, static_cast<PetscInt>(to.size()), to.data(),
                            PETSC_COPY_VALUES, &is_to), "ISCreateGeneral");
  PetscErrorCode ierr = VecScatterCreate(sol_seq_, is_from, x, is_to, &sol_scatter_);
  ISDestroy(&is_from);
  ISDestroy(&is_to);
  err.check(ierr, "VecScatterCreate");
}

void DistributedSchur::solve(Vec b, Vec x)
{
  if (n_c_ > 0 and !schur_is_inverse_) // the same on every rank
    throw std::logic_error("DistributedSchur::solve before set_flexibility");
  std::vector<double> rb = condense(b);
  std::vector<double> uc(rb.size());
  if (rank_ == 0 and n_c_ > 0 and factors_)
    Eigen::Map<Eigen::VectorXd>(uc.data(), n_c_)
        = factors_->apply(Eigen::Map<const Eigen::VectorXd>(rb.data(), n_c_));
  else if (rank_ == 0 and n_c_ > 0)
  {
    Eigen::Map<const Eigen::MatrixXd> F(schur_.data(), n_c_, n_c_);
    Eigen::Map<const Eigen::VectorXd> r(rb.data(), n_c_);
    Eigen::Map<Eigen::VectorXd> u(uc.data(), n_c_);
    // The product streams F* from memory (the log's F* at the main job's mesh is 140 MB,
    // one product a step of its flight after the contact): its lower triangle is half.
    if (schur_symmetric_)
      u.noalias() = F.selfadjointView<Eigen::Lower>() * r;
    else
      u.noalias() = F * r;
  }
  expand(uc, x);
}

Flexibility flexcontact::distributed_flexibility(Mat K, const std::vector<PetscInt>& dofs,
                                                const std::string& ordering,
                                                const std::vector<std::vector<int>>& blocks,
                                                bool factors)
{
  MPI_Comm comm = PetscObjectComm(reinterpret_cast<PetscObject>(K));
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  Flexibility out;
  out.method = "schur";
  out.ordering = ordering;
  out.n_contact_dofs = static_cast<int>(dofs.size());
  const int icntl7 = mumps_icntl7(ordering);
  double t0 = MPI_Wtime();
  std::vector<int> perm_in;
  if (icntl7 == 1)
    perm_in = metis_pivot_order_gathered(K, dofs);
  out.ordering_s = MPI_Wtime() - t0;
  auto f = std::make_shared<DistributedSchur>(K, dofs, icntl7, std::move(perm_in));
  out.factorization_s = MPI_Wtime() - t0;
  const DistributedFactorStats& st = f->stats();
  out.analysis_s = st.analysis_s;
  out.factorizations = 1;
  out.factorization_retries = st.retries;
  out.null_pivots = st.null_pivots;
  out.mumps_ordering = ordering_name(st.infog7);
  out.factor_entries = st.factor_entries;
  out.factor_flops = st.factor_flops;
  out.factor_memory_mb = st.factor_memory_mb;

  double t1 = MPI_Wtime();
  const double* S = f->schur_complement();
  out.schur_s = MPI_Wtime() - t1;
  bool singular = false;
  std::string what;
  if (rank == 0 and !dofs.empty())
  {
    try
    {
      BlockFlexibility Fs = blockwise_cholesky(S, dofs.size(), blocks);
      if (factors)
        out.factors = std::make_shared<BlockFlexibility>(std::move(Fs));
      else
        out.F = Fs.dense();
    }
    catch (const SingularStiffnessError& e)
    {
      singular = true;
      what = e.what();
    }
  }
  throw_collective_if(comm, singular, what,
                      [](const std::string& w) { throw SingularStiffnessError(w); });
  if (out.factors)
    f->set_flexibility(std::shared_ptr<const BlockFlexibility>(out.factors));
  else
    f->set_flexibility(out.F);
  out.inverse_s = MPI_Wtime() - t1 - out.schur_s;
  out.distributed = std::move(f);
  return out;
}
