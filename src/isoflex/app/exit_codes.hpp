#pragma once
// The exit codes of `isoflex run` and `isoflex check` (README "Exit codes"), with the `status` of
// summary.json that goes with each (io::RunSummary).
namespace isoflex::app {

inline constexpr int kExitSuccess = 0;  // "completed"
// Model file or options, or a model whose memory estimate exceeds the memory available
// (system/memory_estimate.hpp, --max-memory); nothing is written.
inline constexpr int kExitBadInput = 2;
// "failed": a step did not converge, gave non-finite values, or the memory ran out (compiling
// the model, setting up, or in a step: the message says which).
inline constexpr int kExitNewtonFailure = 3;
inline constexpr int kExitOutputError = 4;  // "output_error": a file could not be written

// "interrupted" by SIGINT or SIGTERM: 128 + the signal (130, 143), the code a shell reports for
// a process the signal ended, so that scripts see the same whether or not isoflex caught it.
constexpr int exit_code_for_signal(int sig) {
  return 128 + sig;
}

}  // namespace isoflex::app
