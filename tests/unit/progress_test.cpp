#include "cli/progress.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

namespace gvio::cli {
namespace {
using testing::HasSubstr;

// Captures what a Progress writes, through a memory stream.
class Capture {
 public:
  Capture() : file_(open_memstream(&buf_, &size_)) {}
  ~Capture() {
    std::fclose(file_);
    std::free(buf_);
  }
  std::FILE* file() { return file_; }
  std::string text() {
    std::fflush(file_);
    return std::string(buf_, size_);
  }

 private:
  char* buf_ = nullptr;
  std::size_t size_ = 0;
  std::FILE* file_;
};

TEST(Progress, TextHasCountRateAndEta) {
  EXPECT_EQ(progressText(25, 100, "frames", 5.0), "25/100 frames (25.0%), 5.0 frames/s, ETA 0:15");
  EXPECT_EQ(progressText(0, 100, "frames", 0.0), "0/100 frames (0.0%), 0.0 frames/s, ETA --:--");
  EXPECT_THAT(progressText(1, 100000, "frames", 1.0), HasSubstr("ETA 27:46:39"));
}

TEST(Progress, LinesArePeriodic) {
  Capture cap;
  Progress p("run", 1000, "frames", ProgressStyle::kLines, cap.file(), 5.0);
  for (int i = 1; i <= 1000; ++i) p.updateAt(static_cast<std::size_t>(i), 0.02 * i);  // 20 s
  const std::string text = cap.text();
  // One line at the start, then one every 5 s: t = 0.02, 5.02, 10.02, 15.02 -> 4 lines.
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 4);
  EXPECT_THAT(text, HasSubstr("run: 251/1000 frames"));
  EXPECT_EQ(text.find('\r'), std::string::npos);
}

TEST(Progress, BarRedrawsInPlace) {
  Capture cap;
  Progress p("sim", 10, "frames", ProgressStyle::kBar, cap.file());
  p.updateAt(5, 1.0);
  const std::string text = cap.text();
  EXPECT_THAT(text, HasSubstr("\rsim [############............] 5/10 frames"));
  EXPECT_EQ(text.find('\n'), std::string::npos);
}

TEST(Progress, OffWritesNothing) {
  Capture cap;
  {
    Progress p("run", 10, "frames", ProgressStyle::kOff, cap.file());
    p.updateAt(5, 1.0);
  }
  EXPECT_TRUE(cap.text().empty());
  EXPECT_EQ(chooseProgressStyle(false, stderr), ProgressStyle::kOff);
}

TEST(Progress, FinishPrintsSummaryOnce) {
  Capture cap;
  Progress p("run", 3, "frames", ProgressStyle::kLines, cap.file());
  p.updateAt(3, 0.5);
  p.finish();
  p.finish();
  const std::string text = cap.text();
  EXPECT_THAT(text, HasSubstr("run: 3 frames in"));
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 2);
}

}  // namespace
}  // namespace gvio::cli
