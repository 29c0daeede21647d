// GNSS/INS on a slow ground robot (fusion/gnss_ins.hpp, fusion/ins_alignment.hpp,
// fusion/ins_mount.hpp): 1 m/s, a 30 Hz IMU turned 90 degrees in the vehicle,
// 2.5 Hz fixes without speed or course (a ROS NavSatFix), a 10 s wait at rest before driving off
// and a stop on the way. The heading comes from the track alignment, the trajectory starts at the
// anchor (fixes before the heading was known are replayed), the mount is estimated; and the
// alignment on its own: the heading of a drive whatever the IMU's yaw.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <random>

#include "fusion/gnss_ins.hpp"
#include "fusion/ins_alignment.hpp"

namespace gvio::fusion {
namespace {

constexpr std::int64_t kT0Ns = 2'000'000'000'000;
constexpr double kDeg = M_PI / 180.0;

struct Robot {
  double rest_s = 10.0, duration_s = 300.0;
  double stop_t0 = 150.0, stop_t1 = 160.0;  // decelerates to rest, waits, drives on
  double mount_yaw_rad = 90.0 * kDeg;
  Eigen::Vector3d lever_b{0.0, -0.2, 0.5};  // antenna in the IMU body frame
  Eigen::Matrix3d R_v_b() const {
    return Eigen::AngleAxisd(mount_yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  }
  // Speed: 0.5 m/s^2 ramps up and down to 1 m/s.
  double speed(double t) const {
    const auto ramp = [](double u) { return std::clamp(0.5 * u, 0.0, 1.0); };
    const double up = ramp(t - rest_s);
    const double down = 1.0 - ramp(t - (stop_t0 - 2.0)) + ramp(t - stop_t1);
    return std::min(up, std::clamp(down, 0.0, 1.0));
  }
  double yaw(double t) const {
    const double u = std::max(0.0, t - rest_s);
    return 0.7 + 1.2 * std::sin(2.0 * M_PI * u / 70.0) + 0.4 * std::sin(2.0 * M_PI * u / 23.0);
  }
  Eigen::Vector3d velocity(double t) const {
    return speed(t) * Eigen::Vector3d(std::cos(yaw(t)), std::sin(yaw(t)), 0.0);
  }
  Eigen::Matrix3d R_enu_b(double t) const {
    return Eigen::AngleAxisd(yaw(t), Eigen::Vector3d::UnitZ()).toRotationMatrix() * R_v_b();
  }
};

// Body positions on a 1 ms grid (trapezoidal integration of the velocity).
std::vector<Eigen::Vector3d> positions(const Robot& r) {
  const int n = static_cast<int>(r.duration_s * 1000.0) + 2;
  std::vector<Eigen::Vector3d> p(n, Eigen::Vector3d::Zero());
  for (int i = 1; i < n; ++i) {
    p[i] = p[i - 1] + 0.0005 * (r.velocity((i - 1) * 1e-3) + r.velocity(i * 1e-3));
  }
  return p;
}

Eigen::Vector3d positionAt(const std::vector<Eigen::Vector3d>& grid, double t) {
  const auto i = static_cast<std::size_t>(std::floor(t * 1000.0));
  const double s = t * 1000.0 - static_cast<double>(i);
  return (1.0 - s) * grid[i] + s * grid[std::min(i + 1, grid.size() - 1)];
}

ImuNoise consumerImu() {
  ImuNoise n;
  n.acc_noise_density = 0.02;    // m/s^2/sqrt(Hz)
  n.gyr_noise_density = 1.7e-3;  // 0.1 deg/s/sqrt(Hz)
  n.acc_random_walk = 1e-3;
  n.gyr_random_walk = 1e-4;
  return n;
}

struct Outcome {
  double rmse_h = 0.0, raw_rmse_h = 0.0, coverage = 0.0;
  double first_fix_s = 0.0, last_fix_s = 0.0;
  InsStats stats;
};

Outcome drive(const Robot& r, const InsConfig& config, unsigned seed) {
  const std::vector<Eigen::Vector3d> grid = positions(r);
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  const auto noise3 = [&](double sigma) -> Eigen::Vector3d {
    return Eigen::Vector3d(n01(rng), n01(rng), n01(rng)) * sigma;
  };
  const EnuFrame enu(Lla{43.47, -80.54, 330.0});
  GnssIns ins(config, enu);
  const Eigen::Vector3d ba(0.05, -0.04, 0.08), bg(0.004, -0.003, 0.002);
  const double imu_rate = 30.0;
  const double acc_sigma = config.imu.acc_noise_density * std::sqrt(imu_rate);
  const double gyr_sigma = config.imu.gyr_noise_density * std::sqrt(imu_rate);
  // SPP-like fixes: 1 m white noise per horizontal axis plus a first-order Gauss-Markov bias of
  // 0.7 m over 60 s.
  const double sigma_h = 1.0, sigma_v = 2.0, fix_dt = 0.4;
  Eigen::Vector2d bias = Eigen::Vector2d::Zero();
  Outcome out;
  double sse = 0.0, raw = 0.0;
  int n = 0, n_raw = 0, next_fix = 1;
  for (int i = 0; i / imu_rate <= r.duration_s - 0.5; ++i) {
    const double t = i / imu_rate;
    while (next_fix * fix_dt <= t) {
      const double ts = next_fix++ * fix_dt;
      const double phi = std::exp(-fix_dt / 60.0);
      bias = phi * bias + std::sqrt(1.0 - phi * phi) * 0.7 * Eigen::Vector2d(n01(rng), n01(rng));
      Eigen::Vector3d p_ant = positionAt(grid, ts) + r.R_enu_b(ts) * r.lever_b;
      p_ant += Eigen::Vector3d(bias.x() + sigma_h * n01(rng), bias.y() + sigma_h * n01(rng),
                               sigma_v * n01(rng));
      GnssFix fix;
      fix.t_ns = kT0Ns + static_cast<std::int64_t>(std::llround(ts * 1e9));
      const Lla lla = enu.toLla(p_ant);
      fix.lat_deg = lla.lat_deg;
      fix.lon_deg = lla.lon_deg;
      fix.h_ellipsoid_m = lla.h_ellipsoid_m;
      fix.sigma_h_m = sigma_h;
      fix.sigma_v_m = sigma_v;
      ins.addFix(fix);
      raw += (p_ant - positionAt(grid, ts)).head<2>().squaredNorm();
      ++n_raw;
      if (n_raw == 1) out.first_fix_s = ts;
      out.last_fix_s = ts;
    }
    constexpr double h = 1e-3;  // central differences of the analytic velocity and yaw
    const Eigen::Vector3d a_enu =
        (r.velocity(t + h) - r.velocity(std::max(0.0, t - h))) / (t + h - std::max(0.0, t - h));
    const double yaw_rate =
        (r.yaw(t + h) - r.yaw(std::max(0.0, t - h))) / (t + h - std::max(0.0, t - h));
    const Eigen::Matrix3d R = r.R_enu_b(t);
    ImuSample s;
    s.t_ns = kT0Ns + static_cast<std::int64_t>(std::llround(t * 1e9));
    s.acc_b_mps2 = R.transpose() * (a_enu - gravityEnu()) + ba + noise3(acc_sigma);
    s.gyr_b_radps =
        r.R_v_b().transpose() * Eigen::Vector3d(0, 0, yaw_rate) + bg + noise3(gyr_sigma);
    ins.addImu(s);
  }
  ins.finish();
  const Trajectory& traj = ins.trajectory();
  for (std::size_t k = 0; k < traj.size(); ++k) {
    const double t = static_cast<double>(traj.t_ns[k] - kT0Ns) * 1e-9;
    sse += (traj.poses[k].translation() - positionAt(grid, t)).head<2>().squaredNorm();
    ++n;
  }
  out.rmse_h = n > 0 ? std::sqrt(sse / n) : 1e9;
  out.raw_rmse_h = std::sqrt(raw / n_raw);
  if (!traj.empty()) {
    out.coverage = static_cast<double>(traj.t_ns.back() - traj.t_ns.front()) * 1e-9 /
                   (out.last_fix_s - out.first_fix_s);
  }
  out.stats = ins.stats();
  return out;
}

InsConfig robotConfig(const ImuNoise& imu = ImuNoise{}) {
  InsConfig c;
  c.imu = imu;
  c.lever_arm_b = Robot().lever_b;
  return c;  // the mount left unconfigured: estimated
}

// With the default IMU model (ImuNoise{}, the grade gvio simulate draws). Measured (seeds 1-3):
// the trajectory covers the fixes' whole span from the anchor at 0.5 s, horizontal RMS 0.98 /
// 0.85 / 1.17 m against the raw fixes' 1.64 / 1.55 / 1.71 m; heading from the alignment's sums
// after 50 / 48 s (sigma 5.0 / 4.7 deg), from the heading bank after 56 s on seed 3 (9.3 deg);
// mount yaw 93.7 / 89.6 / 95.0 deg.
TEST(GnssInsRobot, SlowRobotWithATurnedImuIsCoveredFromItsStart) {
  for (unsigned seed = 1; seed <= 3; ++seed) {
    const Outcome o = drive(Robot(), robotConfig(), seed);
    const InsStats& s = o.stats;
    ASSERT_TRUE(s.t_init_ns.has_value()) << "seed " << seed;
    const Eigen::Vector3d rpy_deg = s.mount ? Eigen::Vector3d(s.mount->rpy_rad / kDeg)
                                            : Eigen::Vector3d::Constant(std::nan(""));
    std::printf(
        "seed %u: coverage %.3f, rmse_h %.2f m (raw %.2f), init %s at %.1f s (heading at %.1f s, "
        "%.2f deg), used %d rejected %d before %d, mount rpy %.1f %.1f %.1f deg\n",
        seed, o.coverage, o.rmse_h, o.raw_rmse_h, s.init_method.c_str(),
        static_cast<double>(*s.t_init_ns - kT0Ns) * 1e-9,
        static_cast<double>(*s.t_heading_ns - kT0Ns) * 1e-9, s.init_heading_sigma_deg, s.fixes_used,
        s.fixes_rejected, s.fixes_before_init, rpy_deg.x(), rpy_deg.y(), rpy_deg.z());
    EXPECT_TRUE(s.init_method == "track" || s.init_method == "heading bank") << s.init_method;
    EXPECT_TRUE(s.init_quiet_start);
    EXPECT_GE(o.coverage, 0.95);
    EXPECT_LT(o.rmse_h, 0.7 * o.raw_rmse_h);
    EXPECT_LE(s.fixes_before_init, 5);
    ASSERT_TRUE(s.mount.has_value());
    EXPECT_NEAR(s.mount->rpy_rad.z(), 90.0 * kDeg, 6.0 * kDeg);
    EXPECT_GT(s.nhc_used, 300);
  }
}

// The same robot with its mount configured as zero and not estimated: the constraint then
// fights the motion (a robot moving along its body y axis) and its mean innovation says so.
// With a consumer-grade IMU (0.1 deg/s/sqrt(Hz) gyro, 0.02 m/s^2/sqrt(Hz) accelerometer) the
// residual gyro bias tilts the levelled frame faster than the turns reveal the mount: the
// alignment's sums find no heading (without the bank: no initialisation on seeds 1-3). The heading
// bank's scouts estimate tilt and bias with the fixes; the best leads the others by far after
// 60-90 s. Measured (seeds 1-3): heading at 86 / 59 / 62 s (sigma 10 deg), coverage 100 %,
// horizontal RMS 1.15 / 0.95 / 1.21 m against the raw fixes' 1.64 / 1.55 / 1.71 m, mount yaw
// 92.7 / 79.6 / 102.2 deg.
TEST(GnssInsRobot, ConsumerGradeImuIsAlignedByTheHeadingBank) {
  for (unsigned seed = 1; seed <= 3; ++seed) {
    const Outcome o = drive(Robot(), robotConfig(consumerImu()), seed);
    ASSERT_TRUE(o.stats.t_init_ns.has_value()) << "seed " << seed;
    std::printf(
        "consumer seed %u: %s, heading at %.1f s (%.1f deg), coverage %.3f, rmse_h %.2f m "
        "(raw %.2f)\n",
        seed, o.stats.init_method.c_str(), (*o.stats.t_heading_ns - kT0Ns) * 1e-9,
        o.stats.init_heading_sigma_deg, o.coverage, o.rmse_h, o.raw_rmse_h);
    EXPECT_EQ(o.stats.init_method, "heading bank");
    EXPECT_GE(o.coverage, 0.95);
    EXPECT_LT(o.rmse_h, 0.85 * o.raw_rmse_h);
    ASSERT_TRUE(o.stats.mount.has_value());
    EXPECT_NEAR(o.stats.mount->rpy_rad.z(), 90.0 * kDeg, 20.0 * kDeg);
  }
  // Without the bank the same drive never gets a heading; no fix is dropped for it, all are
  // reported as before initialisation.
  InsConfig no_bank = robotConfig(consumerImu());
  no_bank.align.hypotheses = 0;
  const Outcome o = drive(Robot(), no_bank, 1);
  EXPECT_FALSE(o.stats.t_init_ns.has_value());
  EXPECT_GE(o.stats.fixes_before_init, 700);
}

TEST(GnssInsRobot, AWrongMountShowsInTheConstraint) {
  InsConfig c = robotConfig();
  c.estimate_mount = false;
  const Outcome o = drive(Robot(), c, 1);
  const Eigen::Vector2d mean =
      o.stats.nhc_innovation_sum_mps / std::max(1, o.stats.nhc_used + o.stats.nhc_rejected);
  EXPECT_GT(std::abs(mean.x()), 0.15);
}

}  // namespace
}  // namespace gvio::fusion

namespace gvio::fusion {
namespace {

// The alignment alone on noise-free data: the heading of the body at the anchor, whatever the
// IMU's yaw in the vehicle.
TEST(TrackAlignment, FindsTheBodyHeadingWhateverTheMount) {
  for (const double mount_deg : {0.0, 90.0, -135.0}) {
    Robot r;
    r.mount_yaw_rad = mount_deg * kDeg;
    const std::vector<Eigen::Vector3d> grid = positions(r);
    std::vector<ImuSample> window;
    std::optional<TrackAlignment> align;
    std::optional<AlignmentSolution> solution;
    const Eigen::Vector3d bg(0.004, -0.003, 0.002);
    for (int i = 0; i < 30 * 120 && !solution; ++i) {
      const double t = i / 30.0;
      if (align && i % 12 == 0) {
        const Eigen::Vector3d p_ant = positionAt(grid, t) + r.R_enu_b(t) * r.lever_b;
        align->addFix(kT0Ns + static_cast<std::int64_t>(std::llround(t * 1e9)), p_ant, 0.5);
        solution = align->solve();
      }
      constexpr double h = 1e-3;
      const double t0 = std::max(0.0, t - h);
      const Eigen::Vector3d a_enu = (r.velocity(t + h) - r.velocity(t0)) / (t + h - t0);
      const double yaw_rate = (r.yaw(t + h) - r.yaw(t0)) / (t + h - t0);
      ImuSample s;
      s.t_ns = kT0Ns + static_cast<std::int64_t>(std::llround(t * 1e9));
      s.acc_b_mps2 = r.R_enu_b(t).transpose() * (a_enu - gravityEnu());
      s.gyr_b_radps = r.R_v_b().transpose() * Eigen::Vector3d(0, 0, yaw_rate) + bg;
      if (!align) {
        window.push_back(s);
        if (window.size() == 30) align.emplace(AlignmentConfig{}, window, r.lever_b);
      } else {
        align->addImu(s);
      }
    }
    ASSERT_TRUE(solution.has_value()) << "mount " << mount_deg;
    const double t_anchor = static_cast<double>(solution->anchor.t_ns - kT0Ns) * 1e-9;
    const Eigen::Matrix3d R_true = r.R_enu_b(t_anchor);
    const double err = Eigen::AngleAxisd(solution->R_enu_b.transpose() * R_true).angle();
    std::printf(
        "mount %.0f deg: heading error %.3f deg (sigma %.3f), mount yaw %.2f deg (sigma %.2f), "
        "%d fixes in %d chunks, anchor %.1f s\n",
        mount_deg, err / kDeg, solution->heading_sigma_rad / kDeg, solution->mount_yaw_rad / kDeg,
        solution->mount_yaw_sigma_rad / kDeg, solution->fixes, solution->chunks, t_anchor);
    EXPECT_LT(err, 1.0 * kDeg);
    EXPECT_NEAR(solution->mount_yaw_rad, r.mount_yaw_rad, 1.0 * kDeg);
    EXPECT_LT((solution->p_en - positionAt(grid, t_anchor).head<2>()).norm(), 0.5);
    EXPECT_LT((solution->bg_b_radps - bg).norm(), 1e-5);
  }
}

}  // namespace
}  // namespace gvio::fusion
