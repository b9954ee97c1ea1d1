#pragma once
// The example model files for tests: their text, and variants made by replacing a piece of it.
#include <gtest/gtest.h>

#include <string>

#include "support/files.hpp"

namespace isoflex::test {

// The text of examples/DIR/FILE (a failed expectation if it is missing or empty).
inline std::string example_text(const std::string& dir, const std::string& file) {
  const std::string text =
      read_text(std::string(ISOFLEX_SOURCE_DIR) + "/examples/" + dir + "/" + file);
  EXPECT_FALSE(text.empty()) << dir << "/" << file;
  return text;
}

// `text` with the first `from` replaced by `to` (a failed expectation if `from` is not there).
inline std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// `text` with every `from` replaced by `to` (a failed expectation if there is none).
inline std::string replaced_all(std::string text, const std::string& from, const std::string& to) {
  EXPECT_NE(text.find(from), std::string::npos) << from;
  for (auto at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
    text.replace(at, from.size(), to);
  return text;
}

}  // namespace isoflex::test
