// gvio view's site (app/view): the data files the page reads, checked by reading them back as
// the page does (base64, the quantised chunks, the scene), and the loopback server.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <octomap/ColorOcTree.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <atomic>
#include <regex>
#include <thread>

#include "io/trajectory_io.hpp"
#include "run/gnss_run.hpp"
#include "support/fixtures.hpp"
#include "view/base64.hpp"
#include "view/static_server.hpp"
#include "view/view_points.hpp"
#include "view/view_site.hpp"

// Last: glibc's resolv.h, which httplib.h includes, defines _res, a name Eigen's headers use.
#include <httplib.h>

#include "io/input_error.hpp"

namespace gvio::test {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;
using testing::HasSubstr;

std::string base64(std::string_view s) {
  std::string out;
  view::appendBase64(out, s);
  return out;
}

std::string unbase64(const std::string& s) {
  static const std::string alphabet =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  unsigned v = 0;
  int bits = 0;
  for (const char c : s) {
    if (c == '=') break;
    v = (v << 6U) | static_cast<unsigned>(alphabet.find(c));
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out += static_cast<char>((v >> static_cast<unsigned>(bits)) & 0xFFU);
    }
  }
  return out;
}

// RFC 4648 section 10's test vectors.
TEST(ViewBase64, Rfc4648Vectors) {
  EXPECT_EQ(base64(""), "");
  EXPECT_EQ(base64("f"), "Zg==");
  EXPECT_EQ(base64("fo"), "Zm8=");
  EXPECT_EQ(base64("foo"), "Zm9v");
  EXPECT_EQ(base64("foob"), "Zm9vYg==");
  EXPECT_EQ(base64("fooba"), "Zm9vYmE=");
  EXPECT_EQ(base64("foobar"), "Zm9vYmFy");
  std::string all;
  for (int i = 0; i < 256; ++i) all += static_cast<char>(i);
  EXPECT_EQ(unbase64(base64(all)), all);
}

struct Chunk {
  std::size_t n = 0;
  std::string bytes;
};

// points/NAME.js as the page reads it: gvioChunk("NAME", N, "BASE64").
Chunk readChunk(const fs::path& file, const std::string& name) {
  const std::string text = readText(file);
  static const std::regex call(R"re(^gvioChunk\("([0-7r]+)",(\d+),"([A-Za-z0-9+/=]*)"\);\n$)re");
  std::smatch m;
  EXPECT_TRUE(std::regex_match(text, m, call)) << file;
  EXPECT_EQ(m[1].str(), name);
  Chunk c{std::stoul(m[2].str()), unbase64(m[3].str())};
  EXPECT_EQ(c.bytes.size(), 10 * c.n) << file;
  return c;
}

template <typename T>
T at(const std::string& bytes, std::size_t offset) {
  T v;
  std::memcpy(&v, bytes.data() + offset, sizeof(T));
  return v;
}

view::ViewCloud spiral(std::size_t n) {
  view::ViewCloud c;
  for (std::size_t i = 0; i < n; ++i) {
    const double a = 0.01 * static_cast<double>(i);
    c.push({30.0 * std::cos(a) + 0.001 * i, 20.0 * std::sin(3 * a), 0.002 * i},
           static_cast<std::uint8_t>(i % 256), static_cast<std::uint8_t>(i % 7 == 0 ? 0 : 1),
           static_cast<std::uint16_t>(i % 5));
  }
  return c;
}

