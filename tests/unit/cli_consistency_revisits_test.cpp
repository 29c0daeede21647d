// gvio consistency --images at revisits (issue 59): where the drive comes back, each keyframe is
// also checked against the map of the other pass alone. On the simulated city block driven 1.3
// times (tests/support/block_drive.hpp): with the true poses the two passes agree with each other
// as well as each agrees with itself; with the second pass moved 0.5 m sideways the other pass's
// map no longer matches the images there.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <iostream>

#include <nlohmann/json.hpp>

#include "support/block_drive.hpp"
#include "support/fixtures.hpp"
#include "support/image_check_runs.hpp"

namespace gvio::test {
namespace {
namespace fs = std::filesystem;

// The block's second pass starts after one perimeter (335 m at 8 m/s: 41.9 s).
constexpr double kSecondPassS = 42.0;

nlohmann::json checkRevisits(const fs::path& run) {
  const CommandResult c =
      runGvio(fmt::format("consistency --run {} --images --every 2 --no-progress", quoted(run)));
  EXPECT_EQ(c.exit_code, 0) << c.err;
  return nlohmann::json::parse(readText(run / "consistency_images" / "summary.json"));
}

TEST(CliConsistencyImagesRevisits, TheOtherPassAgreesWithTheTruthAndNotWithAMovedPass) {
  const fs::path dataset = simulatedBlockDrive("block_drive.tum");
  TempDir tmp("cli_consistency_revisits");
  writeTrajectoryRun(tmp.path() / "truth", dataset, readText(dataset / "groundtruth.tum"));
  writeTrajectoryRun(tmp.path() / "moved", dataset,
                     displacedTum(dataset / "groundtruth.tum", kSecondPassS, 100.0,
                                  Eigen::Vector3d(0.0, 0.5, 0.0)));
  const nlohmann::json truth = checkRevisits(tmp.path() / "truth");
  const nlohmann::json moved = checkRevisits(tmp.path() / "moved");
  const nlohmann::json& again = truth["revisits"];
  // Both ends of the drive: its first ~13 s and its last ~13 s (every second keyframe).
  EXPECT_GT(again["keyframes"].get<int>(), 20) << again.dump(2);
  const double own = truth["ncc"]["median"].get<double>();
  const double other = again["ncc"]["median"].get<double>();
  EXPECT_GT(other, own - 0.1) << "the true passes disagree";
  // At 4 sigmas a marginal flag among 75 keyframes can happen (0 measured).
  EXPECT_LE(again["flagged"].get<int>(), 2) << again["flags"].dump(2);
  // The moved pass: the other pass's map is drawn 0.5 m off in both passes' images.
  const double moved_other = moved["revisits"]["ncc"]["median"].get<double>();
  EXPECT_LT(moved_other, other - 0.1) << moved["revisits"].dump(2);
  std::cout << fmt::format(
      "revisits: {} keyframes; other pass ZNCC median {:.3f} (true poses), {:.3f} (second pass "
      "moved 0.5 m); all sources {:.3f} / {:.3f}; revisit flags {} / {}; all-source flags {} / "
      "{}\n",
      again["keyframes"].get<int>(), other, moved_other, own, moved["ncc"]["median"].get<double>(),
      again["flagged"].get<int>(), moved["revisits"]["flagged"].get<int>(),
      truth["keyframes"]["flagged"].get<int>(), moved["keyframes"]["flagged"].get<int>());
  // Measured: 22 of 75 revisit keyframes flagged.
  EXPECT_GE(moved["revisits"]["flagged"].get<int>(), 10) << moved["revisits"].dump(2);
  // The check with every source sees it too: half the drive's keyframes are at the revisit.
  EXPECT_LT(moved["ncc"]["median"].get<double>(), own);
  const auto lines = readText(tmp.path() / "truth" / "consistency_images" / "keyframes.csv");
  EXPECT_NE(lines.find("revisit_sources,revisit_ncc,revisit_depth_agreement"), std::string::npos);
}

}  // namespace
}  // namespace gvio::test
