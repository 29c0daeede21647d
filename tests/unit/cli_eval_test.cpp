// gvio eval through the built binary: outputs, exit codes and one-line errors.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <numbers>

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

// A repeated stamp (TUM RGB-D fr2/desk's ground truth has them) is associated as evo does: the
// first pose with that stamp, with a warning; the strict readers elsewhere still refuse it.
TEST_F(CliEval, RepeatedStampsAreAssociatedAsEvoDoes) {
  const auto withRepeat = [&](bool perturbed_first) {
    Trajectory t = ref_;
    Eigen::Isometry3d moved = t.poses[20];
    moved.translation().x() += 3.0;
    const auto at = t.poses.begin() + (perturbed_first ? 20 : 21);
    t.poses.insert(at, moved);
    t.t_ns.insert(t.t_ns.begin() + 20, t.t_ns[20]);
    return t;
  };
  io::writeTum(dir_.path() / "repeat_after.tum", withRepeat(false));
  io::writeTum(dir_.path() / "repeat_first.tum", withRepeat(true));
  const auto apeMax = [&](const std::string& est, const std::string& json) {
    const auto r =
        runGvio("eval --ref " + p("ref.tum") + " --est " + p(est) + " --json " + p(json));
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_THAT(r.err, HasSubstr("1 repeated timestamps and 0 steps back (the first at pose 22"));
    return nlohmann::json::parse(readText(p(json)))["ape"]["max"].get<double>();
  };
  // The longer estimate is matched from the reference's stamps: the first of the two poses.
  EXPECT_NEAR(apeMax("repeat_after.tum", "a.json"), 0.0, 1e-9);
  EXPECT_NEAR(apeMax("repeat_first.tum", "b.json"), 3.0, 1e-9);
}

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

// Pass 1 along y = 0 from x = 0 to 100 m at 10 m/s (10 Hz), round a 100 m square, pass 2 along
// y = 0 from x = 0 to 60 m, 40 s after pass 1. In the estimate, everything after pass 1 is off by
// `offset`, so every revisit pair (pass 1 against the later drive) is off by |offset|.
void writeTwoPasses(const fs::path& ref_file, const fs::path& est_file,
                    const Eigen::Vector3d& offset) {
  Trajectory ref;
  const std::vector<Eigen::Vector2d> corners = {{0, 0},   {100, 0}, {100, 100},
                                                {0, 100}, {0, 0},   {60, 0}};
  for (std::size_t c = 1; c < corners.size(); ++c) {
    const auto steps = static_cast<int>(std::lround((corners[c] - corners[c - 1]).norm()));
    for (int k = c == 1 ? 0 : 1; k <= steps; ++k) {
      const Eigen::Vector2d xy = corners[c - 1] + (corners[c] - corners[c - 1]) * k / steps;
      Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
      T.translation() = Eigen::Vector3d(xy.x(), xy.y(), 0.0);
      ref.poses.push_back(T);
      ref.t_ns.push_back(static_cast<std::int64_t>(ref.t_ns.size()) * 100'000'000LL);
    }
  }
  Trajectory est = ref;
  for (std::size_t i = 101; i < est.size(); ++i) est.poses[i].translation() += offset;
  io::writeTum(ref_file, ref);
  io::writeTum(est_file, est);
}

