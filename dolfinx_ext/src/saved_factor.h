// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file saved_factor.h
/// @brief A serial LDLᵀ factor of a symmetric matrix that can be written to files and read
/// back in another process, so a body factored once (the dam of a sweep) is never
/// refactored (docs/architecture.md §7, "A factor kept on disk").
///
/// MUMPS saves an instance's factor with JOB=7 and restores it into a new instance with
/// JOB=8; this class owns its instance (not PETSc's), on MPI_COMM_SELF. The files are only
/// valid for the same MUMPS version: the Python side (saved_factor.py) records it and checks
/// the files' sizes and hashes before MUMPS reads them.

#include <Eigen/Dense>
#include <dmumps_c.h>
#include <petscmat.h>

#include <string>
#include <vector>

namespace flexcontact
{
class SavedFactor
{
public:
  /// @brief Factor the symmetric serial matrix A (its upper triangle is read).
  /// @throws MumpsError, SingularStiffnessError (null pivots), std::invalid_argument
  explicit SavedFactor(Mat A);

  /// @brief The factor saved by `save(dir, prefix)` of a matrix of n rows.
  /// @throws MumpsError naming the files if MUMPS cannot restore them
  SavedFactor(const std::string& dir, const std::string& prefix, PetscInt n);

  SavedFactor(const SavedFactor&) = delete;
  SavedFactor& operator=(const SavedFactor&) = delete;
  ~SavedFactor();

  /// @brief Write the factor as MUMPS files `<dir>/<prefix>_*` (JOB=7).
  void save(const std::string& dir, const std::string& prefix);

  /// @brief x = A⁻¹ b (serial Vecs of n entries); one back-substitution.
  void solve(Vec b, Vec x);

  /// @brief X = A⁻¹ B for the k columns of B (n × k) in one MUMPS call, which reads the
  /// factor once for all of them (docs/architecture.md §7, "Several right-hand sides at
  /// once").
  /// @throws std::invalid_argument on B's row count
  Eigen::MatrixXd solve_many(const Eigen::Ref<const Eigen::MatrixXd>& B);

  PetscInt size() const { return n_; }
  /// @brief Entries of the factor (INFOG(29), or INFOG(20) once restored).
  double factor_entries() const;
  void release();

private:
  void init();
  void call(int job, const std::string& phase);

  DMUMPS_STRUC_C id_{};
  bool alive_ = false;
  PetscInt n_ = 0;
  std::vector<int> irn_, jcn_;
  std::vector<double> a_, rhs_;
};
} // namespace flexcontact
