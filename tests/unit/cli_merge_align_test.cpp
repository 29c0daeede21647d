// gvio merge's joint alignment (issue 18): two drives over the same streets, each with its own
// SPP-grade receiver error, are brought into agreement by loops between them and one joint pose
// graph before their maps are merged; alignment.json says how far each drive moved.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <vector>

#include "io/run_dir.hpp"
#include "support/fixtures.hpp"

namespace gvio::test {
namespace {
using testing::HasSubstr;
namespace fs = std::filesystem;

// Median horizontal distance (m) from drive 2's track vertices in tiles.geojson to drive 1's track
// (the polyline), in a local tangent plane (metres per degree at the first vertex: ample over a
// few hundred metres).
double trackSeparationM(const fs::path& map) {
  const nlohmann::json geo = io::readJsonObject(map / "tiles.geojson");
  std::map<int, std::vector<Eigen::Vector2d>> tracks;
  std::optional<Eigen::Vector2d> origin;
  for (const auto& f : geo["features"]) {
    if (f["properties"]["kind"] != "track") continue;
    auto& line = tracks[f["properties"]["point_source_id"].get<int>()];
    for (const auto& c : f["geometry"]["coordinates"]) {
      const Eigen::Vector2d lon_lat(c[0].get<double>(), c[1].get<double>());
      if (!origin) origin = lon_lat;
      const double m_per_deg = 111319.5;
      line.emplace_back(
          (lon_lat.x() - origin->x()) * m_per_deg * std::cos(origin->y() * M_PI / 180),
          (lon_lat.y() - origin->y()) * m_per_deg);
    }
  }
  EXPECT_EQ(tracks.size(), 2U);
  const auto& first = tracks[1];
  std::vector<double> d;
  for (const Eigen::Vector2d& p : tracks[2]) {
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k + 1 < first.size(); ++k) {
      const Eigen::Vector2d a = first[k], ab = first[k + 1] - a;
      const double t = std::clamp((p - a).dot(ab) / std::max(ab.squaredNorm(), 1e-12), 0.0, 1.0);
      best = std::min(best, (a + t * ab - p).norm());
    }
    d.push_back(best);
  }
  if (d.empty()) return std::numeric_limits<double>::infinity();
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return d[d.size() / 2];
}

class CliMergeAlign : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir("cli_merge_align");
    for (const int seed : {31, 32}) {
      const fs::path sim = cachedSimulation(
          fmt::format("--trajectory {}/assets/demo/drive.tum --seconds 12 --seed {} --world-seed 7 "
                      "--gnss-noise spp",
                      GVIO_SOURCE_DIR, seed));
      const CommandResult r = runGvio(fmt::format("run --dataset {} --out {} --no-progress {}",
                                                  quoted(sim), quoted(run(seed)), kSimGeo));
      ASSERT_EQ(r.exit_code, 0) << r.err;
    }
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  static fs::path run(int seed) { return dir_->path() / fmt::format("run{}", seed); }
  static CommandResult merge(const std::string& runs, const fs::path& out,
                             const std::string& extra = "") {
    return runGvio(fmt::format("merge --runs {} --out {} {}", runs, quoted(out), extra));
  }
  static inline TempDir* dir_ = nullptr;
};

