#pragma once
// A double as text with 17 significant digits (round-trips exactly), for error messages that
// quote the offending value.
#include <cstdio>
#include <string>

namespace isoflex {

inline std::string exact_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

}  // namespace isoflex
