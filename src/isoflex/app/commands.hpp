#pragma once
// The subcommands of the `isoflex` tool. Each returns the process exit code (exit_codes.hpp):
// 0 success, 2 bad input (model file, options), 3 the simulation failed (Newton), 4 an output
// file could not be written, 130 / 143 the run was interrupted by SIGINT / SIGTERM.
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "isoflex/io/model_overrides.hpp"
#include "isoflex/model/model.hpp"

namespace isoflex::app {

struct RunOptions {
  std::string model_file;
  std::string outdir;  // default: out/<model file stem>
  std::optional<model::Formulation> formulation;
  std::optional<double> dt, t_end;
  std::optional<int> max_subdivisions;  // overrides solver.max_subdivisions (0 … 20)
  // Static equilibrium with load stepping (integrate::StaticEquilibrium): t is a load parameter.
  bool statics = false;
  // Threads of the Kirchhoff–Love shell assembly; 0 = every hardware thread. Results do not
  // depend on it (elements::ColouredElementLoop).
  int threads = 0;
  // The memory the run may use, bytes (--max-memory); default: MemAvailable of /proc/meminfo.
  // A model whose estimate (system/memory_estimate.hpp) exceeds it is refused (exit 2).
  std::optional<double> max_memory;
  // --set KEY=VALUE: model values over the file's (io/model_overrides.hpp), before --dt etc.
  std::vector<io::ModelOverride> overrides;
  // --restart FILE --from-step N: the run starts from the state of step N saved in FILE (a
  // results.h5, io/hdf5_results.hpp) and continues to t_end; empty: from t = 0.
  std::string restart_file;
  int restart_step = -1;
};

struct CheckOptions {
  std::optional<double> max_memory;          // as RunOptions::max_memory
  std::vector<io::ModelOverride> overrides;  // as RunOptions::overrides
};

int run_command(const RunOptions& o, std::FILE* out = stdout, std::FILE* err = stderr);
int check_command(const std::string& model_file, std::FILE* out = stdout, std::FILE* err = stderr,
                  const CheckOptions& options = {});
// check_command's report of a model already read (CheckOptions::overrides are not used: the
// reader applies them); Model::file names it in messages.
int check_model(model::Model m, std::FILE* out = stdout, std::FILE* err = stderr,
                const CheckOptions& options = {});

// A memory size as --max-memory takes it: a number of bytes with an optional suffix K, M, G or T
// (powers of 1024, as free(1) and /proc/meminfo count), optionally followed by B: "2G", "512M",
// "1.5GB", "3000000000". nullopt if `text` is not one, or not positive.
std::optional<double> parse_memory_size(const std::string& text);

}  // namespace isoflex::app
