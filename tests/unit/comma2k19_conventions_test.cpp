// The comma2k19 reader's frame conventions on the real segment (../shared/data/comma2k19): the IMU
// turned into gvio's forward-left-up body must agree with the attitude changes and the velocity
// derivative of the segment's fused truth, with the same signs and on the same clock. A wrong
// sign or axis (the file is forward-right-down) makes a correlation negative or near zero; a
// clock offset moves its peak away from lag 0. docs/how-it-works/gnss-ins.md quotes the output.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "io/dataset.hpp"
#include "odometry/lie.hpp"
#include "support/fixtures.hpp"

namespace gvio::test {
namespace {

double correlation(const std::vector<double>& a, const std::vector<double>& b) {
  const auto n = static_cast<double>(a.size());
  double ma = 0, mb = 0;
  for (std::size_t i = 0; i < a.size(); ++i) ma += a[i] / n, mb += b[i] / n;
  double sab = 0, saa = 0, sbb = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    sab += (a[i] - ma) * (b[i] - mb);
    saa += (a[i] - ma) * (a[i] - ma);
    sbb += (b[i] - mb) * (b[i] - mb);
  }
  return sab / std::sqrt(saa * sbb);
}

struct Agreement {
  double pitch_rate = 0.0;     // gyro y against the truth's body rate about y
  double forward_force = 0.0;  // accelerometer x against the truth's specific force along x
};

// Correlations over the truth's intervals [t_k, t_k+1] (20 Hz): the IMU averaged over the interval
// moved by lag_ns against the truth's rate (Log of its relative rotation) and specific force
// (R^T (a + g), a from central differences of its positions).
Agreement agreementAtLag(const io::Dataset& ds, std::int64_t lag_ns) {
  constexpr std::size_t kSpan = 2;
  const Trajectory& truth = *ds.groundtruth;
  std::vector<double> gyr_y, rate_y, acc_x, force_x;
  std::size_t j = 0;
  for (std::size_t k = kSpan; k + 1 + kSpan < truth.size(); ++k) {
    const std::int64_t t0 = truth.t_ns[k] + lag_ns, t1 = truth.t_ns[k + 1] + lag_ns;
    while (j < ds.imu.size() && ds.imu[j].t_ns < t0) ++j;
    Eigen::Vector3d gyr = Eigen::Vector3d::Zero(), acc = Eigen::Vector3d::Zero();
    int count = 0;
    for (std::size_t i = j; i < ds.imu.size() && ds.imu[i].t_ns < t1; ++i, ++count) {
      gyr += ds.imu[i].gyr_b_radps;
      acc += ds.imu[i].acc_b_mps2;
    }
    if (count == 0) continue;
    const double dt = 1e-9 * static_cast<double>(truth.t_ns[k + 1] - truth.t_ns[k]);
    const Eigen::Matrix3d R0 = truth.poses[k].linear(), R1 = truth.poses[k + 1].linear();
    const Eigen::Vector3d rate_b = odometry::logSo3(R0.transpose() * R1) / dt;
    const auto p = [&](std::size_t i) { return truth.poses[i].translation(); };
    const auto t = [&](std::size_t i) { return 1e-9 * static_cast<double>(truth.t_ns[i]); };
    // Velocities at k and k + 1 over +-kSpan poses, their difference over the interval: a second
    // difference of positions, averaged so that the truth's centimetre noise does not swamp it.
    const Eigen::Vector3d v0 = (p(k + kSpan) - p(k - kSpan)) / (t(k + kSpan) - t(k - kSpan));
    const Eigen::Vector3d v1 =
        (p(k + 1 + kSpan) - p(k + 1 - kSpan)) / (t(k + 1 + kSpan) - t(k + 1 - kSpan));
    const Eigen::Vector3d a_enu = (v1 - v0) / dt;
    const Eigen::Vector3d force_b =
        (0.5 * (R0 + R1)).transpose() * (a_enu + Eigen::Vector3d(0.0, 0.0, 9.81));
    gyr_y.push_back(gyr.y() / count);
    rate_y.push_back(rate_b.y());
    acc_x.push_back(acc.x() / count);
    force_x.push_back(force_b.x());
  }
  return {correlation(gyr_y, rate_y), correlation(acc_x, force_x)};
}

TEST(Comma2k19Real, ImuAgreesWithTheTruthInSignAxisAndClock) {
  const std::filesystem::path data = sharedData("comma2k19");
  if (data.empty()) GTEST_SKIP() << "shared data absent: ../shared/data/comma2k19";
  const io::Dataset ds = io::readDataset(data, std::nullopt, io::ReaderConfig{});
  ASSERT_TRUE(ds.groundtruth);
  const Agreement at0 = agreementAtLag(ds, 0);
  std::printf("lag 0: pitch rate correlation %.3f, forward specific force %.3f\n", at0.pitch_rate,
              at0.forward_force);
  double best_lag_ms = 0.0, best = -1.0;
  for (int lag_ms = -100; lag_ms <= 100; lag_ms += 10) {
    const Agreement a = agreementAtLag(ds, lag_ms * 1'000'000LL);
    if (a.pitch_rate + a.forward_force > best) {
      best = a.pitch_rate + a.forward_force;
      best_lag_ms = lag_ms;
    }
  }
  std::printf("best agreement at lag %+.0f ms (10 ms steps over +-100 ms)\n", best_lag_ms);
  EXPECT_GT(at0.pitch_rate, 0.9);
  EXPECT_GT(at0.forward_force, 0.9);
  EXPECT_LE(std::abs(best_lag_ms), 20.0);
}

}  // namespace
}  // namespace gvio::test
