// Copyright flexcontact developers. MIT licence.
#pragma once

/// @file message_numbers.hpp
/// @brief Numbers in the kernel's error messages and attempt lines, written one way
/// everywhere so that users (and their scripts) read the same form from every object.

#include <cstdio>
#include <string>

namespace flexcontact::detail
{
/// @brief printf's "%.3e" ("1.234e-05"): residuals and lengths, whose magnitude matters more
/// than their digits.
inline std::string exp3(double v)
{
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3e", v);
  return buf;
}

/// @brief printf's "%g" ("0.3", "1e-05", "nan"): a parameter as a user would have written it.
inline std::string num(double v)
{
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}
} // namespace flexcontact::detail
