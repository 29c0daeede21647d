#include "cli/interrupt.hpp"

#include <unistd.h>

#include <csignal>

namespace gvio::cli {
namespace {

volatile std::sig_atomic_t g_signal = 0;  // NOLINT: written by the handler, see the header

extern "C" void onInterrupt(int signal) {
  g_signal = signal;
  // write(2) is async-signal-safe; the handler was installed with SA_RESETHAND, so the same
  // signal again takes the default action and ends the process at once.
  constexpr char kMessage[] =
      "\ngvio: stopping after this frame or stage (send the signal again to stop at once)\n";
  [[maybe_unused]] const auto n = ::write(STDERR_FILENO, kMessage, sizeof kMessage - 1);
}

}  // namespace

InterruptGuard::InterruptGuard() {
  g_signal = 0;
  struct sigaction action {};
  action.sa_handler = onInterrupt;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESETHAND | SA_RESTART;  // restart reads and writes the signal interrupted
  sigaction(SIGINT, &action, &previous_int_);
  sigaction(SIGTERM, &action, &previous_term_);
}

InterruptGuard::~InterruptGuard() {
  sigaction(SIGINT, &previous_int_, nullptr);
  sigaction(SIGTERM, &previous_term_, nullptr);
}

int InterruptGuard::pending() {
  return static_cast<int>(g_signal);
}

void ignoreFileSizeSignal() {
  std::signal(SIGXFSZ, SIG_IGN);
}

}  // namespace gvio::cli
