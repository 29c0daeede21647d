// `gvio simulate --orientation file|motion` end to end: a ground-truth file whose body has travel
// along -z (a camera-like mount) warns with file and drives the body the file says; with motion
// the written truth has a vehicle body along the travel direction and the road's climb. A vehicle
// frame drive is unchanged and does not warn. Short mono drives: rendering is the slow part.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "io/trajectory_io.hpp"
#include "support/fixtures.hpp"
#include "support/sim_orientation.hpp"

namespace gvio::test {
namespace {
using testing::HasSubstr;
using testing::Not;
namespace fs = std::filesystem;

constexpr double kDeg = 180.0 / std::numbers::pi;
constexpr const char* kWarning = "from the direction of travel";

std::size_t countLines(const std::string& text, const std::string& needle) {
  std::size_t count = 0;
  for (std::size_t at = text.find(needle); at != std::string::npos; at = text.find(needle, at + 1))
    ++count;
  return count;
}

class SimOrientationCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<TempDir>("sim_orientation");
    io::writeTum(dir_->path() / "cam.tum",
                 ClimbingCurve{}.poses(10.0, ClimbingCurve::mountTravelAlongMinusZ()));
    io::writeTum(dir_->path() / "car.tum", demoDrive());
  }
  static void TearDownTestSuite() { dir_.reset(); }
  static CommandResult simulate(const std::string& trajectory, const std::string& out,
                                const std::string& args) {
    return runGvio(
        fmt::format("simulate --trajectory {} --camera mono --seed 5 {} --out {} "
                    "--no-progress",
                    quoted(dir_->path() / trajectory), args, quoted(dir_->path() / out)));
  }
  static std::unique_ptr<TempDir> dir_;
};
std::unique_ptr<TempDir> SimOrientationCli::dir_;

TEST_F(SimOrientationCli, FileWarnsOnceWithTheAxisOfTravel) {
  const auto r = simulate("cam.tum", "file", "--seconds 0.3 --orientation file");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::cout << r.err;
  EXPECT_EQ(countLines(r.err, kWarning), 1u) << r.err;
  EXPECT_THAT(r.err, HasSubstr("cam.tum"));
  EXPECT_THAT(r.err, HasSubstr("along its -z axis"));
  EXPECT_THAT(r.err, HasSubstr("--orientation motion"));
  // The body is the file's: travel along its -z.
  const Trajectory truth = io::readTum(dir_->path() / "file" / "groundtruth.tum");
  const ClimbingCurve curve;
  const Eigen::Isometry3d& T_w_b = truth.poses[truth.size() / 2];
  EXPECT_GT(-T_w_b.linear().col(2).dot(curve.travelAt(T_w_b.translation())), 0.99);
}

TEST_F(SimOrientationCli, MotionDrivesAVehicleAlongThePath) {
  const auto r = simulate("cam.tum", "motion", "--seconds 2 --orientation motion");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.err, Not(HasSubstr(kWarning)));
  const Trajectory truth = io::readTum(dir_->path() / "motion" / "groundtruth.tum");
  ASSERT_EQ(truth.size(), 201u);
  const ClimbingCurve curve;
  double worst_x_deg = 0.0, worst_pitch_deg = 0.0, worst_roll_deg = 0.0;
  for (const auto& T_w_b : truth.poses) {
    const Eigen::Matrix3d R_w_b = T_w_b.linear();
    const Eigen::Vector3d travel_w = curve.travelAt(T_w_b.translation());
    worst_x_deg =
        std::max(worst_x_deg, std::acos(std::clamp(R_w_b.col(0).dot(travel_w), -1.0, 1.0)) * kDeg);
    worst_pitch_deg =
        std::max(worst_pitch_deg, std::abs(std::asin(R_w_b(2, 0)) - curve.climbRad()) * kDeg);
    worst_roll_deg = std::max(worst_roll_deg, std::abs(std::asin(R_w_b(2, 1))) * kDeg);
  }
  std::cout << "[ orientation ] simulated truth: worst x-to-travel " << worst_x_deg
            << " deg, pitch error " << worst_pitch_deg << " deg, roll " << worst_roll_deg
            << " deg\n";
  EXPECT_LT(worst_x_deg, 2.0);
  EXPECT_LT(worst_pitch_deg, 0.5);
  EXPECT_LT(worst_roll_deg, 0.5);
  const YAML::Node yaml = YAML::LoadFile((dir_->path() / "motion" / "sim.yaml").string());
  EXPECT_EQ(yaml["orientation"].as<std::string>(), "motion");
}

// A vehicle-frame file: no warning, and --orientation file is the default, byte for byte.
TEST_F(SimOrientationCli, VehicleFrameIsUnchangedAndQuiet) {
  const auto plain = simulate("car.tum", "default", "--seconds 0.3");
  const auto file = simulate("car.tum", "explicit", "--seconds 0.3 --orientation file");
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  ASSERT_EQ(file.exit_code, 0) << file.err;
  EXPECT_THAT(plain.err, Not(HasSubstr(kWarning)));
  EXPECT_THAT(file.err, Not(HasSubstr(kWarning)));
  std::size_t compared = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir_->path() / "default")) {
    if (!e.is_regular_file()) continue;
    const fs::path other =
        dir_->path() / "explicit" / fs::relative(e.path(), dir_->path() / "default");
    EXPECT_EQ(readText(e.path()), readText(other)) << other;
    ++compared;
  }
  EXPECT_GT(compared, 10u);
}

TEST_F(SimOrientationCli, MotionOnAPathAtRestIsOneLineExit2) {
  writeText(dir_->path() / "still.tum",
            "0 1 2 0 0 0 0 1\n0.1 1 2 0 0 0 0 1\n0.2 1 2 0 0 0 0 1\n0.3 1 2 0 0 0 0 1\n"
            "0.4 1 2 0 0 0 0 1\n");
  const auto r = simulate("still.tum", "still", "--orientation motion");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_THAT(r.err, HasSubstr("still.tum"));
  EXPECT_THAT(r.err, HasSubstr("no heading"));
}

// A value other than file or motion: one line naming the flag and what it accepts, exit 2.
TEST_F(SimOrientationCli, BadValueIsOneLineExit2) {
  const auto r = simulate("car.tum", "bad", "--orientation sideways");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_THAT(r.err, HasSubstr("--orientation 'sideways'"));
  EXPECT_THAT(r.err, HasSubstr("file or motion"));
  EXPECT_FALSE(fs::exists(dir_->path() / "bad"));
}

}  // namespace
}  // namespace gvio::test