// Every point in exactly one chunk, within half a quantisation step of where it was, with its
// intensity, kind and drive; the index's counts, children and cubes agree with the files.
TEST(ViewPoints, ChunksHoldEveryPointOnceQuantisedInTheirCube) {
  const TempDir dir("viewpoints");
  const view::ViewCloud cloud = spiral(5000);
  mapping::PointLodConfig lod;
  lod.grid_cells = 8;
  lod.max_points_per_node = 300;
  const view::PointChunks chunks = view::writePointChunks(dir.path(), cloud, lod);
  ASSERT_EQ(chunks.points, cloud.size());
  ASSERT_GT(chunks.depth, 1);
  ASSERT_EQ(chunks.index.size(), chunks.nodes);
  std::vector<int> times_seen(cloud.size(), 0);
  std::size_t total = 0;
  for (const json& node : chunks.index) {
    const std::string name = node["name"];
    for (const json& c : node["children"]) {
      const std::string child = chunks.index[c.get<std::size_t>()]["name"];
      EXPECT_EQ(child.substr(0, name.size()), name);
      EXPECT_EQ(child.size(), name.size() + 1);
    }
    const std::size_t n = node["points"];
    ASSERT_EQ(fs::exists(dir.path() / (name + ".js")), n > 0) << name;
    if (n == 0) continue;
    const Chunk c = readChunk(dir.path() / (name + ".js"), name);
    ASSERT_EQ(c.n, n);
    total += n;
    const double size = node["cube"][3];
    for (std::size_t k = 0; k < n; ++k) {
      Eigen::Vector3d p;
      for (int a = 0; a < 3; ++a) {
        p[a] = node["cube"][a].get<double>() +
               at<std::uint16_t>(c.bytes, 6 * k + 2 * static_cast<std::size_t>(a)) / 65535.0 * size;
      }
      // The nearest input point: the one this must be (points are 3+ cm apart, steps < 1 mm).
      std::size_t best = 0;
      for (std::size_t i = 1; i < cloud.size(); ++i) {
        if ((cloud.p[i] - p).squaredNorm() < (cloud.p[best] - p).squaredNorm()) best = i;
      }
      EXPECT_LE((cloud.p[best] - p).cwiseAbs().maxCoeff(), 0.5 * size / 65535.0 + 1e-9);
      EXPECT_EQ(at<std::uint16_t>(c.bytes, 6 * n + 2 * k), cloud.drive[best]);
      EXPECT_EQ(static_cast<std::uint8_t>(c.bytes[8 * n + k]), cloud.intensity[best]);
      EXPECT_EQ(static_cast<std::uint8_t>(c.bytes[9 * n + k]), cloud.kind[best]);
      ++times_seen[best];
    }
  }
  EXPECT_EQ(total, cloud.size());
  EXPECT_EQ(std::count(times_seen.begin(), times_seen.end(), 1), static_cast<long>(cloud.size()))
      << "a point twice, another never";
}

const fusion::Lla kOrigin{49.011, 8.4, 112.5};

class ViewSite : public ::testing::Test {
 protected:
  void SetUp() override {
    fs::create_directories(run_);
    run::GnssRunResult r;
    r.origin = kOrigin;
    r.fused = ellipseDrive();
    Eigen::Isometry3d T_enu_w = Eigen::Isometry3d::Identity();
    T_enu_w.translation() = Eigen::Vector3d(5, 0, 0);
    r.T_enu_w = T_enu_w;
    run::writeGeoreferencedOutputs(run_, r);
    io::writeTum(run_ / "trajectory_vio.tum", ellipseDrive());
    writeText(run_ / "gnss_fixes.csv",
              "t_s,e_m,n_m,u_m,status\n1317300000.0,50,0,0,used\n1317300000.5,nan,nan,nan,"
              "unaligned\n1317300001.0,48,9,0,rejected\n");
    pcl::PointCloud<pcl::PointXYZI> c;
    octomap::ColorOcTree tree(0.5);
    for (int i = 0; i < 400; ++i) {
      pcl::PointXYZI p;
      p.x = static_cast<float>(-60.0 + 0.3 * i);
      p.y = static_cast<float>(40.0 * std::sin(0.05 * i));
      p.z = static_cast<float>(0.01 * i);
      p.intensity = static_cast<float>(i % 256);
      c.push_back(p);
      tree.updateNode(octomap::point3d(p.x, p.y, p.z), true);
    }
    ASSERT_EQ(pcl::io::savePCDFileBinaryCompressed((run_ / "map.pcd").string(), c), 0);
    ASSERT_TRUE(tree.write((run_ / "map.ot").string()));
    voxels_ = 0;
    for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it) {
      if (tree.isNodeOccupied(*it)) ++voxels_;
    }
    fs::create_directories(page_);
    writeText(page_ / "index.html", "<!doctype html>");
    writeText(page_ / "viewer.js", "/* the viewer */");
  }

  static json scene(const fs::path& site) {
    const std::string text = readText(site / "data" / "scene.js");
    EXPECT_EQ(text.rfind("gvioScene(", 0), 0U);
    EXPECT_EQ(text.substr(text.size() - 3), ");\n");
    return json::parse(text.substr(10, text.size() - 13));
  }

  TempDir dir_{"viewsite"};
  fs::path run_ = dir_.path() / "run", page_ = dir_.path() / "page";
  std::size_t voxels_ = 0;
};

