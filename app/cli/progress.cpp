#include "cli/progress.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>

namespace gvio::cli {
namespace {

std::string clockText(double seconds) {
  const auto s = static_cast<long>(std::lround(std::max(0.0, seconds)));
  if (s >= 3600) return fmt::format("{}:{:02d}:{:02d}", s / 3600, (s / 60) % 60, s % 60);
  return fmt::format("{}:{:02d}", s / 60, s % 60);
}

}  // namespace

ProgressStyle chooseProgressStyle(bool enabled, std::FILE* stream) {
  if (!enabled) return ProgressStyle::kOff;
  return ::isatty(::fileno(stream)) ? ProgressStyle::kBar : ProgressStyle::kLines;
}

std::string progressText(std::size_t done, std::size_t total, const std::string& unit,
                         double elapsed_s) {
  const double rate = elapsed_s > 0.0 ? static_cast<double>(done) / elapsed_s : 0.0;
  const double pct =
      total > 0 ? 100.0 * static_cast<double>(done) / static_cast<double>(total) : 100.0;
  std::string eta = "--:--";
  if (rate > 0.0 && total >= done) eta = clockText(static_cast<double>(total - done) / rate);
  return fmt::format("{}/{} {} ({:.1f}%), {:.1f} {}/s, ETA {}", done, total, unit, pct, rate, unit,
                     eta);
}

Progress::Progress(std::string label, std::size_t total, std::string unit, ProgressStyle style,
                   std::FILE* stream, double line_interval_s)
    : label_(std::move(label)),
      unit_(std::move(unit)),
      total_(total),
      style_(style),
      stream_(stream),
      line_interval_s_(line_interval_s) {}

Progress::~Progress() {
  finish();
}

void Progress::update(std::size_t done) {
  if (style_ == ProgressStyle::kOff) return;
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  updateAt(done, elapsed);
}

void Progress::updateAt(std::size_t done, double elapsed_s) {
  done_ = done;
  if (style_ == ProgressStyle::kOff || finished_) return;
  const double interval = style_ == ProgressStyle::kBar ? 0.1 : line_interval_s_;
  if (elapsed_s - last_draw_s_ < interval) return;
  last_draw_s_ = elapsed_s;
  draw(done, elapsed_s);
}

void Progress::draw(std::size_t done, double elapsed_s) {
  const std::string text = progressText(done, total_, unit_, elapsed_s);
  if (style_ == ProgressStyle::kBar) {
    constexpr int kWidth = 24;
    const double frac =
        total_ > 0 ? std::min(1.0, static_cast<double>(done) / static_cast<double>(total_)) : 1.0;
    const int filled = static_cast<int>(frac * kWidth);
    fmt::print(stream_, "\r{} [{}{}] {}\x1b[K", label_,
               std::string(static_cast<std::size_t>(filled), '#'),
               std::string(static_cast<std::size_t>(kWidth - filled), '.'), text);
  } else {
    fmt::print(stream_, "{}: {}\n", label_, text);
  }
  std::fflush(stream_);
}

void Progress::finish() {
  if (finished_ || style_ == ProgressStyle::kOff) {
    finished_ = true;
    return;
  }
  finished_ = true;
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const double rate = elapsed > 0.0 ? static_cast<double>(done_) / elapsed : 0.0;
  fmt::print(stream_, "{}{}: {} {} in {:.1f} s ({:.1f} {}/s)\n",
             style_ == ProgressStyle::kBar ? "\r\x1b[K" : "", label_, done_, unit_, elapsed, rate,
             unit_);
  std::fflush(stream_);
}

}  // namespace gvio::cli