TEST_F(CliMergeAlign, LoopsBetweenTheDrivesBringTheirMapsIntoAgreement) {
  const std::string runs = quoted(run(31)) + " " + quoted(run(32));
  ASSERT_TRUE(fs::is_regular_file(run(31) / "keyframes.bin"));
  const fs::path apart = dir_->path() / "apart", joint = dir_->path() / "joint";
  const CommandResult a = merge(runs, apart, "--set merge.align=false");
  ASSERT_EQ(a.exit_code, 0) << a.err;
  EXPECT_FALSE(fs::exists(apart / "alignment.json"));
  const CommandResult j = merge(runs, joint);
  ASSERT_EQ(j.exit_code, 0) << j.err;

  const nlohmann::json align = io::readJsonObject(joint / "alignment.json");
  EXPECT_TRUE(align["solved"].get<bool>()) << align.dump(2);
  EXPECT_GT(align["accepted"].get<int>(), 10) << align.dump(2);
  EXPECT_GT(align["active"].get<int>(), 10);
  EXPECT_TRUE(align["graph"]["converged"].get<bool>());
  ASSERT_EQ(align["drives"].size(), 2U);
  for (const auto& d : align["drives"]) {
    EXPECT_TRUE(d["aligned"].get<bool>()) << d.dump();
    EXPECT_GT(d["loops_active"].get<int>(), 10);
    EXPECT_GT(d["keyframes"].get<int>(), 50);
    EXPECT_GT(d["fixes"].get<int>(), 5);
    EXPECT_LT(d["moved_m"]["max"].get<double>(), 5.0);  // SPP-grade: metres at most
  }
  // Two receivers' errors differ: at least one drive moved noticeably.
  EXPECT_GT(std::max(align["drives"][0]["moved_m"]["mean"].get<double>(),
                     align["drives"][1]["moved_m"]["mean"].get<double>()),
            0.05);
  const std::string csv = readText(joint / "alignment_loops.csv");
  EXPECT_THAT(csv, testing::StartsWith("query_drive,candidate_drive,query_t_s,candidate_t_s,"));
  EXPECT_THAT(csv, HasSubstr("run32,run31,"));
  EXPECT_THAT(csv, testing::Not(HasSubstr("run31,run31,")));  // only across drives

  // The second drive's dense points agree with the first's far better after the alignment.
  const auto agreement = [](const fs::path& map) {
    return io::readJsonObject(map / "tiles.json")["drives"][1]["agreement"];
  };
  const nlohmann::json before = agreement(apart), after = agreement(joint);
  std::cout << "agreement within 0.2 m: " << before["within_percent"] << " % (median "
            << before["median_m"] << " m) apart, " << after["within_percent"] << " % (median "
            << after["median_m"] << " m) aligned\n";
  EXPECT_GT(after["within_percent"].get<double>(), before["within_percent"].get<double>() + 10.0);
  EXPECT_LT(after["median_m"].get<double>(), 0.2);
  // The tracks in tiles.geojson move with the maps: the same route's two tracks lie on each
  // other once aligned (the map's agreement, centimetres), a receiver's error apart before.
  const double track_apart_m = trackSeparationM(apart), track_joint_m = trackSeparationM(joint);
  std::cout << "track separation (median): " << track_apart_m << " m apart, " << track_joint_m
            << " m aligned\n";
  EXPECT_LT(track_joint_m, 0.2);
  EXPECT_LT(track_joint_m, 0.5 * track_apart_m);
  // Every point is still merged.
  EXPECT_EQ(io::readJsonObject(apart / "tiles.json")["points"],
            io::readJsonObject(joint / "tiles.json")["points"]);
}

TEST_F(CliMergeAlign, ARunWithoutKeyframesIsMergedAsItIsAndADamagedOneIsRefused) {
  const fs::path copy = dir_->path() / "copy";
  fs::create_directories(copy);
  for (const char* f : {"georef.json", "map.pcd", "trajectory_lla.csv"}) {
    fs::copy_file(run(32) / f, copy / f);
  }
  const fs::path out = dir_->path() / "without";
  const CommandResult r = merge(quoted(run(31)) + " " + quoted(copy), out);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("copy: no keyframes.bin"));
  const nlohmann::json align = io::readJsonObject(out / "alignment.json");
  EXPECT_FALSE(align["solved"].get<bool>());
  EXPECT_FALSE(align["drives"][1]["aligned"].get<bool>());
  EXPECT_THAT(align["drives"][1]["note"].get<std::string>(), HasSubstr("no keyframes.bin"));

  writeText(copy / "keyframes.bin", "GVIOKFDB\x01");
  const CommandResult bad = merge(quoted(run(31)) + " " + quoted(copy), out);
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_THAT(bad.err, HasSubstr("copy/keyframes.bin"));
  EXPECT_THAT(bad.err, HasSubstr("the file ends early"));
  EXPECT_EQ(std::count(bad.err.begin(), bad.err.end(), '\n'), 1) << bad.err;
}

}  // namespace
}  // namespace gvio::test
