// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file stored_problems.hpp
/// @brief Reading the local problems stored under tests/data (tests/data/README.md and
/// random_problems.write_problem): an ASCII header of "key value…" lines after a first line
/// that names the format, a line starting "binary", then little-endian float64 values.

#include "flexcontact/problem.hpp"

#include <bit>
#include <cstddef>
#include <fstream>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace flexcontact::testing
{
static_assert(std::endian::native == std::endian::little,
              "the stored problems are little-endian");

/// @brief The float64 values of a stored problem, taken in the order they were written.
class StoredValues
{
public:
  explicit StoredValues(std::vector<double> v) : v_(std::move(v)) {}

  Vector take(Eigen::Index len)
  {
    Vector x = Eigen::Map<const Vector>(v_.data() + k_, len);
    k_ += static_cast<std::size_t>(len);
    return x;
  }

  /// @brief A symmetric n×n matrix stored as its upper triangle by rows.
  Matrix take_symmetric(Eigen::Index n)
  {
    Matrix W(n, n);
    for (Eigen::Index i = 0; i < n; ++i)
      for (Eigen::Index j = i; j < n; ++j)
        W(i, j) = W(j, i) = v_[k_++];
    return W;
  }

private:
  std::vector<double> v_;
  std::size_t k_ = 0;
};

/// @brief Reads the file at `path` in the format whose first line is `format`: each header
/// line goes to on_line(key, rest of the line), which returns false for a key it does not
/// know; once the header is read, count() (which may throw on a bad header) says how many
/// values must follow, exactly. `missing` is added to the error for a file that is not there.
inline StoredValues read_stored_values(
    const std::string& path, const std::string& format, const std::string& missing,
    const std::function<bool(const std::string& key, std::istringstream& rest)>& on_line,
    const std::function<std::size_t()>& count)
{
  std::ifstream f(path, std::ios::binary);
  if (!f)
    throw std::runtime_error(path + ": cannot open" + missing);
  std::string line;
  std::getline(f, line);
  if (line != format)
    throw std::runtime_error(path + ": first line '" + line + "', expected '" + format + "'");
  while (std::getline(f, line) && line.rfind("binary", 0) != 0)
  {
    std::istringstream in(line);
    std::string key;
    in >> key;
    if (!on_line(key, in))
      throw std::runtime_error(path + ": unknown header line '" + line + "'");
  }
  std::vector<double> v(count());
  f.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(v.size() * 8));
  if (!f || f.peek() != std::char_traits<char>::eof())
    throw std::runtime_error(path + ": binary part is not exactly " + std::to_string(v.size())
                             + " float64 values");
  return StoredValues(std::move(v));
}
} // namespace flexcontact::testing
