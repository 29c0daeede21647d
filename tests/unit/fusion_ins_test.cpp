// GNSS/INS error-state filter (fusion/gnss_ins.hpp, fusion/ins_error_model.hpp): the analytic
// transition and measurement Jacobians against central differences, and regressions on a
// simulated curved drive (known IMU and GNSS noise, receiver latency, lever arm): accuracy well
// below the fix noise, time offset recovered, an outlier rejected, an outage coasted and reported,
// a static start, and re-convergence after a run of rejections.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <random>

#include "fusion/gnss_ins.hpp"
#include "odometry/error.hpp"
#include "odometry/lie.hpp"
#include "support/ins_drive.hpp"
#include "support/numeric_jacobian.hpp"

namespace gvio::fusion {
namespace {

InsState sampleState() {
  InsState x;
  x.p_enu = {12.0, -4.0, 1.5};
  x.v_enu_mps = {8.0, 5.0, -0.3};
  x.R_enu_b = odometry::expSo3(Eigen::Vector3d(0.05, -0.08, 1.1));
  x.ba_b_mps2 = {0.05, -0.03, 0.1};
  x.bg_b_radps = {0.002, -0.001, 0.003};
  x.time_offset_s = -0.07;
  return x;
}

const Eigen::Vector3d kAcc(0.8, 0.6, 9.7), kGyr(0.02, -0.03, 0.25), kLever(-0.3, 0.4, 1.0);

TEST(InsErrorModel, TransitionMatchesNumericDerivative) {
  const InsState x = sampleState();
  for (double dt : {0.01, 0.2}) {
    const InsState x1 = propagateNominal(x, kAcc, kGyr, dt);
    const InsMatrix numeric = test::numericJacobian<kInsDim, kInsDim>([&](const InsVector& dx) {
      return errorBetween(propagateNominal(injectError(x, dx), kAcc, kGyr, dt), x1);
    });
    EXPECT_LT((numeric - transitionMatrix(x, kAcc, kGyr, dt)).cwiseAbs().maxCoeff(), 1e-6)
        << "dt " << dt;
  }
}

TEST(InsErrorModel, PositionJacobianMatchesNumericDerivative) {
  const InsState x = sampleState();
  const double stamp_minus_filter = 0.004;
  const auto h = [&](const InsState& s) {
    return antennaPosition(s, kGyr, kLever, stamp_minus_filter).h;
  };
  const Eigen::Matrix<double, 3, kInsDim> numeric = test::numericJacobian<3, kInsDim>(
      [&](const InsVector& dx) -> Eigen::Vector3d { return h(injectError(x, dx)) - h(x); });
  const Eigen::Matrix<double, 3, kInsDim> H =
      antennaPosition(x, kGyr, kLever, stamp_minus_filter).H;
  EXPECT_LT((numeric - H).cwiseAbs().maxCoeff(), 1e-7) << "numeric\n" << numeric << "\nH\n" << H;
}

TEST(InsErrorModel, VelocityJacobianMatchesNumericDerivative) {
  const InsState x = sampleState();
  const auto h = [&](const InsState& s) {
    return antennaVelocityEn(s, kAcc, kGyr, kLever, 0.006).h;
  };
  const Eigen::Matrix<double, 2, kInsDim> numeric = test::numericJacobian<2, kInsDim>(
      [&](const InsVector& dx) -> Eigen::Vector2d { return h(injectError(x, dx)) - h(x); });
  const Eigen::Matrix<double, 2, kInsDim> H = antennaVelocityEn(x, kAcc, kGyr, kLever, 0.006).H;
  EXPECT_LT((numeric - H).cwiseAbs().maxCoeff(), 1e-7) << "numeric\n" << numeric << "\nH\n" << H;
}

TEST(InsErrorModel, NonHolonomicJacobianMatchesNumericDerivative) {
  const InsState x = sampleState();
  const Eigen::Matrix3d R_v_b = odometry::expSo3(Eigen::Vector3d(0.02, -0.04, 0.01));
  const auto h = [&](const InsState& s) { return vehicleLateralVerticalVelocity(s, R_v_b).h; };
  const Eigen::Matrix<double, 2, kInsDim> numeric = test::numericJacobian<2, kInsDim>(
      [&](const InsVector& dx) -> Eigen::Vector2d { return h(injectError(x, dx)) - h(x); });
  const Eigen::Matrix<double, 2, kInsDim> H = vehicleLateralVerticalVelocity(x, R_v_b).H;
  EXPECT_LT((numeric - H).cwiseAbs().maxCoeff(), 1e-7) << "numeric\n" << numeric << "\nH\n" << H;
  // A vehicle moving along its own forward axis satisfies the constraint exactly.
  InsState along = x;
  along.v_enu_mps = x.R_enu_b * R_v_b.transpose() * Eigen::Vector3d(12.0, 0.0, 0.0);
  EXPECT_LT(h(along).norm(), 1e-12);
}

TEST(InsErrorModel, InjectAndDifferenceAreInverse) {
  const InsState x = sampleState();
  InsVector dx;
  for (int i = 0; i < kInsDim; ++i) dx(i) = 0.01 * (i + 1) * (i % 2 ? -1.0 : 1.0);
  EXPECT_LT((errorBetween(injectError(x, dx), x) - dx).norm(), 1e-12);
}

// A car on a level road with a tilted IMU mount: heading and speed vary smoothly (a curved drive),
// so position, velocity, attitude, specific force and body rates are analytic up to the position,
// which is integrated on a 1 ms grid.
struct SimDrive {
  double static_s = 0.0;  // standing still before driving off
  double duration_s = 60.0;
  double tau_s = -0.08;  // fixes report the antenna position this much after their stamp
  Eigen::Vector3d lever_b{-0.3, 0.4, 1.0};
  // IMU mount: roll 0.03 rad, pitch -0.05 rad in the vehicle (R_v_b = Ry(pitch) Rx(roll)).
  Eigen::Vector3d mount_rpy_rad{0.03, -0.05, 0.0};
  Eigen::Matrix3d R_vehicle_b = (Eigen::AngleAxisd(mount_rpy_rad.y(), Eigen::Vector3d::UnitY()) *
                                 Eigen::AngleAxisd(mount_rpy_rad.x(), Eigen::Vector3d::UnitX()))
                                    .toRotationMatrix();

