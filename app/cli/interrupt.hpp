#pragma once
// SIGINT (Ctrl-C) and SIGTERM during `gvio run`: the first one asks the run to stop at the next
// frame or stage boundary, where it marks its folder incomplete and exits 128 + the signal's
// number (130, 143) as shells expect; a second one ends the process at once (the default action).
// A signal handler can only reach state of static duration, so the signal received is the one
// global of this program, confined to this file.
#include <signal.h>

namespace gvio::cli {

class InterruptGuard {
 public:
  // Installs the handlers. With `restart_calls` false, a blocking call the signal interrupts
  // (waitpid of a fleet's children) returns EINTR instead of resuming, so its caller sees it.
  explicit InterruptGuard(bool restart_calls = true);
  ~InterruptGuard();  // restores the previous ones
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;

  // The signal received since construction (SIGINT or SIGTERM), 0 for none.
  [[nodiscard]] static int pending();

 private:
  struct sigaction previous_int_ {
  }, previous_term_{};
};

// Writes past the file size limit (ulimit -f) fail with EFBIG instead of killing the process with
// SIGXFSZ, so they are reported like a full disk.
void ignoreFileSizeSignal();

}  // namespace gvio::cli
