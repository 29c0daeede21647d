#include "io/trajectory_io.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include "io/input_error.hpp"
#include "odometry/error.hpp"
#include "support/errors.hpp"

namespace gvio::io {
namespace {

namespace fs = std::filesystem;
using test::inputError;
using test::names;

class TrajectoryIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("gvio_traj_test_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  fs::path write(const std::string& name, const std::string& text) const {
    const fs::path path = dir_ / name;
    std::ofstream(path) << text;
    return path;
  }
  [[nodiscard]] fs::path path(const std::string& name) const { return dir_ / name; }

  fs::path dir_;
};

// A trajectory with awkward stamps (not multiples of a round step) and generic rotations.
Trajectory sampleTrajectory() {
  Trajectory traj;
  for (int i = 0; i < 20; ++i) {
    const double a = 0.37 * i;
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = (Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()) *
                     Eigen::AngleAxisd(0.5 - 0.11 * i, Eigen::Vector3d::UnitY()) *
                     Eigen::AngleAxisd(-1.3 + 0.2 * i, Eigen::Vector3d::UnitX()))
                        .toRotationMatrix();
    pose.translation() = Eigen::Vector3d(std::sin(a) * 123.456789, -0.001 * i, 1e3 + i);
    traj.t_ns.push_back(1403715273262142976LL + i * 50'000'001LL);
    traj.poses.push_back(pose);
  }
  return traj;
}

// Translations must survive to 1e-9. Rotations are compared with `rotation_tol`: a quaternion
// printed with 9 decimals (TUM, EuRoC) moves entries of R by up to ~2e-9, KITTI's 13 significant
// digits by far less.
void expectSamePoses(const Trajectory& a, const Trajectory& b, double rotation_tol) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    const Eigen::Vector3d dt = a.poses[i].translation() - b.poses[i].translation();
    const Eigen::Matrix3d dr = a.poses[i].linear() - b.poses[i].linear();
    EXPECT_LT(dt.cwiseAbs().maxCoeff(), 1e-9) << "pose " << i;
    EXPECT_LT(dr.cwiseAbs().maxCoeff(), rotation_tol) << "pose " << i;
  }
}

TEST(TrajectoryIoFormat, ParsesAndPrintsNames) {
  for (const auto f :
       {TrajectoryFormat::kTum, TrajectoryFormat::kKitti, TrajectoryFormat::kEuroc}) {
    EXPECT_EQ(parseTrajectoryFormat(toString(f)), f);
  }
  EXPECT_EQ(toString(TrajectoryFormat::kEuroc), "euroc");
  EXPECT_FALSE(parseTrajectoryFormat("csv").has_value());
  EXPECT_FALSE(parseTrajectoryFormat("").has_value());
}