TEST_F(CliEval, RevisitsTableJsonAndPlot) {
  writeTwoPasses(p("two_ref.tum"), p("two_est.tum"), Eigen::Vector3d(0.3, -0.4, 0.0));
  const auto r = runGvio("eval --ref " + p("two_ref.tum") + " --est " + p("two_est.tum") +
                         " --revisits 2 --json " + p("r.json") + " --plot " + p("plot"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("revisit consistency"));
  EXPECT_THAT(r.out, HasSubstr("within 2 m and at least 30 s apart"));
  EXPECT_THAT(r.out, HasSubstr("       p95  0.500000"));
  EXPECT_THAT(r.out, HasSubstr("     pairs  "));
  const auto j = nlohmann::json::parse(readText(p("r.json")));
  ASSERT_TRUE(j.contains("revisits"));
  const auto& v = j["revisits"];
  for (const char* key : {"radius_m", "min_separation_s", "pairs", "rmse", "mean", "median", "std",
                          "min", "max", "sse", "n", "p95"}) {
    EXPECT_TRUE(v.contains(key)) << key;
  }
  EXPECT_EQ(v["radius_m"].get<double>(), 2.0);
  EXPECT_EQ(v["min_separation_s"].get<double>(), 30.0);
  EXPECT_GT(v["pairs"].get<int>(), 200);
  EXPECT_EQ(v["n"].get<int>(), v["pairs"].get<int>());
  EXPECT_NEAR(v["rmse"].get<double>(), 0.5, 1e-6);
  EXPECT_NEAR(v["max"].get<double>(), 0.5, 1e-6);
  EXPECT_NEAR(v["p95"].get<double>(), 0.5, 1e-6);
  for (const char* f : {"plot_revisits.png", "plot_revisits.svg", "plot_trajectory.png"}) {
    ASSERT_TRUE(fs::exists(p(f))) << f;
    EXPECT_GT(fs::file_size(p(f)), 1000U) << f;
  }
  // Without --revisits there is no revisits key.
  ASSERT_EQ(runGvio("eval --ref " + p("two_ref.tum") + " --est " + p("two_est.tum") + " --json " +
                    p("plain.json"))
                .exit_code,
            0);
  EXPECT_FALSE(nlohmann::json::parse(readText(p("plain.json"))).contains("revisits"));
}

TEST_F(CliEval, RevisitsUseTheAlignedEstimate) {
  // The estimate is the reference turned by 90 degrees about z: every relative position turns
  // with it (errors up to sqrt(2) x 2 m) unless --align se3 undoes the turn.
  writeTwoPasses(p("two_ref.tum"), p("two_est.tum"), Eigen::Vector3d::Zero());
  Trajectory turned = io::readTum(p("two_est.tum"));
  for (auto& T : turned.poses)
    T = Eigen::AngleAxisd(std::numbers::pi / 2.0, Eigen::Vector3d::UnitZ()) * T;
  io::writeTum(p("turned.tum"), turned);
  const std::string args = "eval --ref " + p("two_ref.tum") + " --est " + p("turned.tum") +
                           " --revisits 2 --json " + p("r.json");
  ASSERT_EQ(runGvio(args).exit_code, 0);
  EXPECT_GT(nlohmann::json::parse(readText(p("r.json")))["revisits"]["max"].get<double>(), 1.0);
  ASSERT_EQ(runGvio(args + " --align se3").exit_code, 0);
  EXPECT_LT(nlohmann::json::parse(readText(p("r.json")))["revisits"]["max"].get<double>(), 1e-6);
}

TEST_F(CliEval, RevisitsMinSeparation) {
  writeTwoPasses(p("two_ref.tum"), p("two_est.tum"), Eigen::Vector3d(0.3, -0.4, 0.0));
  const std::string base = "eval --ref " + p("two_ref.tum") + " --est " + p("two_est.tum") +
                           " --revisits 2 --json " + p("r.json");
  auto pairs = [&](const std::string& extra) {
    const auto r = runGvio(base + extra);
    EXPECT_EQ(r.exit_code, 0) << extra << "\n" << r.err;
    return nlohmann::json::parse(readText(p("r.json")))["revisits"]["pairs"].get<int>();
  };
  const int default_pairs = pairs("");
  EXPECT_GT(default_pairs, 0);
  EXPECT_EQ(pairs(" --revisits-min-separation 39"),
            default_pairs);  // revisits are 39.7-40.2 s apart
  EXPECT_EQ(pairs(" --revisits-min-separation 41"), 0);
  EXPECT_GT(pairs(" --revisits-min-separation 0"), default_pairs);  // + neighbours along the drive
}

TEST_F(CliEval, RevisitsWithoutPairsIsNotAnError) {
  // The fixture's 5 s wiggle never comes back.
  const auto r = runGvio("eval --ref " + p("ref.tum") + " --est " + p("est.tum") +
                         " --revisits 3 --json " + p("r.json") + " --plot " + p("plot"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out,
              HasSubstr("revisits: no pair of reference poses within 3 m and at least 30 s apart"));
  EXPECT_THAT(r.out, HasSubstr("rmse  0.100000"));  // APE as before
  const auto v = nlohmann::json::parse(readText(p("r.json")))["revisits"];
  EXPECT_EQ(v["n"].get<int>(), 0);
  EXPECT_EQ(v["pairs"].get<int>(), 0);
  EXPECT_EQ(v["radius_m"].get<double>(), 3.0);
  EXPECT_EQ(v["min_separation_s"].get<double>(), 30.0);
  EXPECT_TRUE(v["rmse"].is_null());
  EXPECT_TRUE(v["p95"].is_null());
  EXPECT_GT(fs::file_size(p("plot_revisits.png")), 1000U);
}

TEST_F(CliEval, BadRevisitValuesAreOneLineExit2) {
  const std::string base = "eval --ref " + p("ref.tum") + " --est " + p("est.tum");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {" --revisits 0", "--revisits '0'"},
      {" --revisits -1", "--revisits '-1'"},
      {" --revisits nan", "--revisits 'nan'"},
      {" --revisits inf", "--revisits 'inf'"},
      {" --revisits x", "--revisits 'x'"},
      {" --revisits 2m", "--revisits '2m'"},
      {" --revisits 2 --revisits-min-separation -1", "--revisits-min-separation '-1'"},
      {" --revisits 2 --revisits-min-separation nan", "--revisits-min-separation 'nan'"},
      {" --revisits 2 --revisits-min-separation x", "--revisits-min-separation 'x'"},
      {" --revisits-min-separation 10", "--revisits-min-separation"},
  };
  for (const auto& [extra, needle] : cases) {
    const auto r = runGvio(base + extra);
    EXPECT_EQ(r.exit_code, 2) << extra << "\n" << r.err;
    EXPECT_EQ(lines(r.err), 1) << extra << "\n" << r.err;
    EXPECT_THAT(r.err, HasSubstr(needle)) << extra;
  }
}

}  // namespace
}  // namespace gvio::test
