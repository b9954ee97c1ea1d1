#pragma once
// Runs the `isoflex` executable of the build (ISOFLEX_BINARY) for end-to-end tests.
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace isoflex::test {

struct CliResult {
  int code;         // exit status (−1 if it did not exit normally)
  std::string out;  // stdout and stderr
};

// The shell command `command` (sh -c), with stderr folded into stdout.
inline CliResult run_shell(const std::string& command) {
  const std::string cmd = "(" + command + ") 2>&1";
  CliResult r{-1, {}};
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  std::array<char, 4096> buf;
  while (fgets(buf.data(), buf.size(), p)) r.out += buf.data();
  const int status = pclose(p);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

// `isoflex ARGS`, with stderr folded into stdout.
inline CliResult run_isoflex(const std::string& args) {
  return run_shell(std::string(ISOFLEX_BINARY) + " " + args);
}

}  // namespace isoflex::test
