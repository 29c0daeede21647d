// keyframes.bin (io/place_database_io.hpp): a run's place database written and read back exactly,
// and every kind of damage refused with the byte offset, never a crash or a huge allocation.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <opencv2/core.hpp>
#include <random>

#include "io/input_error.hpp"
#include "io/place_database_io.hpp"
#include "support/fixtures.hpp"

namespace gvio::io {
namespace {
using testing::HasSubstr;
namespace fs = std::filesystem;

mapping::PlaceDatabase makeDatabase() {
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> u(-5.0F, 5.0F);
  mapping::PlaceDatabase db;
  db.has_imu = true;
  db.camera.width_px = 1241;
  db.camera.height_px = 376;
  db.camera.fx = db.camera.fy = 718.856;
  db.camera.cx = 607.19;
  db.camera.cy = 185.22;
  db.camera.T_b_c.translation() = Eigen::Vector3d(0.1, -0.2, 0.3);
  for (int k = 0; k < 3; ++k) {
    mapping::LoopKeyframe kf;
    kf.t_ns = 1'000'000'000LL * (k + 1);
    const int n = 5 + k;
    for (int i = 0; i < n; ++i) kf.px.push_back(Eigen::Vector2f{u(rng) + 100.0F, u(rng) + 50.0F});
    kf.descriptors.create(n, 32, CV_8U);
    for (int i = 0; i < n * 32; ++i) kf.descriptors.data[i] = static_cast<std::uint8_t>(rng());
    for (int i = 0; i < 3; ++i) kf.p_c.push_back(Eigen::Vector3f{u(rng), u(rng), 10.0F + u(rng)});
    kf.points = kf.p_c.size();
    if (k != 1) {
      kf.thumbnail.resize(mapping::kThumbnailWidth * mapping::kThumbnailHeight);
      for (float& v : kf.thumbnail) v = u(rng);
    }
    db.keyframes.push_back(kf);
    mapping::KeyframePrior p;
    p.t_ns = kf.t_ns;
    p.T_ref_b.linear() = Eigen::AngleAxisd(0.3 * k, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    p.T_ref_b.translation() = Eigen::Vector3d(10.0 * k, 1.0, 0.5);
    p.sigma_m = k == 2 ? std::numeric_limits<double>::infinity() : 0.8;
    p.sigma_rot_deg = k == 2 ? std::numeric_limits<double>::infinity() : 1.5;
    p.path_m = 10.0 * k;
    db.priors.push_back(p);
    db.T_vio.push_back(p.T_ref_b.inverse());
  }
  fusion::GraphFix f;
  f.node = 1;
  f.t_ns = 2'100'000'000;
  f.q_b = Eigen::Vector3d(0, 0, 0.8);
  f.p_enu = Eigen::Vector3d(10.2, 0.9, 1.1);
  f.sigma_h_m = 1.5;
  f.sigma_v_m = 3.0;
  f.quality = 4;
  f.shape_en << 1.4, 0.3, 0.3, 0.6;
  db.fixes.push_back(f);
  fusion::GraphLoop l;
  l.i = 0;
  l.j = 2;
  l.T_i_j.translation() = Eigen::Vector3d(0.5, 0.1, 0.0);
  l.covariance = 1e-4 * Eigen::Matrix<double, 6, 6>::Identity();
  l.covariance(0, 1) = l.covariance(1, 0) = 2e-5;
  db.loops.push_back(l);
  return db;
}

std::string bytesOf(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(PlaceDatabaseIo, WrittenAndReadBackExactly) {
  const test::TempDir dir("place_db");
  const mapping::PlaceDatabase db = makeDatabase();
  writePlaceDatabase(dir.path() / "keyframes.bin", db);
  const mapping::PlaceDatabase back = readPlaceDatabase(dir.path() / "keyframes.bin");
  EXPECT_TRUE(back.has_imu);
  EXPECT_EQ(back.camera.width_px, 1241);
  EXPECT_EQ(back.camera.cx, db.camera.cx);
  EXPECT_TRUE(back.camera.T_b_c.isApprox(db.camera.T_b_c, 0.0));
  ASSERT_EQ(back.keyframes.size(), 3U);
  for (std::size_t k = 0; k < 3; ++k) {
    const auto &a = db.keyframes[k], &b = back.keyframes[k];
    EXPECT_EQ(a.t_ns, b.t_ns);
    EXPECT_EQ(a.px, b.px);
    EXPECT_EQ(a.p_c, b.p_c);
    EXPECT_EQ(a.points, b.points);
    EXPECT_EQ(a.thumbnail, b.thumbnail);
    ASSERT_EQ(b.descriptors.rows, a.descriptors.rows);
    EXPECT_EQ(cv::norm(a.descriptors, b.descriptors, cv::NORM_HAMMING), 0.0);
    EXPECT_TRUE(back.priors[k].T_ref_b.isApprox(db.priors[k].T_ref_b, 0.0));
    EXPECT_TRUE(back.T_vio[k].isApprox(db.T_vio[k], 0.0));
    EXPECT_EQ(back.priors[k].sigma_m, db.priors[k].sigma_m);
    EXPECT_EQ(back.priors[k].sigma_rot_deg, db.priors[k].sigma_rot_deg);
    EXPECT_EQ(back.priors[k].path_m, db.priors[k].path_m);
  }
  ASSERT_EQ(back.fixes.size(), 1U);
  EXPECT_EQ(back.fixes[0].node, 1U);
  EXPECT_EQ(back.fixes[0].p_enu, db.fixes[0].p_enu);
  EXPECT_EQ(back.fixes[0].sigma_v_m, 3.0);
  EXPECT_EQ(back.fixes[0].quality, 4);
  EXPECT_EQ(back.fixes[0].shape_en, db.fixes[0].shape_en);
  ASSERT_EQ(back.loops.size(), 1U);
  EXPECT_EQ(back.loops[0].j, 2U);
  EXPECT_EQ(back.loops[0].covariance, db.loops[0].covariance);
}

TEST(PlaceDatabaseIo, DamageIsRefusedWithItsByteOffset) {
  const test::TempDir dir("place_db_bad");
  const fs::path file = dir.path() / "keyframes.bin";
  writePlaceDatabase(file, makeDatabase());
  const std::string good = bytesOf(file);
  const auto refused = [&](const std::string& bytes, const std::string& message) {
    try {
      parsePlaceDatabase(bytes, file);
      ADD_FAILURE() << "accepted: " << message;
    } catch (const InputError& e) {
      EXPECT_THAT(e.what(), HasSubstr("keyframes.bin"));
      EXPECT_THAT(e.what(), HasSubstr(message));
    }
  };
  refused("", "too short");
  refused("GVIOKFDX" + good.substr(8), "not a gvio keyframe database");
  refused(good.substr(0, good.size() - 1), "the file ends early");
  refused(good + "x", "bytes after the last record");
  for (std::size_t cut = 0; cut < good.size(); cut += 7) {
    EXPECT_THROW(parsePlaceDatabase(good.substr(0, cut), file), InputError) << cut;
  }
  // A keyframe count of 2^60: refused before anything is allocated.
  std::string huge = good;
  const std::size_t counts = 8 + 4 + 4 + 4 + 4 + 4 * 8 + 12 * 8;
  const std::uint64_t n = 1ULL << 60;
  std::memcpy(huge.data() + counts, &n, 8);
  refused(huge, "the file ends early");
  // A NaN focal length, a rotation that is not one.
  std::string nan = good;
  const double q = std::nan("");
  std::memcpy(nan.data() + 8 + 4 + 4 + 4 + 4, &q, 8);
  refused(nan, "byte 24: a value that is not finite");
  std::string skew = good;
  const double two = 2.0;
  std::memcpy(skew.data() + 8 + 4 + 4 + 4 + 4 + 4 * 8, &two, 8);
  refused(skew, "a pose whose rotation is not a rotation");
  EXPECT_THROW(readPlaceDatabase(dir.path() / "missing.bin"), InputError);
  // The fix's quality (version 2) out of NMEA's range, its ellipse (version 3) not one; a version
  // not yet written.
  const std::size_t loop_bytes = 2 * 8 + 48 * 8;
  const std::size_t shape_at = good.size() - loop_bytes - 3 * 8;  // before the one loop
  const std::size_t quality_at = shape_at - 4;
  std::string bad_quality = good;
  const std::int32_t twelve = 12;
  std::memcpy(bad_quality.data() + quality_at, &twelve, 4);
  refused(bad_quality, "a fix quality that is not 0..9");
  std::string bad_shape = good;
  const double thin = 1.3;  // en: |0.3| -> 1.3 > sqrt(1.4 x 0.6)
  std::memcpy(bad_shape.data() + shape_at + 16, &thin, 8);
  refused(bad_shape, "a fix ellipse shape that is not positive definite with trace 2");
  std::string future = good;
  const std::uint32_t four = 4;
  std::memcpy(future.data() + 8, &four, 4);
  refused(future, "a version this gvio does not read");
}

// Files written before the fix quality (version 1) are still read, their fixes as quality 1, and
// those before the ellipse (versions 1 and 2) with circular fixes.
TEST(PlaceDatabaseIo, VersionOneIsReadWithSinglePointFixes) {
  const test::TempDir dir("place_db_v1");
  const fs::path file = dir.path() / "keyframes.bin";
  writePlaceDatabase(file, makeDatabase());
  std::string v1 = bytesOf(file);
  const std::uint32_t one = 1;
  std::memcpy(v1.data() + 8, &one, 4);
  v1.erase(v1.size() - (2 * 8 + 48 * 8) - 3 * 8 - 4, 3 * 8 + 4);
  const mapping::PlaceDatabase back = parsePlaceDatabase(v1, file);
  ASSERT_EQ(back.fixes.size(), 1U);
  EXPECT_EQ(back.fixes[0].quality, 1);
  EXPECT_EQ(back.fixes[0].shape_en, Eigen::Matrix2d::Identity());
  EXPECT_EQ(back.fixes[0].sigma_v_m, 3.0);
  ASSERT_EQ(back.loops.size(), 1U);
  EXPECT_EQ(back.loops[0].covariance, makeDatabase().loops[0].covariance);
  std::string v2 = bytesOf(file);
  const std::uint32_t two = 2;
  std::memcpy(v2.data() + 8, &two, 4);
  v2.erase(v2.size() - (2 * 8 + 48 * 8) - 3 * 8, 3 * 8);
  const mapping::PlaceDatabase back2 = parsePlaceDatabase(v2, file);
  ASSERT_EQ(back2.fixes.size(), 1U);
  EXPECT_EQ(back2.fixes[0].quality, 4);
  EXPECT_EQ(back2.fixes[0].shape_en, Eigen::Matrix2d::Identity());
}

}  // namespace
}  // namespace gvio::io
