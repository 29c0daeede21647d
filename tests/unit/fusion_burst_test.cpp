// Real receivers fail in runs, not one fix at a time (issue 58): a receiver that locks onto a
// reflection gives a block of consecutive fixes metres off in one direction, and a slow multipath
// bias holds them off for tens of seconds. The online gate takes such a run back in after
// max_consecutive_rejections (it cannot tell a burst from its own divergence); the smoother and
// the paper's KF (screened) must find it against the VIO. Drive: test::makeGnssDrive (300 s,
// 1 Hz fixes, 1.5 m / 3 m white noise, a 1 m Gauss-Markov bias, 2 % isolated outliers).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>

#include "fusion/gnss_fusion.hpp"
#include "support/gnss_drive.hpp"
#include "support/ins_drive.hpp"

namespace gvio::fusion {
namespace {

constexpr std::int64_t kS = 1'000'000'000;

// The drive with every fix in [t0_s, t1_s) moved by offset_enu(t_s) (the receiver's run of bad
// fixes); no offset given: the clean drive.
test::GnssDrive withRun(double t0_s, double t1_s,
                        const std::function<Eigen::Vector3d(double)>& offset_enu = {}) {
  test::GnssDrive d = test::makeGnssDrive(-1, -1, 1.0, 60.0);
  if (!offset_enu) return d;
  for (GnssFix& fix : d.fixes) {
    const double t_s = static_cast<double>(fix.t_ns) / kS;
    if (t_s < t0_s || t_s >= t1_s) continue;
    const Eigen::Vector3d p = d.enu.toEnu({fix.lat_deg, fix.lon_deg, fix.h_ellipsoid_m});
    fix = test::fixAt(d.enu, fix.t_ns, p + offset_enu(t_s), fix.sigma_h_m, fix.sigma_v_m);
  }
  return d;
}

struct Errors {
  double all_m = 0.0;  // horizontal RMS over the drive
  double run_m = 0.0;  // horizontal RMS over the bad run
};

Errors horizontalErrors(const test::GnssDrive& d, const Trajectory& est, double t0_s, double t1_s) {
  double all = 0.0, run = 0.0;
  int n_all = 0, n_run = 0;
  for (std::size_t k = 0; k < d.truth.size() && k < est.size(); ++k) {
    const Eigen::Vector3d e = est.poses[k].translation() - d.truth.poses[k].translation();
    const double e2 = e.head<2>().squaredNorm();
    all += e2;
    ++n_all;
    const double t_s = static_cast<double>(d.truth.t_ns[k]) / kS;
    if (t_s >= t0_s && t_s < t1_s) {
      run += e2;
      ++n_run;
    }
  }
  return {std::sqrt(all / std::max(n_all, 1)), std::sqrt(run / std::max(n_run, 1))};
}

struct Outputs {
  Errors smoothed, online, kf;
  FusionStats graph_stats;
};

Outputs fuseBoth(const test::GnssDrive& d, double t0_s, double t1_s) {
  FusionConfig graph;
  graph.lever_arm_b = d.lever;
  graph.smoother.bias_ratio = 1.0 / 1.5;
  GnssFusion g(graph, d.enu);
  test::replay(g, d);
  FusionConfig kf = graph;
  kf.mode = FusionMode::kKf;
  GnssFusion f(kf, d.enu);
  test::replay(f, d);
  return {horizontalErrors(d, g.smoothedTrajectory(), t0_s, t1_s),
          horizontalErrors(d, g.fusedTrajectory(), t0_s, t1_s),
          horizontalErrors(d, f.fusedTrajectory(), t0_s, t1_s), g.stats()};
}

void print(const char* what, const Outputs& o) {
  std::printf(
      "%s: smoothed %.2f m (%.2f over the run, %d fixes left out), online %.2f (%.2f), KF %.2f "
      "(%.2f)\n",
      what, o.smoothed.all_m, o.smoothed.run_m, o.graph_stats.smoother_outliers, o.online.all_m,
      o.online.run_m, o.kf.all_m, o.kf.run_m);
}

// 15 consecutive fixes 12 m east: three times the online gate's patience. Every one of them is
// kept out of the result: the gate takes two in (after max_consecutive_rejections, 5) and the
// smoother leaves those out against the VIO. Measured: smoothed 1.02 m over the run (0.98 m with
// clean fixes), online 2.12 m (1.71 m). The paper's KF, gated the same way, follows the block
// once the gate has let one in (10.6 m over the run, 3.66 m over the drive against 1.62 m): its
// fix-differenced velocity sees nothing wrong inside a block moved as a whole, and it cannot look
// ahead. That is the baseline's model, kept as the paper has it; not asserted.
TEST(GnssBursts, ABlockOfFixesOffInOneDirectionIsLeftOut) {
  const double t0 = 150.0, t1 = 165.0;
  const Outputs clean = fuseBoth(withRun(t0, t1), t0, t1);
  const Outputs burst =
      fuseBoth(withRun(t0, t1, [](double) { return Eigen::Vector3d(12.0, 0.0, 0.0); }), t0, t1);
  print("clean", clean);
  print("burst", burst);
  const auto kept_out = [](const Outputs& o) {
    return o.graph_stats.fixes_rejected + o.graph_stats.smoother_outliers;
  };
  EXPECT_GE(kept_out(burst), kept_out(clean) + 14);
  // The smoother stays where it is without the block; the online graph is pulled by the fixes
  // the gate lets in, by a fraction of the 12 m.
  EXPECT_LT(burst.smoothed.run_m, clean.smoothed.run_m + 0.3);
  EXPECT_LT(burst.smoothed.all_m, clean.smoothed.all_m + 0.1);
  EXPECT_LT(burst.online.run_m, 4.0);
}

// A slow multipath bias: 40 s of fixes drifting 0 -> 6 m north and back, as a facade's
// reflection does while the car passes it. Each fix is plausible against the one before it.
TEST(GnssBursts, ASlowMultipathBiasIsHeldToTheVio) {
  const double t0 = 100.0, t1 = 140.0;
  const auto bump = [&](double t_s) {
    return Eigen::Vector3d(0.0, 6.0 * std::sin(M_PI * (t_s - t0) / (t1 - t0)), 0.0);
  };
  const Outputs clean = fuseBoth(withRun(t0, t1), t0, t1);
  const Outputs biased = fuseBoth(withRun(t0, t1, bump), t0, t1);
  print("clean", clean);
  print("multipath", biased);
  // The bump alone is 4.2 m RMS over the 40 s (6 / sqrt(2)). Measured: smoothed 1.07 m over it
  // (0.41 m with clean fixes) and 1.22 m over the drive (0.98 m); online 3.45 m; KF 4.80 m.
  EXPECT_LT(biased.smoothed.run_m, 1.5);
  EXPECT_LT(biased.smoothed.all_m, clean.smoothed.all_m + 0.4);
}

}  // namespace
}  // namespace gvio::fusion
