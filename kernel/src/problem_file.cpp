// Copyright flexcontact developers. MIT licence.

/// @file problem_file.cpp
/// @brief The local-problem file of problem_file.hpp: writing, reading, re-running.

#include "flexcontact/problem_file.hpp"
#include "flexcontact/solvers.hpp"

#include <bit>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace flexcontact
{
static_assert(std::endian::native == std::endian::little,
              "the problem files hold little-endian float64");

namespace
{
constexpr const char* format2 = "flexcontact-local-problem 2";
constexpr const char* format3 = "flexcontact-local-problem 3";

/// @brief %.17g: enough digits that reading the number back gives the same double.
std::string exact(double x)
{
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

bool exactly_symmetric(const Matrix& W)
{
  for (Eigen::Index i = 0; i < W.rows(); ++i)
    for (Eigen::Index j = i + 1; j < W.cols(); ++j)
      if (std::memcmp(&W(i, j), &W(j, i), sizeof(double)) != 0)
        return false;
  return true;
}

void append(std::string& out, const double* v, Eigen::Index n)
{
  out.append(reinterpret_cast<const char*>(v), static_cast<std::size_t>(n) * sizeof(double));
}

std::vector<PairState> read_states(std::istringstream& in, const std::string& path)
{
  std::vector<PairState> s;
  std::string word;
  while (in >> word)
  {
    if (word == "none")
      return {};
    int v = -1;
    try
    {
      v = std::stoi(word);
    }
    catch (const std::exception&)
    {
    }
    if (v < static_cast<int>(PairState::open) || v > static_cast<int>(PairState::crush))
      throw std::runtime_error(path + ": state '" + word + "' is not 1, 2, 3 or 4");
    s.push_back(static_cast<PairState>(v));
  }
  return s;
}

/// @brief Takes the float64 values in the order they were written.
class Values
{
public:
  Values(std::vector<double> v) : v_(std::move(v)) {}
  Vector take(Eigen::Index len)
  {
    Vector x = Eigen::Map<const Vector>(v_.data() + k_, len);
    k_ += static_cast<std::size_t>(len);
    return x;
  }
  Matrix take_matrix(Eigen::Index n, bool symmetric)
  {
    Matrix W(n, n);
    for (Eigen::Index i = 0; i < n; ++i)
      for (Eigen::Index j = symmetric ? i : 0; j < n; ++j)
      {
        W(i, j) = v_[k_++];
        if (symmetric)
          W(j, i) = W(i, j);
      }
    return W;
  }

private:
  std::vector<double> v_;
  std::size_t k_ = 0;
};
} // namespace

std::string local_problem_bytes(const LocalProblem& p)
{
  const int m = p.pairs();
  const Eigen::Index n = p.q.size();
  if ((p.dim != 2 && p.dim != 3) || n != static_cast<Eigen::Index>(m) * p.dim || m < 1
      || p.W.rows() != n || p.W.cols() != n || p.mu.size() != m
      || (p.cap.size() != 0 && p.cap.size() != m)
      || (p.lambda_start.size() != 0 && p.lambda_start.size() != n)
      || (!p.states_start.empty() && static_cast<int>(p.states_start.size()) != m))
    throw std::invalid_argument("flexcontact: write_local_problem: inconsistent sizes (dim "
                                + std::to_string(p.dim) + ", " + std::to_string(n)
                                + " unknowns)");
  const bool symmetric = exactly_symmetric(p.W);
  std::ostringstream h;
  h << format3 << "\n";
  std::string source = p.source;
  for (char& c : source)
    if (c == '\n' || c == '\r')
      c = ' ';
  h << "source " << source << "\n";
  h << "dim " << p.dim << "\npairs " << m << "\nstates_start";
  if (p.states_start.empty())
    h << " none";
  for (PairState s : p.states_start)
    h << " " << static_cast<int>(s);
  h << "\ncaps " << (p.cap.size() ? "yes" : "no") << "\n";
  h << "tolerance " << exact(p.options.tolerance) << "\n";
  h << "max_iterations " << p.options.max_iterations << "\n";
  h << "chain";
  if (p.options.chain.empty())
    h << " default";
  for (const auto& c : p.options.chain)
    h << " " << c;
  h << "\nwork_budget_gflop " << exact(p.options.work_budget_gflop) << "\n";
  h << "W " << (symmetric ? "symmetric" : "full") << "\n";
  h << "binary float64 little-endian: mu[pairs], W (upper triangle by rows if symmetric, "
       "else all by rows), q, lambda_start, cap[pairs] if caps\n";
  std::string out = h.str();
  append(out, p.mu.data(), m);
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = symmetric ? i : 0; j < n; ++j)
      append(out, &p.W(i, j), 1);
  append(out, p.q.data(), n);
  const Vector start = p.lambda_start.size() ? p.lambda_start : Vector(Vector::Zero(n));
  append(out, start.data(), n);
  if (p.cap.size())
    append(out, p.cap.data(), m);
  return out;
}

void write_local_problem(const std::string& path, const LocalProblem& p)
{
  const std::string bytes = local_problem_bytes(p);
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  f.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!f)
    throw std::runtime_error("flexcontact: cannot write the local problem to " + path);
}

