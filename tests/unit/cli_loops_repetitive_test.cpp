// gvio run's loop closure on the repetitive world: the city block of cli_loops_test (1.3 laps,
// SPP-grade GNSS) simulated with `--world-style repetitive`, where identical buildings, lamps and
// trees repeat every 12 m on both sides, so a place looks like the places a period before and
// after it. Every accepted loop must be a true one: its pair lies within the search distance
// (loops.search_radius_m) in the truth, and the final trajectory puts the pair where the truth
// does (0.2 m). A loop onto a place a period away is a false loop.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>

#include "fusion/vio_enu_alignment.hpp"
#include "io/loops_csv.hpp"
#include "io/trajectory_io.hpp"
#include "sim/world.hpp"
#include "support/block_drive.hpp"
#include "support/fixtures.hpp"

namespace gvio::test {
namespace {
namespace fs = std::filesystem;

constexpr double kSearchRadius_m = 10.0;  // loops.search_radius_m's default
constexpr double kPairTolerance_m = 0.2;

struct LoopAudit {
  int verified = 0, accepted = 0, period_away = 0;  // period_away: verified pairs 10-20 m apart
  std::map<std::string, int> rejected;              // by reason
  std::map<std::string, int> period_verdicts;       // of the pairs a period away, by reason
  std::vector<std::string> false_loops;             // accepted rows that are not true loops
};

class CliLoopsRepetitive : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    tmp_ = std::make_unique<TempDir>("cli_loops_repetitive");
    sim_ = simulatedBlockDrive("block_drive_repetitive.tum", " --world-style repetitive");
  }
  static void TearDownTestSuite() { tmp_.reset(); }

  static nlohmann::json run(const std::string& name, const std::string& options) {
    const CommandResult r =
        runGvio(fmt::format("run --dataset {} --out {} --no-progress --set map.enabled=false {}",
                            quoted(sim_), quoted(tmp_->path() / name), options));
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return nlohmann::json::parse(readText(tmp_->path() / name / "report.json"));
  }

  // Every row of loops.csv against the truth and the run's final trajectory.
  static LoopAudit audit(const std::string& name) {
    const fs::path dir = tmp_->path() / name;
    const Trajectory truth = io::readTum(sim_ / "groundtruth.tum");
    const Trajectory estimate = io::readTum(
        fs::exists(dir / "trajectory.tum") ? dir / "trajectory.tum" : dir / "trajectory_vio.tum");
    LoopAudit a;
    for (const io::LoopCsvRow& row : io::readLoopsCsv(dir / "loops.csv")) {
      ++a.verified;
      const auto ta = fusion::interpolatePose(truth, row.candidate_t_ns);
      const auto tb = fusion::interpolatePose(truth, row.query_t_ns);
      if (!ta || !tb) {
        ADD_FAILURE() << "loop stamps outside the truth: " << row.query_t_ns;
        continue;
      }
      const Eigen::Vector3d true_rel = tb->translation() - ta->translation();
      const double true_distance = true_rel.norm();
      if (true_distance > kSearchRadius_m && true_distance < 2.0 * kSearchRadius_m) {
        ++a.period_away;
        ++a.period_verdicts[row.reason];
      }
      if (!row.accepted) {
        ++a.rejected[row.reason];
        continue;
      }
      ++a.accepted;
      const auto ea = fusion::interpolatePose(estimate, row.candidate_t_ns);
      const auto eb = fusion::interpolatePose(estimate, row.query_t_ns);
      const double pair_error = ea && eb
                                    ? ((eb->translation() - ea->translation()) - true_rel).norm()
                                    : std::numeric_limits<double>::infinity();
      if (true_distance > kSearchRadius_m || !(pair_error < kPairTolerance_m)) {
        a.false_loops.push_back(fmt::format(
            "query {:.3f} s, candidate {:.3f} s: true distance {:.2f} m, pair error {:.2f} m, "
            "inliers {}, correction {:.2f} m",
            1e-9 * static_cast<double>(row.query_t_ns),
            1e-9 * static_cast<double>(row.candidate_t_ns), true_distance, pair_error, row.inliers,
            row.correction_m));
      }
    }
    std::string reasons, period;
    for (const auto& [reason, n] : a.rejected) reasons += fmt::format(" {} {}", reason, n);
    for (const auto& [reason, n] : a.period_verdicts) period += fmt::format(" {} {}", reason, n);
    std::cout << fmt::format(
        "[ repetitive, {} ] verified {}, accepted {} ({} false), rejected:{}; verified pairs "
        "10-20 m apart in truth (a period away): {}:{}\n",
        name, a.verified, a.accepted, a.false_loops.size(), reasons, a.period_away, period);
    for (const auto& row : a.false_loops) std::cout << "  false loop: " << row << "\n";
    return a;
  }

  static std::unique_ptr<TempDir> tmp_;
  static fs::path sim_;
};
std::unique_ptr<TempDir> CliLoopsRepetitive::tmp_;
fs::path CliLoopsRepetitive::sim_;

TEST_F(CliLoopsRepetitive, PureVioAcceptsNoFalseLoop) {
  const nlohmann::json r = run("off", "--gnss off");
  ASSERT_TRUE(r["loops"].is_object()) << r.dump(2);
  EXPECT_GT(r["loops"]["pairs_in_radius"].get<int>(), 0);
  const LoopAudit a = audit("off");
  EXPECT_GT(a.verified, 0);
  EXPECT_TRUE(a.false_loops.empty());
}

TEST_F(CliLoopsRepetitive, GraphWithSppGnssAcceptsNoFalseLoop) {
  const nlohmann::json r = run("graph", fmt::format("--gnss graph {}", kSimGeo));
  ASSERT_TRUE(r["loops"].is_object()) << r.dump(2);
  EXPECT_GT(r["loops"]["pairs_in_radius"].get<int>(), 0);
  const LoopAudit a = audit("graph");
  EXPECT_GT(a.verified, 0);
  EXPECT_TRUE(a.false_loops.empty());
}

}  // namespace
}  // namespace gvio::test