TEST_F(ViewSite, WritesThePageTheSceneThePointsAndTheVoxels) {
  view::ViewInput in = view::readViewInput(run_);
  const fs::path site = dir_.path() / "site";
  const view::ViewSiteSummary s = view::writeViewSite(in, site, page_);
  EXPECT_EQ(s.points, 400U);
  EXPECT_EQ(s.voxels, voxels_);
  EXPECT_EQ(s.trajectories, 2U);  // fused and VIO; no truth, no online
  EXPECT_EQ(readText(site / "viewer.js"), "/* the viewer */");
  const json j = scene(site);
  EXPECT_EQ(j["kind"], "run");
  EXPECT_EQ(j["frame"]["type"], "enu");
  EXPECT_DOUBLE_EQ(j["frame"]["lat_deg"].get<double>(), kOrigin.lat_deg);
  ASSERT_EQ(j["trajectories"].size(), 2U);
  EXPECT_EQ(j["trajectories"][0]["name"], "fused");
  EXPECT_EQ(j["trajectories"][0]["p"].size(), 300U);
  EXPECT_DOUBLE_EQ(j["trajectories"][0]["p"][0].get<double>(), 50.0);
  // The VIO trajectory moved into ENU by georef.json's T_enu_w.
  EXPECT_EQ(j["trajectories"][1]["name"], "vio");
  EXPECT_DOUBLE_EQ(j["trajectories"][1]["p"][0].get<double>(), 55.0);
  // Fixes with a position, with what the run did with them.
  EXPECT_EQ(j["fixes"]["status"], json({"used", "rejected"}));
  EXPECT_EQ(j["points"]["count"], 400);
  EXPECT_EQ(j["voxels"]["count"], voxels_);
  EXPECT_TRUE(fs::exists(site / "data" / "points" / "r.js"));
  const std::string voxels = readText(site / "data" / "voxels.js");
  EXPECT_EQ(voxels.rfind("gvioVoxels(" + std::to_string(voxels_) + ",", 0), 0U);
}

TEST_F(ViewSite, ReplacesItsOwnSiteAndRefusesAnyOtherFolder) {
  const fs::path site = dir_.path() / "site";
  view::ViewInput in = view::readViewInput(run_);
  (void)view::writeViewSite(in, site, page_);
  writeText(site / "stale.txt", "from before");
  view::ViewInput again = view::readViewInput(run_);
  (void)view::writeViewSite(again, site, page_);
  EXPECT_FALSE(fs::exists(site / "stale.txt"));
  const fs::path mine = dir_.path() / "mine";
  fs::create_directories(mine);
  writeText(mine / "keep.txt", "x");
  view::ViewInput third = view::readViewInput(run_);
  try {
    (void)view::writeViewSite(third, mine, page_);
    FAIL() << "wrote over a folder that is not a site";
  } catch (const io::InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("is not a gvio view site"));
  }
  EXPECT_TRUE(fs::exists(mine / "keep.txt"));
}

// Through the binary: a site for the run, and bad input refused in one line, exit 2.
TEST_F(ViewSite, CliWritesTheSiteAndRefusesBadInputInOneLine) {
  const bool built = !view::builtViewerPage().empty();
  const auto ok = runGvio("view --run " + quoted(run_) + " --images 0");
  if (built) {
    ASSERT_EQ(ok.exit_code, 0) << ok.err;
    EXPECT_THAT(ok.err, HasSubstr("400 points in 1 octree nodes"));
    EXPECT_TRUE(view::isViewSite(run_ / "viewer"));
  } else {
    EXPECT_EQ(ok.exit_code, 2);
    EXPECT_THAT(ok.err, HasSubstr("./setup.sh viewer"));
  }
  const auto missing = runGvio("view --run " + quoted(dir_.path() / "nope"));
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_THAT(missing.err, HasSubstr(built ? "run folder not found" : "./setup.sh viewer"));
  EXPECT_EQ(std::count(missing.err.begin(), missing.err.end(), '\n'), 1) << missing.err;
  if (!built) return;
  writeText(dir_.path() / "mine" / "keep.txt", "x");
  const auto refused =
      runGvio("view --run " + quoted(run_) + " --images 0 --out " + quoted(dir_.path() / "mine"));
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_THAT(refused.err, HasSubstr("is not a gvio view site"));
}

// The folder over HTTP on loopback, nothing outside it, stopped on request.
TEST_F(ViewSite, ServesTheFolderOnLoopbackOnly) {
  fs::create_directories(dir_.path() / "site" / "data");
  writeText(dir_.path() / "site" / "index.html", "<p>hello</p>");
  writeText(dir_.path() / "site" / "data" / "scene.js", "gvioScene({});");
  writeText(dir_.path() / "secret.txt", "not served");
  std::atomic<bool> stop{false};
  std::atomic<int> port{0};
  std::thread server([&] {
    view::serveFolder(
        dir_.path() / "site", 0, [&](int p) { port = p; }, [&] { return stop.load(); });
  });
  while (port == 0) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  httplib::Client client("127.0.0.1", port);
  const auto index = client.Get("/index.html");
  ASSERT_TRUE(index);
  EXPECT_EQ(index->status, 200);
  EXPECT_EQ(index->body, "<p>hello</p>");
  const auto script = client.Get("/data/scene.js");
  ASSERT_TRUE(script);
  EXPECT_THAT(script->get_header_value("Content-Type"), HasSubstr("javascript"));
  const auto outside = client.Get("/../secret.txt");
  ASSERT_TRUE(outside);
  EXPECT_NE(outside->status, 200);
  EXPECT_THAT(outside->body, testing::Not(HasSubstr("not served")));
  stop = true;
  server.join();
}

}  // namespace
}  // namespace gvio::test
