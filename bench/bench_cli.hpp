#pragma once
// Command-line values shared by the benchmark programs: the walk over the arguments, comma lists,
// positive counts, times and formulation names. `usage` is the program's own [[noreturn]] error
// exit (message, exit code 2).
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

// The walk over argv: `while (args.next())` visits each argument, `is("--x")` names it, `value()`
// takes the one after it (usage() when there is none), `count`, `number` and `counts` parse it.
class Args {
 public:
  Args(int argc, char** argv, Usage usage) : argc_(argc), argv_(argv), usage_(usage) {}

  bool next() {
    if (++i_ >= argc_) return false;
    arg_ = argv_[i_];
    return true;
  }
  const std::string& arg() const { return arg_; }
  bool is(const char* name) const { return arg_ == name; }

  std::string value() {
    if (i_ + 1 >= argc_) usage_(arg_ + " needs a value");
    return argv_[++i_];
  }
  int count(const std::string& what) { return static_cast<int>(parse_int(value(), what, usage_)); }
  double number(const std::string& what) { return parse_double(value(), what, usage_); }
  // A comma list of counts > 0, at least one.
  std::vector<int> counts(const std::string& what) {
    std::vector<int> out;
    for (const auto& s : split(value()))
      out.push_back(static_cast<int>(parse_int(s, what, usage_)));
    if (out.empty()) usage_(arg_ + " needs at least one " + what);
    return out;
  }
  // -h, --help or an argument the program does not know.
  [[noreturn]] void unknown() const {
    usage_(arg_ == "-h" || arg_ == "--help" ? "help" : fmt::format("unknown argument '{}'", arg_));
    std::exit(2);
  }

 private:
  int argc_;
  char** argv_;
  Usage usage_;
  int i_ = 0;
  std::string arg_;
};

}  // namespace isoflex::bench