  double speed(double t) const {
    if (t < static_s) return 0.0;
    const double u = t - static_s;
    return u < 5.0 ? 2.4 * u : 12.0 + 3.0 * std::sin(2.0 * M_PI * (u - 5.0) / 15.0);
  }
  double speedRate(double t) const {
    if (t < static_s) return 0.0;
    const double u = t - static_s;
    return u < 5.0 ? 2.4 : 3.0 * 2.0 * M_PI / 15.0 * std::cos(2.0 * M_PI * (u - 5.0) / 15.0);
  }
  double yaw(double t) const { return 0.4 + 0.6 * std::sin(2.0 * M_PI * t / 25.0); }
  double yawRate(double t) const {
    return 0.6 * 2.0 * M_PI / 25.0 * std::cos(2.0 * M_PI * t / 25.0);
  }
  Eigen::Matrix3d R_enu_b(double t) const {
    return Eigen::AngleAxisd(yaw(t), Eigen::Vector3d::UnitZ()).toRotationMatrix() * R_vehicle_b;
  }
  Eigen::Vector3d velocity(double t) const {
    return speed(t) * Eigen::Vector3d(std::cos(yaw(t)), std::sin(yaw(t)), 0.0);
  }

  // Body positions on a 1 ms grid.
  std::vector<Eigen::Vector3d> positions() const {
    return test::positionsOnMsGrid(duration_s, [this](double t) { return velocity(t); });
  }
};

using test::positionAt;

struct SimOutcome {
  double rmse_h = 0.0, rmse_3d = 0.0, raw_rmse_h = 0.0, max_err_in_outage = 0.0;
  double final_err = 0.0;
  InsStats stats;
  InsState state;
};

struct SimSpec {
  SimDrive drive;
  double outlier_at_s = -1.0;  // one fix 30 m off
  double outage_t0 = -1.0, outage_t1 = -1.0;
  double jump_from_s = -1.0;  // every later fix 15 m east (a receiver jump)
};

constexpr std::int64_t kT0Ns = 1'000'000'000'000;

SimOutcome simulate(const SimSpec& spec, const InsConfig& config) {
  const SimDrive& d = spec.drive;
  const std::vector<Eigen::Vector3d> grid = d.positions();
  std::mt19937 rng(7);
  std::normal_distribution<double> n01(0.0, 1.0);
  // Braces, not parentheses, around every draw: a braced list is evaluated left to right, a call's
  // arguments in the compiler's order, and the same seed must give the same drive with gcc and
  // clang.
  const auto noise3 = [&](double sigma) -> Eigen::Vector3d {
    return Eigen::Vector3d{n01(rng), n01(rng), n01(rng)} * sigma;
  };
  const Lla origin{37.72, -122.47, 30.0};
  const EnuFrame enu(origin);
  GnssIns ins(config, enu);
  const Eigen::Vector3d ba(0.05, -0.04, 0.08), bg(0.0015, -0.001, 0.002);
  const double acc_sigma = config.imu.acc_noise_density / std::sqrt(0.01);
  const double gyr_sigma = config.imu.gyr_noise_density / std::sqrt(0.01);
  const double sigma_h = 1.0, sigma_v = 2.0;
  SimOutcome out;
  double sse_h = 0.0, sse_3d = 0.0, raw_h = 0.0;
  int n = 0, n_raw = 0;
  int next_fix = 1;
  for (int i = 0; i * 0.01 <= d.duration_s - 0.2; ++i) {
    const double t = i * 0.01;
    const auto t_ns = kT0Ns + static_cast<std::int64_t>(i) * 10'000'000;
    // Fixes every 0.1 s, stamped on arrival; given before the first IMU sample after their stamp.
    while (next_fix * 0.1 + 0.003 <= t) {
      const double ts = next_fix * 0.1 + 0.003;
      const double te = ts + d.tau_s;  // the epoch the fix describes
      ++next_fix;
      if (ts > spec.outage_t0 && ts < spec.outage_t1) continue;
      const Eigen::Matrix3d R = d.R_enu_b(te);
      Eigen::Vector3d p_ant =
          positionAt(grid, te) + R * d.lever_b +
          Eigen::Vector3d{n01(rng) * sigma_h, n01(rng) * sigma_h, n01(rng) * sigma_v};
      if (spec.outlier_at_s > 0 && std::abs(ts - spec.outlier_at_s) < 0.05) p_ant.x() += 30.0;
      if (spec.jump_from_s > 0 && ts >= spec.jump_from_s) p_ant.x() += 15.0;
      const Eigen::Vector3d w_b = d.R_vehicle_b.transpose() * Eigen::Vector3d(0, 0, d.yawRate(te));
      const Eigen::Vector3d v_ant = d.velocity(te) + R * w_b.cross(d.lever_b) +
                                    Eigen::Vector3d{n01(rng), n01(rng), 0.0} * 0.05;
      GnssFix fix = test::fixAt(enu, kT0Ns + static_cast<std::int64_t>(std::llround(ts * 1e9)),
                                p_ant, sigma_h, sigma_v);
      fix.speed_mps = v_ant.head<2>().norm();
      fix.course_deg = std::atan2(v_ant.x(), v_ant.y()) * 180.0 / M_PI;
      ins.addFix(fix);
      raw_h += (p_ant - positionAt(grid, ts)).head<2>().squaredNorm();
      ++n_raw;
    }
    const Eigen::Matrix3d R = d.R_enu_b(t);
    const Eigen::Vector3d a_enu =
        d.speedRate(t) * Eigen::Vector3d(std::cos(d.yaw(t)), std::sin(d.yaw(t)), 0.0) +
        d.speed(t) * d.yawRate(t) * Eigen::Vector3d(-std::sin(d.yaw(t)), std::cos(d.yaw(t)), 0.0);
    ImuSample s;
    s.t_ns = t_ns;
    s.acc_b_mps2 = R.transpose() * (a_enu - gravityEnu()) + ba + noise3(acc_sigma);
    s.gyr_b_radps =
        d.R_vehicle_b.transpose() * Eigen::Vector3d(0, 0, d.yawRate(t)) + bg + noise3(gyr_sigma);
    ins.addImu(s);
    if (!ins.initialized()) continue;
    const Eigen::Vector3d e = ins.state().p_enu - positionAt(grid, t);
    sse_h += e.head<2>().squaredNorm();
    sse_3d += e.squaredNorm();
    ++n;
    if (t > spec.outage_t0 && t < spec.outage_t1) {
      out.max_err_in_outage = std::max(out.max_err_in_outage, e.norm());
    }
    out.final_err = e.head<2>().norm();
  }
  ins.finish();
  out.rmse_h = std::sqrt(sse_h / n);
  out.rmse_3d = std::sqrt(sse_3d / n);
  out.raw_rmse_h = std::sqrt(raw_h / n_raw);
  out.stats = ins.stats();
  out.state = ins.state();
  return out;
}

InsConfig simConfig() {
  InsConfig c;
  c.lever_arm_b = SimDrive().lever_b;
  c.velocity_sigma_mps = 0.1;
  c.mount_rpy_deg = SimDrive().mount_rpy_rad * 180.0 / M_PI;
  return c;
}

TEST(GnssIns, CurvedDriveBeatsTheFixesAndFindsTheLatency) {
  const SimOutcome r = simulate({}, simConfig());
  // Raw fixes: 1 m per horizontal axis, plus 0.08 s of latency at ~12 m/s.
  EXPECT_GT(r.raw_rmse_h, 1.5);
  std::printf(
      "curved drive: fused %.2f m horizontal, %.2f m 3-D against raw %.2f m; latency %.3f s\n",
      r.rmse_h, r.rmse_3d, r.raw_rmse_h, r.state.time_offset_s);
  EXPECT_LT(r.rmse_h, 0.35) << "raw " << r.raw_rmse_h;
  EXPECT_LT(r.rmse_3d, 0.7);
  EXPECT_NEAR(r.state.time_offset_s, -0.08, 0.015);
  EXPECT_LE(r.stats.fixes_rejected, 3);  // the 99.9 % gate rejects ~0.1 % of good fixes
  EXPECT_TRUE(r.stats.outages.empty());
  EXPECT_GT(r.stats.velocity_used, 500);
}

TEST(GnssIns, WithoutLatencyEstimateTheErrorIsLarger) {
  InsConfig c = simConfig();
  c.estimate_time_offset = false;
  const SimOutcome fixed = simulate({}, c);
  const SimOutcome estimated = simulate({}, simConfig());
  std::printf("latency state off: %.2f m horizontal against %.2f m\n", fixed.rmse_h,
              estimated.rmse_h);
  EXPECT_GT(fixed.rmse_h, estimated.rmse_h + 0.5);
}

// Measured (the same with gcc and clang): 0.313 m 3-D with the constraint, 0.455 m without,
// 2.360 m with the IMU's tilt left out of the vehicle frame, 1.413 m with the mount left out and
// estimated (pitch 1.25 deg off the true -2.86 deg): the estimate from the filter's own attitude
// is worth a fraction of a measured mount.
TEST(GnssIns, NonHolonomicConstraintWithTheMountHelps) {
  InsConfig off = simConfig();
  off.use_nhc = false;
  InsConfig unmounted = simConfig();
  unmounted.mount_rpy_deg.setZero();  // the 2.9 deg pitch of the IMU left out
  unmounted.estimate_mount = false;
  InsConfig estimated = unmounted;
  estimated.estimate_mount = true;
  const SimOutcome with = simulate({}, simConfig());
  const SimOutcome without = simulate({}, off);
  const SimOutcome wrong = simulate({}, unmounted);
  const SimOutcome learned = simulate({}, estimated);
  std::printf(
      "3-D rmse: nhc %.3f m, no nhc %.3f m, nhc without the mount %.3f m, with it estimated %.3f "
      "m\n",
      with.rmse_3d, without.rmse_3d, wrong.rmse_3d, learned.rmse_3d);
  // The mean innovation shows the wrong vehicle frame (measured 0.003 vs 0.173 m/s vertical),
  // which gvio run turns into a warning above 0.05 m/s.
  const auto mean = [](const SimOutcome& o) -> Eigen::Vector2d {
    return o.stats.nhc_innovation_sum_mps / (o.stats.nhc_used + o.stats.nhc_rejected);
  };
  EXPECT_LT(mean(with).cwiseAbs().maxCoeff(), 0.05);
  EXPECT_GT(mean(wrong).cwiseAbs().maxCoeff(), 0.1);
  EXPECT_GT(with.stats.nhc_used, 500);
  EXPECT_EQ(without.stats.nhc_used, 0);
  EXPECT_LT(with.rmse_3d, without.rmse_3d);
  EXPECT_GT(wrong.rmse_3d, with.rmse_3d);
  EXPECT_LT(learned.rmse_3d, 0.75 * wrong.rmse_3d);
  EXPECT_FALSE(with.stats.mount.has_value());  // configured: used as it is
  ASSERT_TRUE(learned.stats.mount.has_value());
  std::printf("estimated mount pitch %.2f deg off the true %.2f deg\n",
              (learned.stats.mount->rpy_rad.y() - SimDrive().mount_rpy_rad.y()) * 180.0 / M_PI,
              SimDrive().mount_rpy_rad.y() * 180.0 / M_PI);
  EXPECT_NEAR(learned.stats.mount->rpy_rad.y(), SimDrive().mount_rpy_rad.y(), 0.03);
  EXPECT_NEAR(learned.stats.mount->rpy_rad.z(), 0.0, 0.03);
}

TEST(GnssIns, OutlierFixIsRejected) {
  SimSpec spec;
  spec.outlier_at_s = 30.0;
  const SimOutcome r = simulate(spec, simConfig());
  EXPECT_LE(r.stats.fixes_rejected, 4);
  int outliers = 0;
  for (const InsFixOutcome& f : r.stats.fixes) {
    const double ts = static_cast<double>(f.t_ns - kT0Ns) * 1e-9;
    if (std::abs(ts - 30.0) < 0.05) {
      EXPECT_EQ(f.status, InsFixStatus::kRejected);
      ++outliers;
    }
  }
  EXPECT_EQ(outliers, 1);
  EXPECT_LT(r.rmse_h, 0.45);
}

TEST(GnssIns, OutageIsCoastedAndReported) {
  SimSpec spec;
  spec.outage_t0 = 30.0;
  spec.outage_t1 = 40.0;
  const SimOutcome r = simulate(spec, simConfig());
  ASSERT_EQ(r.stats.outages.size(), 1U);
  const double t0 = static_cast<double>(r.stats.outages[0].first - kT0Ns) * 1e-9;
  const double t1 = static_cast<double>(r.stats.outages[0].second - kT0Ns) * 1e-9;
  EXPECT_NEAR(t0, 30.0, 0.11);
  EXPECT_NEAR(t1, 40.0, 0.11);
  // 10 s of IMU-only coasting on calibrated biases.
  std::printf("10 s outage: at most %.2f m off while coasting, %.2f m at the end\n",
              r.max_err_in_outage, r.final_err);
  EXPECT_LT(r.max_err_in_outage, 3.0);
  EXPECT_LT(r.final_err, 0.8);
}

TEST(GnssIns, StaticStartWaitsForMotion) {
  SimSpec spec;
  spec.drive.static_s = 5.0;
  const SimOutcome r = simulate(spec, simConfig());
  ASSERT_TRUE(r.stats.t_init_ns.has_value());
  const double t_init = static_cast<double>(*r.stats.t_init_ns - kT0Ns) * 1e-9;
  EXPECT_GT(t_init, 5.0);
  EXPECT_LT(t_init, 7.5);
  EXPECT_GT(r.stats.fixes_before_init, 40);
  EXPECT_LT(r.rmse_h, 0.6);
}

TEST(GnssIns, ReconvergesAfterBoundedRejections) {
  SimSpec spec;
  spec.jump_from_s = 40.0;
  InsConfig c = simConfig();
  c.max_consecutive_rejections = 5;
  const SimOutcome r = simulate(spec, c);
  EXPECT_GE(r.stats.fixes_rejected, 5);
  EXPECT_GE(r.stats.fixes_forced, 1);
  // After the jump the filter follows the fixes: it ends ~15 m east of the truth.
  EXPECT_NEAR(r.final_err, 15.0, 1.5);
}

TEST(GnssIns, ConfigValidationNamesTheKey) {
  const auto expectNamed = [](const InsConfig& c, const std::string& key) {
    try {
      c.validate();
      ADD_FAILURE() << "expected InvalidInput for " << key;
    } catch (const InvalidInput& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  };
  InsConfig c;
  c.velocity_sigma_mps = 0.0;
  expectNamed(c, "fusion.ins.velocity_sigma_mps");
  c = InsConfig{};
  c.nhc_sigma_mps = -0.1;
  expectNamed(c, "fusion.ins.nhc_sigma_mps");
  c = InsConfig{};
  c.mount_rpy_deg.y() = std::nan("");
  expectNamed(c, "fusion.ins.mount_rpy_deg");
  c.mount_rpy_deg = {0.0, 0.0, 270.0};
  expectNamed(c, "fusion.ins.mount_rpy_deg");
}

}  // namespace
}  // namespace gvio::fusion
