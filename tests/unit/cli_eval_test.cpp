// gvio eval through the built binary: outputs, exit codes and one-line errors.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "io/trajectory_io.hpp"
#include "support/fixtures.hpp"

namespace gvio::test {
namespace {
using testing::HasSubstr;
namespace fs = std::filesystem;

class CliEval : public ::testing::Test {
 protected:
  void SetUp() override {
    for (int i = 0; i < 50; ++i) {
      Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
      T.translation() = Eigen::Vector3d(i, std::sin(0.2 * i) * 5, 0.1 * i);
      ref_.poses.push_back(T);
      ref_.t_ns.push_back(1'000'000'000LL + i * 100'000'000LL);
      T.translation() += Eigen::Vector3d(0.1, 0.0, 0.0);
      est_.poses.push_back(T);
      est_.t_ns.push_back(ref_.t_ns.back() + 2'000'000);  // 2 ms later
    }
    io::writeTum(dir_.path() / "ref.tum", ref_);
    io::writeTum(dir_.path() / "est.tum", est_);
  }
  std::string p(const std::string& name) const { return (dir_.path() / name).string(); }
  static int lines(const std::string& s) {
    return static_cast<int>(std::count(s.begin(), s.end(), '\n'));
  }

  TempDir dir_{"clieval"};
  Trajectory ref_, est_;
};

TEST_F(CliEval, TableJsonAlignedAndPlots) {
  const auto r =
      runGvio("eval --ref " + p("ref.tum") + " --est " + p("est.tum") + " --rpe-delta 5 --json " +
              p("r.json") + " --est-aligned " + p("al.tum") + " --plot " + p("plot"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("APE w.r.t. translation part (m)"));
  EXPECT_THAT(r.out, HasSubstr("rmse  0.100000"));
  const auto j = nlohmann::json::parse(readText(p("r.json")));
  for (const char* key : {"rmse", "mean", "median", "std", "min", "max", "sse", "n"}) {
    EXPECT_TRUE(j["ape"].contains(key)) << key;
    EXPECT_TRUE(j["rpe"].contains(key)) << key;
  }
  EXPECT_NEAR(j["ape"]["rmse"].get<double>(), 0.1, 1e-9);
  EXPECT_EQ(j["ape"]["n"].get<int>(), 50);
  EXPECT_EQ(io::readTum(p("al.tum")).size(), 50u);
  for (const char* f : {"plot_trajectory.png", "plot_error.svg", "plot_axes.png"}) {
    EXPECT_TRUE(fs::exists(p(f))) << f;
  }
}

TEST_F(CliEval, Se3RemovesConstantOffset) {
  const auto r = runGvio("eval --ref " + p("ref.tum") + " --est " + p("est.tum") +
                         " --align se3 --json " + p("r.json"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_LT(nlohmann::json::parse(readText(p("r.json")))["ape"]["rmse"].get<double>(), 1e-6);
}

TEST_F(CliEval, BadInputIsOneLineExit2) {
  Trajectory short_ref = ref_;
  short_ref.poses.resize(40);
  short_ref.t_ns.clear();
  io::writeKitti(p("ref.kitti"), short_ref);
  Trajectory est_kitti = est_;
  est_kitti.t_ns.clear();
  io::writeKitti(p("est.kitti"), est_kitti);
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"eval --ref " + p("ref.kitti") + " --est " + p("est.kitti"), "40 poses and estimate 50"},
      {"eval --ref " + p("ref.tum") + " --est " + p("est.tum") + " --t-offset 100",
       "associated poses"},
      {"eval --ref " + p("missing.tum") + " --est " + p("est.tum"), "missing.tum"},
      {"eval --ref " + p("ref.tum") + " --est " + p("est.tum") + " --plot /nonexistent/dir/x",
       "/nonexistent/dir/x"},
      {"eval --ref " + p("ref.tum") + " --est " + p("est.tum") + " --outages " + p("missing.txt") +
           " --plot " + p("o"),
       "missing.txt"},
  };
  for (const auto& [args, needle] : cases) {
    const auto r = runGvio(args);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
    EXPECT_EQ(lines(r.err), 1) << args << "\n" << r.err;
    EXPECT_THAT(r.err, HasSubstr(needle)) << args;
  }
  EXPECT_EQ(
      runGvio("eval --ref " + p("ref.tum") + " --est " + p("est.tum") + " --align se2").exit_code,
      2);
}

TEST_F(CliEval, CollinearAlignmentIsRejected) {
  Trajectory line = ref_;
  for (std::size_t i = 0; i < line.size(); ++i)
    line.poses[i].translation() = Eigen::Vector3d(i, 0, 0);
  io::writeTum(p("line.tum"), line);
  const auto r =
      runGvio("eval --ref " + p("line.tum") + " --est " + p("line.tum") + " --align sim3");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("collinear"));
}

}  // namespace
}  // namespace gvio::test
