#include "isoflex/app/interrupt.hpp"

#include <csignal>

namespace isoflex::app {

namespace {

// The one piece of global mutable state: a signal handler can reach nothing else, and only an
// object of this type may be written from it (C++20 [support.signal]).
volatile std::sig_atomic_t g_signal = 0;

extern "C" void record_signal(int sig) {
  g_signal = sig;
}

// Installs record_signal for `sig` unless the process started with `sig` ignored; returns
// whether it did, with the previous action in `previous`.
bool install(int sig, struct sigaction& previous) {
  if (sigaction(sig, nullptr, &previous) != 0 || previous.sa_handler == SIG_IGN) return false;
  struct sigaction action {};
  action.sa_handler = record_signal;
  sigemptyset(&action.sa_mask);
  // SA_RESTART: the writes in progress go on; SA_RESETHAND: a second signal ends the process.
  action.sa_flags = SA_RESTART | SA_RESETHAND;
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