TEST_F(TrajectoryIoTest, ReadsTumWithQuaternionWLast) {
  const fs::path file = write("a.tum",
                              "# timestamp tx ty tz qx qy qz qw\n"
                              "\n"
                              "1403715273.262142976 1 2 3 0 0 0.70710678118654752 "
                              "0.70710678118654752\n"
                              "  1403715273.3\t4  5 6 0 0 0 1\r\n");
  const Trajectory traj = readTum(file);
  ASSERT_EQ(traj.size(), 2u);
  EXPECT_EQ(traj.t_ns[0], 1403715273262142976LL);
  EXPECT_EQ(traj.t_ns[1], 1403715273300000000LL);
  EXPECT_TRUE(traj.poses[0].translation().isApprox(Eigen::Vector3d(1, 2, 3)));
  // 90 degrees about z: x axis maps to y.
  EXPECT_NEAR((traj.poses[0].linear() * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(),
              0.0, 1e-12);
  EXPECT_TRUE(traj.poses[1].linear().isIdentity(1e-15));
}

TEST_F(TrajectoryIoTest, ReadsEurocWithQuaternionWFirstAndExtraColumns) {
  const fs::path file = write("a.csv",
                              "#timestamp [ns],p_x,p_y,p_z,q_w,q_x,q_y,q_z,v_x,v_y,v_z\n"
                              "1403715273262142976, 1,2,3,0.70710678118654752,0,0,"
                              "0.70710678118654752,9,9,9\n"
                              "1403715273312143104,4,5,6,1,0,0,0\n");
  const Trajectory traj = readEurocCsv(file);
  ASSERT_EQ(traj.size(), 2u);
  EXPECT_EQ(traj.t_ns[0], 1403715273262142976LL);
  EXPECT_EQ(traj.t_ns[1], 1403715273312143104LL);
  EXPECT_TRUE(traj.poses[0].translation().isApprox(Eigen::Vector3d(1, 2, 3)));
  EXPECT_NEAR((traj.poses[0].linear() * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(),
              0.0, 1e-12);
  EXPECT_TRUE(traj.poses[1].linear().isIdentity(1e-15));
}

TEST_F(TrajectoryIoTest, ReadsEurocFloatNanosecondStamps) {
  const fs::path file = write("f.csv", "1.5e9,0,0,0,1,0,0,0\n2000000000.0,0,0,0,1,0,0,0\n");
  const Trajectory traj = readEurocCsv(file);
  ASSERT_EQ(traj.size(), 2u);
  EXPECT_EQ(traj.t_ns[0], 1'500'000'000LL);
  EXPECT_EQ(traj.t_ns[1], 2'000'000'000LL);
}

TEST_F(TrajectoryIoTest, ReadsKittiRowMajorWithoutTimestamps) {
  const fs::path file = write("a.kitti",
                              "0 -1 0 1 1 0 0 2 0 0 1 3\n"
                              "# comment\n"
                              "1 0 0 4 0 1 0 5 0 0 1 6\n");
  const Trajectory traj = readKitti(file);
  ASSERT_EQ(traj.size(), 2u);
  EXPECT_FALSE(traj.hasTimestamps());
  EXPECT_EQ(traj.poses[0].linear()(0, 1), -1.0);
  EXPECT_EQ(traj.poses[0].linear()(1, 0), 1.0);
  EXPECT_EQ(traj.poses[0].translation(), Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(traj.poses[1].translation(), Eigen::Vector3d(4, 5, 6));
}

TEST_F(TrajectoryIoTest, KeepsKittiRotationAsRead) {
  const fs::path file = write("r.kitti", "9.999999e-01 1e-4 0 0 -1e-4 1.0000001 0 0 0 0 1 0\n");
  const Eigen::Matrix3d r = readKitti(file).poses[0].linear();
  EXPECT_EQ(r(0, 0), 9.999999e-01);
  EXPECT_EQ(r(0, 1), 1e-4);
  EXPECT_EQ(r(1, 1), 1.0000001);
}

TEST_F(TrajectoryIoTest, ReadsKittiTimesFile) {
  const fs::path file = write("b.kitti", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 1 0 1 0 0 0 0 1 0\n");
  const fs::path times = write("times.txt", "# s\n0.000000e+00\n\n1.037359e-01\n");
  const Trajectory traj = readTrajectory(file, TrajectoryFormat::kKitti, times);
  ASSERT_EQ(traj.t_ns.size(), 2u);
  EXPECT_EQ(traj.t_ns[0], 0);
  EXPECT_EQ(traj.t_ns[1], 103'735'900LL);
}

TEST_F(TrajectoryIoTest, RejectsKittiTimesCountMismatch) {
  const fs::path file = write("c.kitti", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 1 0 1 0 0 0 0 1 0\n");
  const fs::path times = write("short_times.txt", "0.0\n0.1\n0.2\n");
  const std::string msg = inputError([&] { readKitti(file, times); });
  EXPECT_NE(msg.find(times.string() + ": 3 timestamps for 2 poses"), std::string::npos) << msg;
}

TEST_F(TrajectoryIoTest, RejectsMalformedKittiTimes) {
  const fs::path file = write("d.kitti", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 1 0 1 0 0 0 0 1 0\n");
  const fs::path times = write("bad_times.txt", "0.0\n0.1x\n");
  EXPECT_TRUE(names(inputError([&] { readKitti(file, times); }), times, 2, "malformed"));
}

TEST_F(TrajectoryIoTest, RejectsTimesFileForOtherFormats) {
  const fs::path file = write("e.tum", "0 0 0 0 0 0 0 1\n");
  EXPECT_THROW(readTrajectory(file, TrajectoryFormat::kTum, path("times.txt")), InvalidInput);
}

TEST_F(TrajectoryIoTest, RoundTripsTum) {
  const Trajectory traj = sampleTrajectory();
  writeTrajectory(path("rt.tum"), traj, TrajectoryFormat::kTum);
  const Trajectory back = readTrajectory(path("rt.tum"), TrajectoryFormat::kTum);
  EXPECT_EQ(back.t_ns, traj.t_ns);
  expectSamePoses(back, traj, 3e-9);
}

TEST_F(TrajectoryIoTest, RoundTripsEuroc) {
  const Trajectory traj = sampleTrajectory();
  writeTrajectory(path("rt.csv"), traj, TrajectoryFormat::kEuroc);
  const Trajectory back = readTrajectory(path("rt.csv"), TrajectoryFormat::kEuroc);
  EXPECT_EQ(back.t_ns, traj.t_ns);
  expectSamePoses(back, traj, 3e-9);
}

TEST_F(TrajectoryIoTest, RoundTripsKittiWithTimes) {
  const Trajectory traj = sampleTrajectory();
  writeTrajectory(path("rt.kitti"), traj, TrajectoryFormat::kKitti);
  writeKittiTimes(path("rt_times.txt"), traj);
  const Trajectory back = readKitti(path("rt.kitti"), path("rt_times.txt"));
  EXPECT_EQ(back.t_ns, traj.t_ns);
  expectSamePoses(back, traj, 1e-12);
}

TEST_F(TrajectoryIoTest, WritesDocumentedLayouts) {
  Trajectory traj;
  traj.t_ns = {1'500'000'001LL};
  traj.poses = {Eigen::Isometry3d(Eigen::Translation3d(1, 2, 3))};
  writeTum(path("l.tum"), traj);
  writeEurocCsv(path("l.csv"), traj);
  writeKitti(path("l.kitti"), traj);
  auto slurp = [](const fs::path& p) {
    std::ifstream in(p);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  EXPECT_EQ(slurp(path("l.tum")),
            "1.500000001 1.000000000 2.000000000 3.000000000 0.000000000 0.000000000 0.000000000 "
            "1.000000000\n");
  EXPECT_EQ(slurp(path("l.csv")),
            "#timestamp [ns],p_x [m],p_y [m],p_z [m],q_w [],q_x [],q_y [],q_z []\n"
            "1500000001,1.000000000,2.000000000,3.000000000,1.000000000,0.000000000,0.000000000,"
            "0.000000000\n");
  EXPECT_EQ(slurp(path("l.kitti")).substr(0, 38), "1.000000000000e+00 0.000000000000e+00 ");
}

TEST_F(TrajectoryIoTest, WritersNeedingTimestampsRejectNone) {
  Trajectory traj = sampleTrajectory();
  traj.t_ns.clear();
  EXPECT_THROW(writeTum(path("n.tum"), traj), InvalidInput);
  EXPECT_THROW(writeEurocCsv(path("n.csv"), traj), InvalidInput);
  EXPECT_THROW(writeKittiTimes(path("n.txt"), traj), InvalidInput);
  EXPECT_NO_THROW(writeKitti(path("n.kitti"), traj));
  EXPECT_FALSE(fs::exists(path("n.tum")));
}

TEST_F(TrajectoryIoTest, WriterNamesMissingDirectory) {
  const fs::path file = path("no_such_dir") / "x.tum";
  EXPECT_NE(inputError([&] { writeTum(file, sampleTrajectory()); }).find(file.string()),
            std::string::npos);
}

TEST_F(TrajectoryIoTest, RejectsTumWrongFieldCount) {
  const fs::path file = write("count.tum", "# header\n0 0 0 0 0 0 0 1\n1 0 0 0 0 0 1\n");
  EXPECT_TRUE(names(inputError([&] { readTum(file); }), file, 3, "expected 8 fields, got 7"));
}

TEST_F(TrajectoryIoTest, RejectsKittiWrongFieldCount) {
  const fs::path file = write("count.kitti", "1 0 0 0 0 1 0 0 0 0 1 0 7\n");
  EXPECT_TRUE(names(inputError([&] { readKitti(file); }), file, 1, "expected 12 fields, got 13"));
}

TEST_F(TrajectoryIoTest, RejectsEurocTooFewFields) {
  const fs::path file = write("count.csv", "#h\n1,0,0,0,1,0,0,0\n2,0,0,0,1,0,0\n");
  EXPECT_TRUE(
      names(inputError([&] { readEurocCsv(file); }), file, 3, "expected at least 8 fields, got 7"));
}

TEST_F(TrajectoryIoTest, RejectsMalformedNumber) {
  const fs::path file = write("bad.tum", "0 0 0 0 0 0 0 1\n1 0 0 0.5x 0 0 0 1\n");
  EXPECT_TRUE(names(inputError([&] { readTum(file); }), file, 2, "malformed tz '0.5x'"));
}

TEST_F(TrajectoryIoTest, RejectsMalformedTimestamp) {
  const fs::path file = write("badt.csv", "12a4,0,0,0,1,0,0,0\n");
  EXPECT_TRUE(names(inputError([&] { readEurocCsv(file); }), file, 1, "malformed timestamp"));
}

TEST_F(TrajectoryIoTest, RejectsNan) {
  const fs::path file = write("nan.csv", "1,0,nan,0,1,0,0,0\n");
  EXPECT_TRUE(names(inputError([&] { readEurocCsv(file); }), file, 1, "p_y"));
}

TEST_F(TrajectoryIoTest, RejectsInf) {
  const fs::path file = write("inf.kitti", "1 0 0 0\t0 1 0 inf 0 0 1 0\n");
  EXPECT_TRUE(names(inputError([&] { readKitti(file); }), file, 1, "ty"));
}

TEST_F(TrajectoryIoTest, RejectsDecreasingTimestamp) {
  const fs::path file = write("dec.tum", "2 0 0 0 0 0 0 1\n\n1 0 0 0 0 0 0 1\n");
  EXPECT_TRUE(names(inputError([&] { readTum(file); }), file, 3,
                    "timestamp not increasing (previous 2.000000000"));
}

TEST_F(TrajectoryIoTest, RejectsDuplicateTimestamp) {
  const fs::path file = write("dup.csv", "#h\n5,0,0,0,1,0,0,0\n6,0,0,0,1,0,0,0\n6,0,0,0,1,0,0,0\n");
  EXPECT_TRUE(names(inputError([&] { readEurocCsv(file); }), file, 4,
                    "timestamp not increasing (previous 0.000000006"));
}

// gvio eval reads stamps as evo does: in any order, with a summary of what is not increasing.
TEST_F(TrajectoryIoTest, AsGivenKeepsRepeatsAndStepsBackInFileOrder) {
  const fs::path tum = write("any.tum",
                             "2 0 0 0 0 0 0 1\n2 1 0 0 0 0 0 1\n1 2 0 0 0 0 0 1\n"
                             "3 3 0 0 0 0 0 1\n3 4 0 0 0 0 0 1\n");
  const Trajectory t = readTum(tum, StampOrder::kAsGiven);
  ASSERT_EQ(t.size(), 5U);
  EXPECT_EQ(t.t_ns, (std::vector<std::int64_t>{2'000'000'000, 2'000'000'000, 1'000'000'000,
                                               3'000'000'000, 3'000'000'000}));
  EXPECT_DOUBLE_EQ(t.poses[2].translation().x(), 2.0);
  const StampOrderSummary s = summarizeStampOrder(t.t_ns);
  EXPECT_EQ(s.repeated, 2U);
  EXPECT_EQ(s.steps_back, 1U);
  EXPECT_EQ(s.first_index, 1U);
  EXPECT_EQ(summarizeStampOrder({1, 2, 3}).repeated + summarizeStampOrder({1, 2, 3}).steps_back,
            0U);
  const fs::path csv = write("any.csv", "6,0,0,0,1,0,0,0\n6,0,0,0,1,0,0,0\n");
  EXPECT_EQ(
      readTrajectory(csv, TrajectoryFormat::kEuroc, std::nullopt, StampOrder::kAsGiven).size(), 2U);
  const fs::path kitti = write("k.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1 0\n");
  const fs::path times = write("times.txt", "0.5\n0.5\n");
  EXPECT_EQ(readKitti(kitti, times, StampOrder::kAsGiven).t_ns.size(), 2U);
  EXPECT_THROW(readKitti(kitti, times), InputError);  // the default stays strict
}

TEST_F(TrajectoryIoTest, RejectsUnnormalisedQuaternion) {
  const fs::path file = write("q.tum", "0 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1.01\n");
  EXPECT_TRUE(
      names(inputError([&] { readTum(file); }), file, 2, "quaternion not normalised (|q| = 1.01"));
}

TEST_F(TrajectoryIoTest, RejectsNonRotationKitti) {
  const fs::path scaled = write("s.kitti", "1 0 0 0 0 1 0 0 0 0 1 0\n1.01 0 0 0 0 1 0 0 0 0 1 0\n");
  EXPECT_TRUE(names(inputError([&] { readKitti(scaled); }), scaled, 2, "not a rotation"));
  const fs::path mirrored = write("m.kitti", "-1 0 0 0 0 1 0 0 0 0 1 0\n");
  EXPECT_TRUE(names(inputError([&] { readKitti(mirrored); }), mirrored, 1, "not a rotation"));
}

TEST_F(TrajectoryIoTest, RejectsMissingFile) {
  const fs::path file = path("absent.tum");
  const std::string msg = inputError([&] { readTum(file); });
  EXPECT_NE(msg.find(file.string() + ": file not found"), std::string::npos) << msg;
}

TEST_F(TrajectoryIoTest, RejectsFileWithoutPoses) {
  for (const auto format :
       {TrajectoryFormat::kTum, TrajectoryFormat::kKitti, TrajectoryFormat::kEuroc}) {
    const fs::path file = write("empty_" + toString(format), "# only a header\n\n");
    const std::string msg = inputError([&] { readTrajectory(file, format); });
    EXPECT_NE(msg.find(file.string() + ": no poses"), std::string::npos) << msg;
  }
}

TEST(TrajectoryIoSharedData, ReadsKitti00GroundTruth) {
  const fs::path dir = fs::path(GVIO_SHARED_DATA_DIR) / "kitti00";
  if (!fs::exists(dir / "KITTI_00_gt.txt") || !fs::exists(dir / "KITTI_00_gt_times.txt")) {
    GTEST_SKIP() << "shared data absent: " << dir;
  }
  const Trajectory traj = readKitti(dir / "KITTI_00_gt.txt", dir / "KITTI_00_gt_times.txt");
  ASSERT_EQ(traj.size(), 4541u);
  ASSERT_EQ(traj.t_ns.size(), 4541u);
  EXPECT_EQ(traj.t_ns.front(), 0);
  EXPECT_EQ(traj.t_ns.back(), 470'581'600'000LL);  // "4.705816e+02"
  EXPECT_TRUE(traj.poses.front().matrix().isIdentity(1e-6));
  EXPECT_NEAR(traj.poses[1].translation().z(), 0.8586941, 1e-12);
}

// evo's own reference estimate: its rotations are printed with 9 digits and are not exactly
// orthonormal, which must not trip the "not a rotation" check.
TEST(TrajectoryIoSharedData, ReadsEvoKitti00OrbEstimate) {
  const fs::path file = fs::path(GVIO_SHARED_DATA_DIR) / "evo_kitti00" / "KITTI_00_ORB.txt";
  if (!fs::exists(file)) GTEST_SKIP() << "shared data absent: " << file;
  const Trajectory traj = readKitti(file);
  EXPECT_EQ(traj.size(), 4541u);
  EXPECT_EQ(traj.poses.front().linear()(1, 1), 0.999999940);
}

TEST(TrajectoryIoSharedData, ReadsEurocV101GroundTruth) {
  const fs::path file =
      fs::path(GVIO_SHARED_DATA_DIR) / "euroc_v101_micro" / "groundtruth_V1_01_easy.csv";
  if (!fs::exists(file)) GTEST_SKIP() << "shared data absent: " << file;
  const Trajectory traj = readEurocCsv(file);
  ASSERT_EQ(traj.size(), 2895u);
  EXPECT_EQ(traj.t_ns.front(), 1403715273262142976LL);
  EXPECT_EQ(traj.t_ns.back(), 1403715417962142976LL);
  EXPECT_TRUE(
      traj.poses.front().translation().isApprox(Eigen::Vector3d(0.878895, 2.1834, 0.948427)));
  const Eigen::Quaterniond q(traj.poses.front().linear());
  const Eigen::Quaterniond expected =
      Eigen::Quaterniond(0.069433, -0.824237, -0.106942, -0.551702).normalized();
  EXPECT_NEAR(q.angularDistance(expected), 0.0, 1e-9);
}

}  // namespace
}  // namespace gvio::io
