#pragma once
// SIGINT and SIGTERM as a request to stop a run between two steps (README "Exit codes").
//
// While an InterruptHandlers object lives, the two signals only record which of them arrived
// (the handler is async-signal-safe: it stores the signal number and returns); the run loop asks
// throw_if_interrupted() after each step, finishes its outputs and exits with 128 + the signal. A
// second signal at least a second after the first ends the process at once (a run stuck in a long
// Newton step can still be stopped); one within the second is taken for a duplicate of the first
// (a process-group kill that a supervisor such as `timeout` also forwards) and ignored. A signal
// that was ignored when the process started (`nohup`, background jobs of a non-interactive shell)
// stays ignored.
#include <signal.h>

#include <string>

namespace isoflex::app {

class InterruptHandlers {
 public:
  InterruptHandlers();   // installs the handlers and clears the flag
  ~InterruptHandlers();  // restores the previous handlers
  InterruptHandlers(const InterruptHandlers&) = delete;
  InterruptHandlers& operator=(const InterruptHandlers&) = delete;

 private:
  struct sigaction previous_int_ {};
  struct sigaction previous_term_ {};
  bool installed_int_ = false, installed_term_ = false;
};

// Thrown by throw_if_interrupted. Not a std::exception, so that no `catch (const
// std::exception&)` on the way (a solver's, around a step) takes it for a failure.
struct Interrupted {
  int signal;
};

// Throws Interrupted when SIGINT or SIGTERM has arrived since the handlers were installed. Called
// by the run driver after each step: a static run's load steps are driven by the solver
// (integrate::StaticNewtonSolver), and the observer it calls after each step can only leave that
// loop by an exception.
void throw_if_interrupted();

// "SIGINT", "SIGTERM" or "signal N".
std::string signal_name(int sig);

}  // namespace isoflex::app
