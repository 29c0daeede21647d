// The committed demo drive (assets/demo) must be exactly what the fixture generator writes, so the
// README's first command never runs on stale data.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <set>

#include "io/trajectory_io.hpp"
#include "support/fixtures.hpp"

namespace gvio::test {
namespace {
namespace fs = std::filesystem;

std::set<std::string> relativeFiles(const fs::path& root) {
  std::set<std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(root)) {
    if (e.is_regular_file()) files.insert(fs::relative(e.path(), root).string());
  }
  return files;
}

TEST(DemoAssets, MatchGenerator) {
  const fs::path committed = fs::path(GVIO_SOURCE_DIR) / "assets" / "demo";
  TempDir tmp("demo");
  writeKittiFixture(tmp.path(), demoFixture());
  io::writeTum(tmp.path() / "drive.tum", demoDrive());
  const auto expected = relativeFiles(tmp.path());
  ASSERT_EQ(relativeFiles(committed), expected)
      << "regenerate with build/tests/gvio_make_fixture assets/demo";
  for (const auto& rel : expected) {
    if (fs::path(rel).extension() == ".png") {
      const cv::Mat a = cv::imread((committed / rel).string(), cv::IMREAD_UNCHANGED);
      const cv::Mat b = cv::imread((tmp.path() / rel).string(), cv::IMREAD_UNCHANGED);
      ASSERT_FALSE(a.empty()) << rel;
      EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0) << rel;
    } else {
      EXPECT_EQ(readText(committed / rel), readText(tmp.path() / rel)) << rel;
    }
  }
}

}  // namespace
}  // namespace gvio::test
