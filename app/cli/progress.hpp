#pragma once
// Progress of long loops on stderr: a redrawn bar (rate, ETA) when stderr is a terminal, plain
// periodic lines when it is a log file or pipe, nothing with --no-progress or -q.
#include <chrono>
#include <cstddef>
#include <cstdio>
#include <string>

namespace gvio::cli {

enum class ProgressStyle { kOff, kBar, kLines };

// kBar when `enabled` and `stream` is a terminal, kLines when enabled otherwise, kOff when not.
ProgressStyle chooseProgressStyle(bool enabled, std::FILE* stream);

// "12/340 frames (3.5%), 8.1 frames/s, ETA 0:40" (the words of both styles).
std::string progressText(std::size_t done, std::size_t total, const std::string& unit,
                         double elapsed_s);

class Progress {
 public:
  Progress(std::string label, std::size_t total, std::string unit, ProgressStyle style,
           std::FILE* stream = stderr, double line_interval_s = 5.0);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  void update(std::size_t done);                      // cheap; draws at most every 0.1 s (bar)
  void updateAt(std::size_t done, double elapsed_s);  // explicit clock, for tests
  void finish();                                      // final line; idempotent

 private:
  void draw(std::size_t done, double elapsed_s);

  std::string label_, unit_;
  std::size_t total_;
  ProgressStyle style_;
  std::FILE* stream_;
  double line_interval_s_;
  double last_draw_s_ = -1e9;
  std::size_t done_ = 0;
  bool finished_ = false;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace gvio::cli