LocalProblem read_local_problem(const std::string& path)
{
  std::ifstream f(path, std::ios::binary);
  if (!f)
    throw std::runtime_error(path + ": cannot open");
  std::string line;
  std::getline(f, line);
  const bool v3 = line == format3;
  if (!v3 && line != format2)
    throw std::runtime_error(path + ": first line '" + line.substr(0, 60) + "', expected '"
                             + format3 + "' (or 2)");
  LocalProblem p;
  int m = -1;
  bool caps = false, symmetric = true;
  while (std::getline(f, line) && line.rfind("binary", 0) != 0)
  {
    std::istringstream in(line);
    std::string key;
    in >> key;
    if (key == "source")
      std::getline(in >> std::ws, p.source);
    else if (key == "dim")
      in >> p.dim;
    else if (key == "pairs")
      in >> m;
    else if (key == "states_start" || key == "states_previous")
      p.states_start = read_states(in, path);
    else if (key == "states")
      read_states(in, path); // format 2: the recorded answer's, checked only
    else if (key == "caps")
    {
      std::string v;
      in >> v;
      caps = v == "yes";
    }
    else if (key == "tolerance")
      in >> p.options.tolerance;
    else if (key == "max_iterations")
      in >> p.options.max_iterations;
    else if (key == "chain")
    {
      std::string name;
      while (in >> name)
        if (name != "default")
          p.options.chain.push_back(name);
    }
    else if (key == "work_budget_gflop")
      in >> p.options.work_budget_gflop;
    else if (key == "W")
    {
      std::string v;
      in >> v;
      symmetric = v != "full";
    }
    else if (key == "solver" || key == "residual")
      continue; // format 2: the recorded answer's
    else
      throw std::runtime_error(path + ": unknown header line '" + line.substr(0, 60) + "'");
    if (in.fail() && !in.eof())
      throw std::runtime_error(path + ": cannot read header line '" + line.substr(0, 60) + "'");
  }
  if ((p.dim != 2 && p.dim != 3) || m < 1
      || (!p.states_start.empty() && static_cast<int>(p.states_start.size()) != m))
    throw std::runtime_error(path + ": bad header (dim " + std::to_string(p.dim) + ", pairs "
                             + std::to_string(m) + ", or the start states' count)");
  const std::size_t n = static_cast<std::size_t>(m) * p.dim;
  const std::size_t w = symmetric ? n * (n + 1) / 2 : n * n;
  // Format 2 holds the recorded λ before the previous one, which is its start.
  const std::size_t count = m + w + (v3 ? 2 * n + (caps ? m : 0) : 3 * n);
  std::vector<double> v(count);
  f.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(count * 8));
  if (!f || f.peek() != std::char_traits<char>::eof())
    throw std::runtime_error(path + ": the binary part is not exactly " + std::to_string(count)
                             + " float64 values");
  Values values(std::move(v));
  const auto N = static_cast<Eigen::Index>(n);
  p.mu = values.take(m);
  p.W = values.take_matrix(N, symmetric);
  p.q = values.take(N);
  if (!v3)
    values.take(N);
  p.lambda_start = values.take(N);
  if (caps)
    p.cap = values.take(m);
  return p;
}

SolveReport solve(const LocalProblem& p)
{
  return solve(p.view(), p.lambda_start, p.states_start, p.options);
}
} // namespace flexcontact
