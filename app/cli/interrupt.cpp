#include "cli/interrupt.hpp"

#include <unistd.h>

#include <atomic>
#include <csignal>

namespace gvio::cli {
namespace {

// Written by the handler on whichever thread takes the signal, read by the run's thread: a
// lock-free atomic is both async-signal-safe and free of data races (a volatile sig_atomic_t is
// only the former).
std::atomic<int> g_signal{0};  // NOLINT: see the header
static_assert(std::atomic<int>::is_always_lock_free);

extern "C" void onInterrupt(int signal) {
  g_signal = signal;
  // write(2) is async-signal-safe; the handler was installed with SA_RESETHAND, so the same
  // signal again takes the default action and ends the process at once.
  constexpr char kMessage[] =
      "\ngvio: stopping after this frame or stage (send the signal again to stop at once)\n";
  [[maybe_unused]] const auto n = ::write(STDERR_FILENO, kMessage, sizeof kMessage - 1);
}

}  // namespace

InterruptGuard::InterruptGuard(bool restart_calls) {
  g_signal = 0;
  struct sigaction action {};
  action.sa_handler = onInterrupt;
  sigemptyset(&action.sa_mask);
  // Restart reads and writes the signal interrupted (unless the caller waits for it).
  action.sa_flags = SA_RESETHAND | (restart_calls ? SA_RESTART : 0);
  sigaction(SIGINT, &action, &previous_int_);
  sigaction(SIGTERM, &action, &previous_term_);
}

InterruptGuard::~InterruptGuard() {
  sigaction(SIGINT, &previous_int_, nullptr);
  sigaction(SIGTERM, &previous_term_, nullptr);
}

int InterruptGuard::pending() {
  return g_signal.load();
}

void ignoreFileSizeSignal() {
  std::signal(SIGXFSZ, SIG_IGN);
}

}  // namespace gvio::cli
