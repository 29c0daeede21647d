// gvio render through the built binary (EGL on llvmpipe in CI): views, sizes and bad input.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "io/loops_csv.hpp"
#include "io/trajectory_io.hpp"
#include "render_map_fixture.hpp"
#include "support/fixtures.hpp"

namespace gvio::test {
namespace {
using testing::HasSubstr;
namespace fs = std::filesystem;

Trajectory loop(double offset_m) {
  Trajectory t;
  for (int i = 0; i < 100; ++i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    const double a = 0.0628 * i;
    T.translation() =
        Eigen::Vector3d(50 * std::cos(a) + offset_m * i / 100.0, 30 * std::sin(a), 0.0);
    t.poses.push_back(T);
    t.t_ns.push_back(1'000'000'000LL + i * 100'000'000LL);
  }
  return t;
}

class CliRender : public ::testing::Test {
 protected:
  void SetUp() override {
    fs::create_directories(run_);
    io::writeTum(run_ / "trajectory.tum", loop(3.0));
    io::writeTum(run_ / "groundtruth.tum", loop(0.0));
  }
  std::string out(const std::string& name) const { return (dir_.path() / name).string(); }
  TempDir dir_{"clirender"};
  fs::path run_ = dir_.path() / "run";
};

TEST_F(CliRender, EveryViewWritesAnImageOfTheAskedSize) {
  for (const char* view : {"topdown", "perspective", "error"}) {
    const auto r = runGvio("render --run " + run_.string() + " --view " + view +
                           " --size 320x200 --out " + out(std::string(view) + ".png"));
    ASSERT_EQ(r.exit_code, 0) << view << ": " << r.err;
    const cv::Mat img = cv::imread(out(std::string(view) + ".png"));
    ASSERT_FALSE(img.empty()) << view;
    EXPECT_EQ(img.cols, 320);
    EXPECT_EQ(img.rows, 200);
    cv::Scalar mean, stddev;
    cv::meanStdDev(img, mean, stddev);
    EXPECT_GT(stddev[0], 5.0) << view << " looks blank";
  }
}

TEST_F(CliRender, BadInputIsOneLineExit2) {
  fs::create_directories(dir_.path() / "empty_run");
  const std::string base = "render --run " + run_.string() + " --out " + out("x.png");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"render --run " + (dir_.path() / "missing").string() + " --out " + out("x.png"),
       "run folder not found"},
      {"render --run " + (dir_.path() / "empty_run").string() + " --out " + out("x.png"),
       "no trajectory.tum"},
      {base + " --size 0x100", "1..16384"},
      {base + " --size 16385x100", "1..16384"},
      {base + " --size big", "expected WxH"},
      {base + " --view sideways", "topdown, perspective, octomap or error"},
      {"render --run " + run_.string() + " --out /nonexistent/dir/x.png", "/nonexistent/dir/x.png"},
  };
  for (const auto& [args, needle] : cases) {
    const auto r = runGvio(args);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << "\n" << r.err;
    EXPECT_THAT(r.err, HasSubstr(needle)) << args;
  }
}

TEST_F(CliRender, ErrorViewNeedsTruthAndEmptyTrajectoryIsRejected) {
  fs::remove(run_ / "groundtruth.tum");
  auto r = runGvio("render --run " + run_.string() + " --view error --out " + out("e.png"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("needs ground truth"));
  writeText(run_ / "trajectory.tum", "# no poses\n");
  r = runGvio("render --run " + run_.string() + " --out " + out("e.png"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("no poses"));
}

// The map views on a run folder with map.pcd, map.ot, gnss_fixes.csv and report.json.
TEST_F(CliRender, MapViewsWriteImages) {
  const fs::path map_run = dir_.path() / "map_run";
  writeSyntheticMapRun(map_run);
  for (const char* view : {"topdown", "perspective", "octomap"}) {
    const std::string png = out(std::string("map_") + view + ".png");
    const auto r = runGvio("render --run " + map_run.string() + " --view " + view +
                           " --size 320x240 --out " + png);
    ASSERT_EQ(r.exit_code, 0) << view << ": " << r.err;
    const cv::Mat img = cv::imread(png);
    ASSERT_FALSE(img.empty()) << view;
    EXPECT_EQ(img.cols, 320);
    EXPECT_EQ(img.rows, 240);
    cv::Scalar mean, stddev;
    cv::meanStdDev(img, mean, stddev);
    EXPECT_GT(stddev[0], 5.0) << view << " looks blank";
  }
}

TEST_F(CliRender, BadMapFilesAreOneLineExit2) {
  const fs::path map_run = dir_.path() / "map_run";
  writeSyntheticMapRun(map_run);
  const std::string args = "render --run " + map_run.string() + " --out " + out("m.png");
  auto expectOneLine = [&](const std::string& view, const std::string& needle) {
    const auto r = runGvio(args + " --view " + view);
    EXPECT_EQ(r.exit_code, 2) << view << "\n" << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_THAT(r.err, HasSubstr(needle)) << view;
  };
  writeText(map_run / "gnss_fixes.csv", "t_s,e_m,n_m,u_m,status\n1,2,3,4,used\n1,2,x,4,used\n");
  expectOneLine("topdown", "gnss_fixes.csv:3:");
  fs::remove(map_run / "gnss_fixes.csv");
  writeText(map_run / "map.pcd", "VERSION .7\nFIELDS x y z\n");
  expectOneLine("perspective", "map.pcd: not a PCD file");
  const std::string ot = readText(map_run / "map.ot");
  writeText(map_run / "map.ot", ot.substr(0, ot.size() / 2));
  expectOneLine("octomap", "map.ot: OctoMap data is truncated");
  fs::remove(map_run / "map.ot");
  expectOneLine("octomap", "the octomap view needs map.ot or map.bt");
  // The error view reads none of these: it still works with them broken or missing.
  writeText(map_run / "gnss_fixes.csv", "t_s,e_m,n_m,u_m,status\n1,2,x,4,used\n");
  writeText(map_run / "report.json", "{");
  io::writeTum(map_run / "groundtruth.tum", syntheticDrive());
  EXPECT_EQ(runGvio(args + " --view error").exit_code, 0);
}

// loops.csv is read for the topdown view only: malformed, it fails that view in one line naming
// the file and line, and leaves the other views alone.
TEST_F(CliRender, LoopsCsvIsDrawnAndWhenMalformedOneLineExit2) {
  io::LoopCsvRow closure;  // the end of the loop drive, back near its start
  closure.query_t_ns = 10'800'000'000LL;
  closure.candidate_t_ns = 1'000'000'000LL;
  closure.accepted = true;
  closure.reason = "ok";
  io::writeLoopsCsv(run_ / "loops.csv", {closure});
  const std::string args =
      "render --run " + run_.string() + " --size 320x200 --out " + out("l.png");
  auto r = runGvio(args + " --view topdown");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_FALSE(cv::imread(out("l.png")).empty());
  writeText(run_ / "loops.csv", std::string(io::kLoopsCsvHeader) +
                                    "\n10.8,1.0,3.0,15.0,10,5,0.5,0.1,0.2,accepted,ok\n"
                                    "10.9,1.0,3.0,15.0,-10,0,nan,nan,nan,rejected,few_matches\n");
  r = runGvio(args + " --view topdown");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_THAT(r.err, HasSubstr("loops.csv:3: negative matches '-10'"));
  EXPECT_EQ(runGvio(args + " --view perspective").exit_code, 0);
}

// With no EGL vendor library (glvnd finds none), every path fails and the CLI says so in one line.
TEST_F(CliRender, NoEglIsAClearError) {
  const auto r = runGvio("render --run " + run_.string() + " --out " + out("n.png"));
  ASSERT_EQ(r.exit_code, 0) << r.err;  // sanity: it works with the system's EGL
  const auto none = runGvioWithEnv("__EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent.json",
                                   "render --run " + run_.string() + " --out " + out("n.png"));
  EXPECT_EQ(none.exit_code, 2);
  EXPECT_EQ(std::count(none.err.begin(), none.err.end(), '\n'), 1) << none.err;
  EXPECT_THAT(none.err, HasSubstr("no headless OpenGL 3.3 context through EGL"));
}

}  // namespace
}  // namespace gvio::test
