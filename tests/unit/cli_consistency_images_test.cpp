// gvio consistency --images (issue 19): the map checked against the recorded images without ground
// truth. On a simulated 20 s drive: the map from the true poses is flagged nowhere; the same map
// with 10 s of its poses moved 0.5 m north (trajectory.tum edited; the check rebuilds the map
// from it) is flagged around that stretch only; the VIO's own poses score below the truth's.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>

#include <Eigen/Core>
#include <cmath>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include <nlohmann/json.hpp>

#include "support/fixtures.hpp"
#include "support/image_check_runs.hpp"

namespace gvio::test {
namespace {
using testing::HasSubstr;
namespace fs = std::filesystem;

struct CsvRow {
  double t_s = 0.0, ncc = 0.0, depth = 0.0, drawn_depth_m = 0.0;
  bool flagged = false;
  std::string status, reason;
};

std::vector<CsvRow> readRows(const fs::path& csv) {
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line.rfind("t_s,t_from_start_s,x_m,y_m,z_m,ncc,ncc_flag_below,", 0), 0U) << line;
  std::vector<CsvRow> rows;
  while (std::getline(in, line)) {
    std::vector<std::string> f(1);  // a trailing empty field counts too
    for (const char ch : line) {
      if (ch == ',') {
        f.emplace_back();
      } else {
        f.back() += ch;
      }
    }
    EXPECT_EQ(f.size(), 29U) << line;
    if (f.size() != 29U) continue;
    rows.push_back({std::stod(f[1]), std::stod(f[5]), std::stod(f[9]), std::stod(f[28]),
                    f[14] == "1", f[21], f[22]});
  }
  return rows;
}

// Each test runs in a process of its own (ctest), so each does only what it needs, once: the
// truth and the moved poses need no gvio run (a run folder is its report.json's sources and a
// trajectory: the check rebuilds the map from them); the VIO's poses need one.
class CliConsistencyImages : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir("cli_consistency_images");
    dataset_ = cachedSimulation(fmt::format(
        "--trajectory {}/assets/demo/drive.tum --seconds 20 --seed 9", GVIO_SOURCE_DIR));
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  static fs::path run(const std::string& name) { return dir_->path() / name; }
  static fs::path report(const std::string& name) { return run(name) / "consistency_images"; }
  static nlohmann::json summary(const std::string& name) {
    return nlohmann::json::parse(readText(report(name) / "summary.json"));
  }
  // A run folder of `trajectory_tum` (the text of a TUM file) over the simulated drive.
  static void makeRun(const std::string& name, const std::string& trajectory_tum) {
    writeTrajectoryRun(run(name), dataset_, trajectory_tum);
  }
  static void check(const std::string& name) {
    if (fs::exists(report(name) / "summary.json")) return;
    const CommandResult c =
        runGvio(fmt::format("consistency --run {} --images --no-progress", quoted(run(name))));
    ASSERT_EQ(c.exit_code, 0) << name << ": " << c.err;
  }
  static void checkTruth() {
    if (!fs::exists(run("truth"))) makeRun("truth", readText(dataset_ / "groundtruth.tum"));
    check("truth");
  }
  static void checkFault() {
    if (!fs::exists(run("fault"))) {
      makeRun("fault",
              displacedTum(dataset_ / "groundtruth.tum", kFaultFrom, kFaultTo, {0.0, 0.5, 0.0}));
    }
    check("fault");
  }
  static void checkVio() {
    if (!fs::exists(run("vio"))) {
      const CommandResult r = runGvio(fmt::format(
          "run --dataset {} --out {} --no-progress --gnss off --set loops.enabled=false",
          quoted(dataset_), quoted(run("vio"))));
      ASSERT_EQ(r.exit_code, 0) << r.err;
    }
    check("vio");
  }

  static constexpr double kFaultFrom = 6.0, kFaultTo = 16.0;
  static TempDir* dir_;
  static fs::path dataset_;
};
TempDir* CliConsistencyImages::dir_ = nullptr;
fs::path CliConsistencyImages::dataset_;

