// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file problem_file.hpp
/// @brief One local problem as a file: everything solve() was given, so that a failure can
/// be re-run, bitwise, elsewhere (docs/solvers.md, "A failing problem as a file").

#include "flexcontact/problem.hpp"

#include <string>
#include <vector>

namespace flexcontact
{
/// @brief What solve() was given: u = W λ + q, μ, the caps, the start and the options.
struct LocalProblem
{
  int dim = 0;
  Matrix W;
  Vector q;
  Vector mu;
  Vector cap;                       ///< m caps of the normal forces, or empty for none
  Vector lambda_start;              ///< the start λ0 (empty: zero)
  std::vector<PairState> states_start; ///< the start states (empty: none)
  SolverOptions options;            ///< verbose is not kept
  std::string source;               ///< where it came from, one line of free text

  int pairs() const { return dim > 0 ? static_cast<int>(q.size()) / dim : 0; }
  ProblemView view() const
  {
    return ProblemView{dim, W, q, mu, cap.size() ? cap.data() : nullptr};
  }
};

/// @brief The file's bytes (format 3 of docs/solvers.md): an ASCII header, then
/// little-endian float64 values. W is kept as its upper triangle when it is exactly
/// symmetric and whole otherwise, so that reading gives back every bit.
std::string local_problem_bytes(const LocalProblem& p);

/// @brief Writes local_problem_bytes(p) to path (replacing it).
void write_local_problem(const std::string& path, const LocalProblem& p);

/// @brief Reads format 3, and format 2 of the recorded problems under tests/data (their
/// previous increment's λ and states are the start). Throws std::runtime_error naming the
/// path and what is wrong.
LocalProblem read_local_problem(const std::string& path);

/// @brief solve() on the problem, from its start, with its options.
SolveReport solve(const LocalProblem& p);
} // namespace flexcontact
