// The run-folder map files `gvio render` reads (io::readRunDir): map.pcd through PCL, map.ot /
// map.bt through OctoMap, gnss_fixes.csv, report.json outages; malformed files fail with one line
// naming the file (and line).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>

#include "io/input_error.hpp"
#include "io/loops_csv.hpp"
#include "io/run_dir.hpp"
#include "render_map_fixture.hpp"

namespace gvio::test {
namespace {
namespace fs = std::filesystem;
using testing::HasSubstr;

class RenderMapIo : public ::testing::Test {
 protected:
  void SetUp() override { writeSyntheticMapRun(run_); }
  // The one-line message readRunDir throws.
  std::string failure() {
    try {
      io::readRunDir(run_);
    } catch (const io::InputError& e) {
      return e.what();
    }
    return "(no error)";
  }
  TempDir dir_{"rendermapio"};
  fs::path run_ = dir_.path() / "run";
};

TEST_F(RenderMapIo, ReadsEveryMapFile) {
  const io::RunFiles r = io::readRunDir(run_);
  ASSERT_TRUE(r.cloud.has_value());
  const auto want = syntheticMapPoints();
  ASSERT_EQ(r.cloud->p_enu.size(), want.size());
  ASSERT_EQ(r.cloud->intensity.size(), want.size());
  ASSERT_EQ(r.cloud->source.size(), want.size());
  for (std::size_t i = 0; i < want.size(); i += 97) {
    EXPECT_EQ(r.cloud->p_enu[i], Eigen::Vector3f(want[i].x, want[i].y, want[i].z)) << i;
    EXPECT_EQ(r.cloud->intensity[i], want[i].intensity);
    EXPECT_EQ(r.cloud->source[i], want[i].source);
  }
  ASSERT_TRUE(r.occupancy.has_value());
  EXPECT_EQ(r.occupancy->file.filename(), "map.ot");
  EXPECT_TRUE(r.occupancy->has_color);
  EXPECT_DOUBLE_EQ(r.occupancy->resolution_m, 0.5);
  std::size_t red = 0, blue = 0;
  for (const auto& v : r.occupancy->voxels) {
    const auto volume =
        static_cast<std::size_t>(std::lround(std::pow(static_cast<double>(v.size_m) / 0.5, 3)));
    if (v.rgb == std::array<std::uint8_t, 3>{220, 30, 20}) red += volume;
    if (v.rgb == std::array<std::uint8_t, 3>{20, 40, 230}) blue += volume;
  }
  EXPECT_EQ(red, 8U);
  EXPECT_EQ(blue, 64U);
  ASSERT_TRUE(r.gnss_fixes.has_value());
  ASSERT_EQ(r.gnss_fixes->size(), 5U);
  EXPECT_EQ((*r.gnss_fixes)[2].status, io::FixStatus::kRejected);
  EXPECT_TRUE((*r.gnss_fixes)[2].p_enu.isApprox(Eigen::Vector3d(20, 4, 1)));
  EXPECT_EQ((*r.gnss_fixes)[3].status, io::FixStatus::kSkipped);
  EXPECT_FALSE((*r.gnss_fixes)[3].p_enu.allFinite());
  ASSERT_EQ(r.outages.size(), 1U);
  EXPECT_DOUBLE_EQ(r.outages[0].t0_s, 20.0);
  EXPECT_DOUBLE_EQ(r.outages[0].t1_s, 28.0);
}

TEST_F(RenderMapIo, BinaryTreeIsTheFallbackAndMapsAreReadOnRequest) {
  fs::remove(run_ / "map.ot");
  writeOcTreeBinary(run_ / "map.bt");
  io::RunReadOptions options;
  options.cloud = false;
  const io::RunFiles r = io::readRunDir(run_, options);
  EXPECT_FALSE(r.cloud.has_value());
  ASSERT_TRUE(r.occupancy.has_value());
  EXPECT_EQ(r.occupancy->file.filename(), "map.bt");
  EXPECT_FALSE(r.occupancy->has_color);
  double volume = 0.0;
  for (const auto& v : r.occupancy->voxels) volume += std::pow(static_cast<double>(v.size_m), 3);
  EXPECT_NEAR(volume, 72 * 0.125, 1e-9);  // the 8 + 64 leaves, pruned or not
  options.occupancy = false;
  EXPECT_FALSE(io::readRunDir(run_, options).occupancy.has_value());
}

TEST_F(RenderMapIo, OutageKeysWithUnitsAreAccepted) {
  writeText(run_ / "report.json", R"({"outages": [{"t0_s": 1.5, "t1_s": 2.5}]})");
  EXPECT_DOUBLE_EQ(io::readRunDir(run_).outages.at(0).t1_s, 2.5);
  writeText(run_ / "report.json", R"({"frames": 3})");
  EXPECT_TRUE(io::readRunDir(run_).outages.empty());
}

TEST_F(RenderMapIo, MalformedGnssFixesNameFileAndLine) {
  const fs::path csv = run_ / "gnss_fixes.csv";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"t_s,e_m,n_m,u_m,status\n1,2,3,4,used\n1,2,3,4,maybe\n", "gnss_fixes.csv:3: status 'maybe'"},
      {"t_s,e_m,n_m,u_m,status\n1,2,3,used\n", "gnss_fixes.csv:2: expected 5 fields, got 4"},
      {"t_s,e_m,n_m,status\n", "gnss_fixes.csv:1: header has no column 'u_m'"},
      {"t_s,e_m,n_m,u_m,status\n1,nan,3,4,used\n", "gnss_fixes.csv:2:"},
      {"t_s,e_m,n_m,u_m,status\n1,abc,3,4,skipped\n", "gnss_fixes.csv:2: e_m 'abc'"},
      {"t_s,e_m,n_m,u_m,status\n1,2,3,4,unmatched\n1,2,3,4,unaligned\n1,2,3,4,lost\n",
       "gnss_fixes.csv:4: status 'lost': expected used, rejected, skipped, unmatched or unaligned"},
      {"", "gnss_fixes.csv: empty file"},
  };
  for (const auto& [text, needle] : cases) {
    writeText(csv, text);
    const std::string msg = failure();
    EXPECT_THAT(msg, HasSubstr(needle)) << text;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
}

TEST_F(RenderMapIo, LoopsCsvIsReadWhenPresentAndAsked) {
  EXPECT_FALSE(io::readRunDir(run_).loops.has_value());  // the fixture has none
  const std::string header = std::string(io::kLoopsCsvHeader) + "\n";
  writeText(run_ / "loops.csv", header + "20.5,2.0,1.5,15.0,300,120,0.6,1.2,0.8,accepted,ok\n");
  const io::RunFiles r = io::readRunDir(run_);
  ASSERT_TRUE(r.loops.has_value());
  ASSERT_EQ(r.loops->size(), 1U);
  EXPECT_EQ(r.loops->at(0).query_t_ns, 20'500'000'000LL);
  EXPECT_TRUE(r.loops->at(0).accepted);
  writeText(run_ / "loops.csv", header + "20.5,2.0,1.5,15.0,300,120,0.6,1.2,0.8,kept,ok\n");
  EXPECT_THAT(failure(), HasSubstr("loops.csv:2: verdict 'kept'"));
  io::RunReadOptions options;
  options.loops = false;
  EXPECT_FALSE(io::readRunDir(run_, options).loops.has_value());
}

TEST_F(RenderMapIo, MalformedReportNamesFileAndLine) {
  writeText(run_ / "report.json", "{\n  \"frames\": 3,\n  \"outages\": [ {\"t0\": 1 ]\n}\n");
  EXPECT_THAT(failure(), HasSubstr("report.json:3: not valid JSON"));
  writeText(run_ / "report.json", R"({"outages": [{"t0": 5, "t1": 2}]})");
  EXPECT_THAT(failure(), HasSubstr("outages[0] ends before it starts"));
  writeText(run_ / "report.json", R"({"outages": [{"t0": 5}]})");
  EXPECT_THAT(failure(), HasSubstr("outages[0]: needs a finite number \"t1\""));
}

TEST_F(RenderMapIo, MalformedMapFilesFailInOneLine) {
  // PCL 1.13 itself crashes on the first of these.
  writeText(run_ / "map.pcd", "not a point cloud\n");
  EXPECT_THAT(failure(), HasSubstr("map.pcd:1: not a PCD header line"));
  writeText(run_ / "map.pcd",
            "VERSION .7\nFIELDS x y z\nSIZE 4 4\nTYPE F F F\nWIDTH 1\n"
            "HEIGHT 1\nPOINTS 1\nDATA ascii\n0 0 0\n");
  EXPECT_THAT(failure(), HasSubstr("map.pcd:8: PCD header: FIELDS, SIZE, TYPE"));
  writeMapPcd(run_ / "map.pcd", syntheticMapPoints());
  const std::string pcd = readText(run_ / "map.pcd");
  writeText(run_ / "map.pcd", pcd.substr(0, pcd.size() / 2));  // PCL pads to whole pages
  EXPECT_THAT(failure(), HasSubstr("map.pcd: PCD data is shorter than its header says"));
  writeText(run_ / "map.pcd",
            "VERSION .7\nFIELDS x y\nSIZE 4 4\nTYPE F F\nWIDTH 1\n"
            "HEIGHT 1\nPOINTS 1\nDATA ascii\n0 0\n");
  EXPECT_THAT(failure(), HasSubstr("map.pcd: PCD has no x, y and z fields"));
  writeMapPcd(run_ / "map.pcd", syntheticMapPoints());
  // A truncated tree (OctoMap itself would recurse into garbage) and a foreign file.
  const std::string ot = readText(run_ / "map.ot");
  writeText(run_ / "map.ot", ot.substr(0, ot.size() - 20));
  EXPECT_THAT(failure(), HasSubstr("map.ot: OctoMap data is truncated"));
  writeText(run_ / "map.ot", "# some other file\n");
  EXPECT_THAT(failure(), HasSubstr("map.ot:1: not an OctoMap .ot file"));
  writeText(run_ / "map.ot", "# Octomap OcTree file\nid OcTreeStamped\nsize 1\nres 0.1\ndata\n");
  EXPECT_THAT(failure(), HasSubstr("tree type 'OcTreeStamped' is not supported"));
  fs::remove(run_ / "map.ot");
  writeOcTreeBinary(run_ / "map.bt");
  const std::string bt = readText(run_ / "map.bt");
  writeText(run_ / "map.bt", bt.substr(0, bt.size() - 3));
  EXPECT_THAT(failure(), HasSubstr("map.bt: OctoMap data is truncated"));
}

}  // namespace
}  // namespace gvio::test
