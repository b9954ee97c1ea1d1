#include "isoflex/app/interrupt.hpp"

#include <time.h>

#include <csignal>

namespace isoflex::app {

namespace {

// The only global mutable state: a signal handler can reach nothing else, and only objects of
// this type may be written from it (C++20 [support.signal]).
volatile std::sig_atomic_t g_signal = 0;
volatile std::sig_atomic_t g_first_second = 0;  // CLOCK_MONOTONIC seconds of the first signal

// The first signal is recorded. A later one ends the process at once (default action) only if it
// comes at least a second after the first: the same SIGTERM often arrives twice within
// microseconds — `kill -- -PGID` reaches both `timeout` and isoflex, and `timeout` forwards its
// copy — and a duplicate must not undo the orderly stop (it did, 4 of 12 runs lost summary.json).
// A user's second Ctrl-C or kill is seconds later. clock_gettime, signal and raise are
// async-signal-safe (POSIX.1-2008 §2.4.3).
extern "C" void record_signal(int sig) {
  timespec now{};
  clock_gettime(CLOCK_MONOTONIC, &now);
  const auto second = static_cast<std::sig_atomic_t>(now.tv_sec);
  if (g_signal == 0) {
    g_first_second = second;
    g_signal = sig;
    return;
  }
  if (second - g_first_second >= 2) {
    signal(sig, SIG_DFL);
    raise(sig);  // delivered when the handler returns (the signal is blocked inside it)
  }
}

// Installs record_signal for `sig` unless the process started with `sig` ignored; returns
// whether it did, with the previous action in `previous`.
bool install(int sig, struct sigaction& previous) {
  if (sigaction(sig, nullptr, &previous) != 0 || previous.sa_handler == SIG_IGN) return false;
  struct sigaction action {};
  action.sa_handler = record_signal;
  sigemptyset(&action.sa_mask);
  // SA_RESTART: the writes in progress go on.
  action.sa_flags = SA_RESTART;
  return sigaction(sig, &action, nullptr) == 0;
}

}  // namespace

InterruptHandlers::InterruptHandlers() {
  g_signal = 0;
  installed_int_ = install(SIGINT, previous_int_);
  installed_term_ = install(SIGTERM, previous_term_);
}

InterruptHandlers::~InterruptHandlers() {
  if (installed_int_) sigaction(SIGINT, &previous_int_, nullptr);
  if (installed_term_) sigaction(SIGTERM, &previous_term_, nullptr);
}

void throw_if_interrupted() {
  if (const int sig = g_signal; sig != 0) throw Interrupted{sig};
}

std::string signal_name(int sig) {
  if (sig == SIGINT) return "SIGINT";
  if (sig == SIGTERM) return "SIGTERM";
  return "signal " + std::to_string(sig);
}

}  // namespace isoflex::app
