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
#include <optional>
#include <random>

#include "fusion/gnss_ins.hpp"
#include "fusion/ins_alignment.hpp"
#include "support/ins_drive.hpp"

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

// Body positions on a 1 ms grid.
std::vector<Eigen::Vector3d> positions(const Robot& r) {
  return test::positionsOnMsGrid(r.duration_s, [&r](double t) { return r.velocity(t); });
}

using test::positionAt;

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

// With `ahrs_sigma_deg`, the IMU also reports its attitude (an AHRS) stating that yaw 1-sigma,
// its yaw off by a constant error of that sigma (a magnetometer's: declination, soft iron).
Outcome drive(const Robot& r, const InsConfig& config, unsigned seed,
              std::optional<double> ahrs_sigma_deg = std::nullopt) {
  const std::vector<Eigen::Vector3d> grid = positions(r);
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  const auto noise3 = [&](double sigma) -> Eigen::Vector3d {
    // Drawn one by one: the order of a call's arguments is the compiler's choice, and the same
    // seed must give the same drive with gcc and clang.
    Eigen::Vector3d v;
    for (int i = 0; i < 3; ++i) v[i] = n01(rng);
    return v * sigma;
  };
  const EnuFrame enu(Lla{43.47, -80.54, 330.0});
  GnssIns ins(config, enu);
  const double ahrs_yaw_error = ahrs_sigma_deg ? *ahrs_sigma_deg * kDeg * n01(rng) : 0.0;
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
      const double be = n01(rng);
      const double bn = n01(rng);
      bias = phi * bias + std::sqrt(1.0 - phi * phi) * 0.7 * Eigen::Vector2d(be, bn);
      Eigen::Vector3d p_ant = positionAt(grid, ts) + r.R_enu_b(ts) * r.lever_b;
      const Eigen::Vector3d white = noise3(1.0);
      p_ant += Eigen::Vector3d(bias.x() + sigma_h * white.x(), bias.y() + sigma_h * white.y(),
                               sigma_v * white.z());
      ins.addFix(test::fixAt(enu, kT0Ns + static_cast<std::int64_t>(std::llround(ts * 1e9)), p_ant,
                             sigma_h, sigma_v));
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
    if (ahrs_sigma_deg) {
      const Eigen::Matrix3d error(Eigen::AngleAxisd(ahrs_yaw_error, Eigen::Vector3d::UnitZ()));
      ins.addAttitude({s.t_ns, error * R, *ahrs_sigma_deg * kDeg});
    }
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

// With the default IMU model (ImuNoise{}, the grade gvio simulate draws). Measured (seeds 1-6):
// the trajectory covers the fixes' whole span from the anchor at 0.5 s, horizontal RMS 1.00-1.26
// m against the raw fixes' 1.61-1.79 m (ratio 0.60-0.70); heading after 48-60 s, from the
// alignment's sums on seed 1, the heading bank on the others; mount yaw 79-107 deg.
TEST(GnssInsRobot, SlowRobotWithATurnedImuIsCoveredFromItsStart) {
  for (unsigned seed = 1; seed <= 6; ++seed) {
    const Outcome o = drive(Robot(), robotConfig(), seed);
    const InsStats& s = o.stats;
    if (!s.t_init_ns) {
      ADD_FAILURE() << "seed " << seed << ": not initialised";
      continue;
    }
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
    EXPECT_LT(o.rmse_h, 0.8 * o.raw_rmse_h);
    EXPECT_LE(s.fixes_before_init, 5);
    EXPECT_TRUE(s.mount.has_value());
    EXPECT_GT(s.nhc_used, 300);
  }
}

// With a consumer-grade IMU (0.1 deg/s/sqrt(Hz) gyro, 0.02 m/s^2/sqrt(Hz) accelerometer) the
// residual gyro bias tilts the levelled frame faster than the turns reveal the mount: the
// alignment's sums find no heading (without the bank: no initialisation). The heading bank's
// scouts estimate tilt and bias with the fixes; the best leads the others by far after 55-86 s.
// Measured (seeds 1-6): sigma 10-14 deg, coverage 100 %, horizontal RMS 1.04-1.29 m against the
// raw fixes' 1.61-1.79 m (ratio 0.63-0.72).
TEST(GnssInsRobot, ConsumerGradeImuIsAlignedByTheHeadingBank) {
  for (unsigned seed = 1; seed <= 6; ++seed) {
    const Outcome o = drive(Robot(), robotConfig(consumerImu()), seed);
    if (!o.stats.t_init_ns) {
      ADD_FAILURE() << "consumer seed " << seed << ": not initialised";
      continue;
    }
    std::printf(
        "consumer seed %u: %s, heading at %.1f s (%.1f deg), coverage %.3f, rmse_h %.2f m "
        "(raw %.2f)\n",
        seed, o.stats.init_method.c_str(), (*o.stats.t_heading_ns - kT0Ns) * 1e-9,
        o.stats.init_heading_sigma_deg, o.coverage, o.rmse_h, o.raw_rmse_h);
    EXPECT_EQ(o.stats.init_method, "heading bank");
    EXPECT_GE(o.coverage, 0.95);
    EXPECT_LT(o.rmse_h, 0.85 * o.raw_rmse_h);
    // The mount is reported, not asserted: 80-116 deg on seeds 2-6, not yet estimated on seed 1
    // (its body-frame velocity directions too scattered at 1 m/s for the 90 % concentration).
    if (o.stats.mount) std::printf("  mount yaw %.1f deg\n", o.stats.mount->rpy_rad.z() / kDeg);
  }
  // Without the bank the same drive never gets a heading; no fix is dropped for it, all are
  // reported as before initialisation.
  InsConfig no_bank = robotConfig(consumerImu());
  no_bank.align.hypotheses = 0;
  const Outcome o = drive(Robot(), no_bank, 1);
  EXPECT_FALSE(o.stats.t_init_ns.has_value());
  EXPECT_GE(o.stats.fixes_before_init, 700);
}

// An IMU that reports its own attitude (an AHRS, sensor_msgs/Imu orientation with its covariance)
// gives the heading at the first fix after the initial window, well before the track or the
// heading bank could (48-86 s above); one whose stated yaw sigma is above
// fusion.ins.align_imu_orientation_max_sigma_deg is not used.
TEST(GnssInsRobot, AnImuReportingItsAttitudeGivesTheHeadingAtOnce) {
  for (unsigned seed = 1; seed <= 3; ++seed) {
    const Outcome o = drive(Robot(), robotConfig(), seed, 3.0);
    ASSERT_TRUE(o.stats.t_heading_ns) << "seed " << seed;
    const double t_heading_s = static_cast<double>(*o.stats.t_heading_ns - kT0Ns) * 1e-9;
    std::printf("ahrs seed %u: %s, heading at %.1f s, coverage %.3f, rmse_h %.2f m (raw %.2f)\n",
                seed, o.stats.init_method.c_str(), t_heading_s, o.coverage, o.rmse_h, o.raw_rmse_h);
    EXPECT_EQ(o.stats.init_method, "imu orientation");
    EXPECT_LT(t_heading_s, 15.0);
    EXPECT_GE(o.coverage, 0.95);
    EXPECT_LT(o.rmse_h, 0.8 * o.raw_rmse_h);
  }
  const Outcome vague = drive(Robot(), robotConfig(), 1, 30.0);
  EXPECT_NE(vague.stats.init_method, "imu orientation");
}

// The same robot with its mount configured as zero and not estimated: the constraint then holds
// a robot that moves along its body y axis to its body x axis. The filter either fights it (a
// large mean innovation) or turns its heading to satisfy it (a small one, and the position pays):
// the mount is estimated by default for that reason.
TEST(GnssInsRobot, AWrongConfiguredMountCostsWhatTheEstimateSaves) {
  for (unsigned seed = 1; seed <= 3; ++seed) {
    InsConfig wrong = robotConfig();
    wrong.estimate_mount = false;
    const Outcome w = drive(Robot(), wrong, seed);
    const Outcome e = drive(Robot(), robotConfig(), seed);
    const Eigen::Vector2d mean =
        w.stats.nhc_innovation_sum_mps / std::max(1, w.stats.nhc_used + w.stats.nhc_rejected);
    std::printf(
        "seed %u: mount configured 0: rmse_h %.2f m (mean lateral innovation %.3f m/s), "
        "estimated: %.2f m\n",
        seed, w.rmse_h, mean.x(), e.rmse_h);
    EXPECT_TRUE(std::abs(mean.x()) > 0.15 || w.rmse_h > 1.2 * e.rmse_h) << "seed " << seed;
  }
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