// The truth is flagged nowhere (and every report file is there).
// One line of a check's summary: the figures docs/cli/consistency.md's table gives.
void printSummary(const char* what, const nlohmann::json& s) {
  std::string stretches;
  for (const auto& st : s["flagged_stretches"]) {
    stretches +=
        fmt::format(" {:.1f}-{:.1f} s", st["from_s"].get<double>(), st["to_s"].get<double>());
  }
  std::printf(
      "%s: ZNCC mean %.3f, depth agreement mean %.3f, %d of %d flagged (%zu stretches:%s), %d not "
      "enough evidence, %.0f ms per keyframe (median %.0f)\n",
      what, s["ncc"]["mean"].get<double>(), s["depth_agreement"]["mean"].get<double>(),
      s["keyframes"]["flagged"].get<int>(), s["keyframes"]["checked"].get<int>(),
      s["flagged_stretches"].size(), stretches.c_str(),
      s["keyframes"]["not_enough_evidence"].get<int>(), s["ms_per_keyframe"]["mean"].get<double>(),
      s["ms_per_keyframe"]["median"].get<double>());
}

TEST_F(CliConsistencyImages, TheTruePosesAreFlaggedNowhere) {
  ASSERT_NO_FATAL_FAILURE(checkTruth());
  const nlohmann::json s = summary("truth");
  printSummary("true poses", s);
  const std::size_t checked = s["keyframes"]["checked"].get<std::size_t>();
  EXPECT_GT(checked, 60U);  // 20 s at ~8 m/s, one map keyframe per 1.5 m
  const std::vector<CsvRow> rows = readRows(report("truth") / "keyframes.csv");
  EXPECT_EQ(rows.size(), checked);
  for (const CsvRow& r : rows) {  // the map drawn in view: the demo's road and houses, 2-60 m
    EXPECT_GT(r.drawn_depth_m, 2.0) << r.t_s;
    EXPECT_LT(r.drawn_depth_m, 60.0) << r.t_s;
  }
  for (const char* file : {"scores.png", "scores.svg"}) {
    EXPECT_TRUE(fs::exists(report("truth") / file)) << file;
  }
  ASSERT_EQ(s["worst"].size(), 3U);
  const cv::Mat side =
      cv::imread((report("truth") / s["worst"][0]["image"].get<std::string>()).string());
  ASSERT_FALSE(side.empty());
  EXPECT_EQ(side.cols, 3 * 1241);  // recorded | rendered | difference
  EXPECT_EQ(side.rows, 376);
  EXPECT_GT(s["ms_per_keyframe"]["mean"].get<double>(), 0.0);
  EXPECT_EQ(s["keyframes"]["flagged"].get<int>(), 0);
  EXPECT_TRUE(s["flagged_stretches"].empty());
  EXPECT_TRUE(s["flags"].empty());
  EXPECT_EQ(s["revisits"]["keyframes"].get<int>(), 0);  // a drive that never comes back
  EXPECT_GT(s["flag_rule"]["ncc_normal_false_alarm_rate"].get<double>(), 0.0);
  EXPECT_GT(s["ncc"]["mean"].get<double>(), 0.5);
  EXPECT_GT(s["depth_agreement"]["mean"].get<double>(), 0.8);
}

