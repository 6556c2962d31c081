#pragma once
// Strict number parsing for hand-written text formats (CSV, pair files): the whole field must be
// the number ("0.12abc" is not 0.12, as std::stod would have it), and it must be finite.
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <string>

namespace trimbot {

// Whether nothing but spaces, tabs and a CR follow: the number was the whole field.
inline bool OnlyBlanks(const char* rest) {
  for (const char* c = rest; *c != '\0'; ++c) {
    if (*c != ' ' && *c != '\t' && *c != '\r') return false;
  }
  return true;
}

inline std::optional<double> ParseFiniteNumber(const std::string& text) {
  const auto first = text.find_first_not_of(" \t\r");
  if (first == std::string::npos) return std::nullopt;
  const char* begin = text.c_str() + first;
  char* end = nullptr;
  errno = 0;
  const double value = std::strtod(begin, &end);
  if (end == begin || errno == ERANGE || !std::isfinite(value) || !OnlyBlanks(end)) return std::nullopt;
  return value;
}

// A whole number within [lo, hi] ("3.0" and "3e0" are refused: an id or a count is written as one).
inline std::optional<long long> ParseInteger(const std::string& text, long long lo, long long hi) {
  const auto first = text.find_first_not_of(" \t\r");
  if (first == std::string::npos) return std::nullopt;
  const char* begin = text.c_str() + first;
  char* end = nullptr;
  errno = 0;
  const long long value = std::strtoll(begin, &end, 10);
  if (end == begin || errno == ERANGE || value < lo || value > hi || !OnlyBlanks(end)) return std::nullopt;
  return value;
}

}  // namespace trimbot
