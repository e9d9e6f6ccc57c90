// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file python_float.hpp
/// @brief Numbers written as Python's repr() writes them, so that messages built here read
/// the same as those the Python layer writes (and users' scripts may match them).

#include <charconv>
#include <cmath>
#include <string>

namespace flexcontact::detail
{
/// @brief repr() of a Python float: the shortest digits that round-trip, in fixed notation
/// with at least one decimal ("0.5", "2.0") unless the decimal exponent is below −4 or
/// above 15 ("1e-05", "1.5e+16").
inline std::string python_float(double v)
{
  if (std::isnan(v))
    return "nan";
  if (std::isinf(v))
    return v > 0 ? "inf" : "-inf";
  char buf[64];
  // Shortest round-trip digits, as "d.ddde±x".
  auto [end, ec] = std::to_chars(buf, buf + sizeof buf, std::abs(v),
                                 std::chars_format::scientific);
  std::string s(buf, end);
  const auto e = s.find('e');
  std::string digits = s.substr(0, e);
  if (digits.size() > 1)
    digits.erase(1, 1); // the point
  const int exponent = std::stoi(s.substr(e + 1));
  const int decpt = exponent + 1; // digits before the point
  const int n = static_cast<int>(digits.size());
  std::string out = std::signbit(v) ? "-" : "";
  if (decpt <= -4 || decpt > 16)
  {
    out += digits.substr(0, 1);
    if (n > 1)
      out += "." + digits.substr(1);
    const int a = std::abs(exponent);
    out += std::string(exponent < 0 ? "e-" : "e+") + (a < 10 ? "0" : "") + std::to_string(a);
  }
  else if (decpt <= 0)
    out += "0." + std::string(-decpt, '0') + digits;
  else if (decpt >= n)
    out += digits + std::string(decpt - n, '0') + ".0";
  else
    out += digits.substr(0, decpt) + "." + digits.substr(decpt);
  return out;
}
} // namespace flexcontact::detail