// A stretch moved as a whole agrees with itself: what disagrees is where its map meets the
// unmoved one, seen by the keyframes whose view reaches across the stretch's ends (the camera
// looks ahead up to 40 m, ~5 s at this speed). Keyframes elsewhere must not be flagged.
TEST_F(CliConsistencyImages, PosesMovedHalfAMetreAreFlaggedAtThatStretchOnly) {
  ASSERT_NO_FATAL_FAILURE(checkTruth());
  ASSERT_NO_FATAL_FAILURE(checkFault());
  const auto rows = readRows(report("fault") / "keyframes.csv");
  std::size_t flagged = 0;
  for (const CsvRow& r : rows) {
    if (!r.flagged) {
      EXPECT_NE(r.status, "flagged");
      continue;
    }
    ++flagged;
    EXPECT_EQ(r.status, "flagged");
    EXPECT_THAT(r.reason, HasSubstr(" over "));  // the score, its threshold and its support
    EXPECT_GE(r.t_s, kFaultFrom - 5.0) << "flagged before the stretch could be seen";
    EXPECT_LE(r.t_s, kFaultTo + 1.0) << "flagged after the stretch";
  }
  EXPECT_GE(flagged, 2U);
  // Keyframes out of sight of the stretch score as with the true poses (but for a few far points
  // of the stretch within 40 m; the keyframes chosen along the moved stretch differ: the spacing
  // rule sees the jump).
  const auto truth = readRows(report("truth") / "keyframes.csv");
  std::size_t compared = 0;
  for (std::size_t i = 0; i < rows.size() && i < truth.size(); ++i) {
    if (rows[i].t_s >= kFaultFrom - 5.5) break;
    ASSERT_DOUBLE_EQ(rows[i].t_s, truth[i].t_s);
    EXPECT_NEAR(rows[i].ncc, truth[i].ncc, 0.01) << rows[i].t_s;
    ++compared;
  }
  EXPECT_GT(compared, 0U);
  EXPECT_LT(summary("fault")["ncc"]["mean"].get<double>(),
            summary("truth")["ncc"]["mean"].get<double>());
  printSummary("poses moved 0.5 m", summary("fault"));
}

TEST_F(CliConsistencyImages, TheVioPosesScoreBelowTheTruePoses) {
  ASSERT_NO_FATAL_FAILURE(checkTruth());
  ASSERT_NO_FATAL_FAILURE(checkVio());
  const nlohmann::json vio = summary("vio"), truth = summary("truth");
  EXPECT_LT(vio["ncc"]["mean"].get<double>(), truth["ncc"]["mean"].get<double>());
  EXPECT_LT(vio["depth_agreement"]["mean"].get<double>(),
            truth["depth_agreement"]["mean"].get<double>());
}

TEST_F(CliConsistencyImages, OneKeyframeAtATimeAndBadRequests) {
  if (!fs::exists(run("truth"))) makeRun("truth", readText(dataset_ / "groundtruth.tum"));
  const fs::path out = dir_->path() / "at";
  CommandResult r = runGvio(fmt::format("consistency --run {} --images --at 5 --worst 1 --out {}",
                                        quoted(run("truth")), quoted(out)));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto rows = readRows(out / "keyframes.csv");
  ASSERT_EQ(rows.size(), 1U);
  EXPECT_NEAR(rows[0].t_s, 5.0, 0.2);
  r = runGvio(fmt::format("consistency --run {} --images --reference x.ply", quoted(run("truth"))));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("either --reference"));
  r = runGvio(fmt::format("consistency --run {}", quoted(run("truth"))));
  EXPECT_EQ(r.exit_code, 2);
  r = runGvio(fmt::format("consistency --run {} --images --every 0", quoted(run("truth"))));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("--every"));
  r = runGvio(fmt::format("consistency --run {} --images --exclude -1", quoted(run("truth"))));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("--exclude"));
  // Counts are unsigned: -1 is refused, not wrapped into a huge count.
  for (const char* count : {"--every", "--worst", "--similar-views"}) {
    r = runGvio(fmt::format("consistency --run {} --images {} -1", quoted(run("truth")), count));
    EXPECT_EQ(r.exit_code, 2) << count;
    EXPECT_THAT(r.err, HasSubstr(count));
  }
  r = runGvio(fmt::format("consistency --run {} --images --similar-views 3", quoted(run("truth"))));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("similar_views must be 0 (off) or >= min_views_to_flag"));
  r = runGvio(fmt::format("consistency --run {} --images --flag-sigmas 0", quoted(run("truth"))));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("flag_sigmas must be > 0"));
  r = runGvio(
      fmt::format("consistency --run {} --images --depth-flag-sigmas nan", quoted(run("truth"))));
  EXPECT_EQ(r.exit_code, 2);
  r = runGvio(fmt::format("consistency --run {} --images --dataset {}", quoted(run("truth")),
                          quoted(dir_->path() / "missing")));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("missing"));
}

}  // namespace
}  // namespace gvio::test
