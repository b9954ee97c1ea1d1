#pragma once
// Command-line values shared by the benchmark programs: comma lists, positive counts, times and
// formulation names. `usage` is the program's own [[noreturn]] error exit (message, exit code 2).
#include <fmt/format.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "isoflex/model/model.hpp"

namespace isoflex::bench {

using Usage = void (*)(const std::string& message);

// "a,b,,c" → {a, b, c}.
inline std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (start <= s.size()) {
    const std::size_t comma = s.find(',', start);
    const std::size_t end = comma == std::string::npos ? s.size() : comma;
    if (end > start) out.push_back(s.substr(start, end - start));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

inline long parse_int(const std::string& s, const std::string& what, Usage usage) {  // > 0
  char* end = nullptr;
  const long v = std::strtol(s.c_str(), &end, 10);
  if (s.empty() || *end != '\0' || v <= 0) usage(fmt::format("bad {} '{}'", what, s));
  return v;
}

inline double parse_double(const std::string& s, const std::string& what, Usage usage) {  // >= 0
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || *end != '\0' || !(v >= 0)) usage(fmt::format("bad {} '{}'", what, s));
  return v;
}

inline std::vector<model::Formulation> parse_formulations(const std::string& list, Usage usage) {
  std::vector<model::Formulation> out;
  for (const auto& s : split(list)) {
    const auto f = model::formulation_from_string(s);
    if (!f) usage(fmt::format("unknown formulation '{}'", s));
    out.push_back(*f);
  }
  if (out.empty()) usage("--formulations needs at least one formulation");
  return out;
}

}  // namespace isoflex::bench
