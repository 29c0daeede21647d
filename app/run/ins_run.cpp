#include "run/ins_run.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "io/atomic_write.hpp"
#include "io/dataset_summary.hpp"
#include "io/trajectory_io.hpp"
#include "odometry/error.hpp"
#include "run/coverage.hpp"
#include "run/gnss_run.hpp"
#include "run/report.hpp"
#include "run/stats.hpp"
#include "run/vio_runner.hpp"

namespace gvio::run {
namespace {

using nlohmann::json;

constexpr std::int64_t kAssociationNs = 10'000'000;  // evo's default t_max_diff

double seconds(std::int64_t t_ns) {
  return static_cast<double>(t_ns) * 1e-9;
}

bool sameOrigin(const fusion::Lla& a, const fusion::Lla& b) {
  return a.lat_deg == b.lat_deg && a.lon_deg == b.lon_deg && a.h_ellipsoid_m == b.h_ellipsoid_m;
}

// Linear interpolation of the truth's position at t (nullopt outside it).
std::optional<Eigen::Vector3d> positionAt(const Trajectory& truth, std::int64_t t_ns) {
  const auto it = std::lower_bound(truth.t_ns.begin(), truth.t_ns.end(), t_ns);
  if (it == truth.t_ns.end()) return std::nullopt;
  const auto k = static_cast<std::size_t>(it - truth.t_ns.begin());
  if (*it == t_ns) return truth.poses[k].translation();
  if (k == 0) return std::nullopt;
  const double s = static_cast<double>(t_ns - truth.t_ns[k - 1]) /
                   static_cast<double>(truth.t_ns[k] - truth.t_ns[k - 1]);
  return (1.0 - s) * truth.poses[k - 1].translation() + s * truth.poses[k].translation();
}

json statsJson(const eval::Stats& s) {
  return {{"rmse", s.rmse}, {"mean", s.mean}, {"median", s.median}, {"std", s.std}, {"min", s.min},
          {"max", s.max},   {"n", s.n}};
}

json optionalSeconds(const std::optional<std::int64_t>& t_ns) {
  return t_ns ? json(seconds(*t_ns)) : json(nullptr);
}

json optionalStats(const std::optional<eval::Stats>& s) {
  return s ? statsJson(*s) : json(nullptr);
}

}  // namespace

// Both frames are exact tangent frames: positions go through LLA, rotations through ECEF.
Trajectory reexpressEnu(const Trajectory& poses, const fusion::Lla& from, const fusion::Lla& to) {
  if (sameOrigin(from, to)) return poses;
  const fusion::EnuFrame a(from), b(to);
  const Eigen::Matrix3d R_b_a = b.R_enu_ecef() * a.R_enu_ecef().transpose();
  Trajectory out = poses;
  for (Eigen::Isometry3d& T : out.poses) {
    T.translation() = b.toEnu(a.toLla(T.translation()));
    T.linear() = R_b_a * T.linear();
  }
  return out;
}

namespace {

// The non-holonomic constraint's mean innovation (vehicle lateral, vertical), m/s; none unused.
std::optional<Eigen::Vector2d> nhcMeanInnovation(const fusion::InsStats& s) {
  const int n = s.nhc_used + s.nhc_rejected;
  if (n == 0) return std::nullopt;
  return Eigen::Vector2d(s.nhc_innovation_sum_mps / n);
}

// Above this mean innovation the vehicle frame is probably wrong. The filter partly bends its
// attitude to a wrong constraint, so a tilt shows as less than speed x tilt: a 2.9 deg pitch
// gave 0.17 m/s on a simulated 12 m/s drive and a forced 3 deg one 0.06 m/s on comma2k19 (0.02
// m/s without).
constexpr double kNhcBiasWarnMps = 0.05;

}  // namespace

bool wantsGnssIns(const io::Dataset& ds) {
  return ds.frames.empty() && !ds.imu.empty() && !ds.gnss.empty();
}

InsRunResult runGnssIns(const io::Dataset& ds, const fusion::InsConfig& config,
                        const std::optional<fusion::Lla>& origin) {
  const auto start = std::chrono::steady_clock::now();
  const fusion::ScreeningResult screened =
      fusion::screenFixes(ds.gnss, ds.imu.front().t_ns, ds.imu.back().t_ns);
  if (screened.fixes.empty()) {
    throw InvalidInput(ds.gnss_source + ": no usable GNSS fix during the IMU data (" +
                       screened.counts.summary() + ")");
  }
  InsRunResult r;
  r.config = config;
  r.screening = screened.counts;
  const GnssFix& first = screened.fixes.front();
  r.origin = origin ? *origin
             : ds.groundtruth_enu_origin
                 ? *ds.groundtruth_enu_origin
                 : fusion::Lla{first.lat_deg, first.lon_deg, first.h_ellipsoid_m};
  fusion::GnssIns ins(config, fusion::EnuFrame(r.origin));
  std::size_t f = 0, a = 0;
  for (const ImuSample& s : ds.imu) {
    while (f < screened.fixes.size() && screened.fixes[f].t_ns <= s.t_ns) {
      ins.addFix(screened.fixes[f++]);
    }
    ins.addImu(s);
    // The IMU's own attitudes (an AHRS's orientation in its messages), with their samples.
    while (a < ds.imu_attitude.size() && ds.imu_attitude[a].t_ns <= s.t_ns) {
      ins.addAttitude(ds.imu_attitude[a++]);
    }
  }
  ins.finish();
  r.stats = ins.stats();
  const std::optional<Eigen::Vector2d> nhc = nhcMeanInnovation(r.stats);
  if (nhc && nhc->cwiseAbs().maxCoeff() > kNhcBiasWarnMps) {
    spdlog::warn(
        "the non-holonomic constraint's mean innovation is {:.2f} m/s lateral, {:.2f} m/s "
        "vertical: the IMU may be turned in the vehicle; set fusion.ins.mount_rpy_deg, or "
        "fusion.ins.use_nhc false",
        nhc->x(), nhc->y());
  }
  r.final_state = ins.state();
  r.time_offset_sigma_s = std::sqrt(ins.covariance()(fusion::kInsTau, fusion::kInsTau));
  r.fused = ins.trajectory();
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

InsEvaluation evaluateGnssIns(const InsRunResult& run, const Trajectory& truth) {
  InsEvaluation e;
  const eval::Association a = eval::associateByTime(truth.t_ns, run.fused.t_ns, kAssociationNs, 0);
  if (a.ref.size() < 3) {
    e.error = fmt::format("only {} fused poses within 10 ms of a truth pose", a.ref.size());
  } else {
    std::vector<double> h, d3;
    for (std::size_t i = 0; i < a.ref.size(); ++i) {
      const Eigen::Vector3d d =
          run.fused.poses[a.est[i]].translation() - truth.poses[a.ref[i]].translation();
      h.push_back(d.head<2>().norm());
      d3.push_back(d.norm());
    }
    e.fused_h = eval::computeStats(h);
    e.fused_3d = eval::computeStats(d3);
  }
  std::vector<double> h, d3;
  for (const fusion::InsFixOutcome& fix : run.stats.fixes) {
    const std::optional<Eigen::Vector3d> p = positionAt(truth, fix.t_ns);
    if (!p) continue;
    h.push_back((fix.p_enu - *p).head<2>().norm());
    d3.push_back((fix.p_enu - *p).norm());
  }
  if (!h.empty()) {
    e.raw_h = eval::computeStats(h);
    e.raw_3d = eval::computeStats(d3);
  }
  return e;
}

void writeGnssInsOutputs(const std::filesystem::path& out, const InsRunResult& r) {
  GnssRunResult fixes;  // gnss_fixes.csv in the camera fusion's layout (gvio render reads it)
  for (const fusion::InsFixOutcome& f : r.stats.fixes) {
    const fusion::FixStatus status = f.status == fusion::InsFixStatus::kUsed
                                         ? fusion::FixStatus::kUsed
                                     : f.status == fusion::InsFixStatus::kRejected
                                         ? fusion::FixStatus::kRejected
                                         : fusion::FixStatus::kUnaligned;  // before initialisation
    fixes.stats.fixes.push_back({f.t_ns, f.p_enu, status});
  }
  writeGnssFixes(out / "gnss_fixes.csv", fixes);
  if (r.fused.empty()) return;
  io::writeTum(out / "trajectory.tum", r.fused);
  writeTrajectoryLla(out / "trajectory_lla.csv", r.fused, r.origin);
  json j = georefJson(r.origin);
  j["heights"] = "ellipsoidal (WGS84)";
  j["time_base"] =
      "dataset timestamps in seconds (the IMU clock; GNSS fixes are corrected by the estimated "
      "receiver time offset)";
  io::writeTextAtomic(out / "georef.json", j.dump(2) + "\n");
}

Coverage insCoverage(const io::Dataset& ds, const InsRunResult& r) {
  std::vector<std::int64_t> imu;
  imu.reserve(ds.imu.size());
  for (const auto& sample : ds.imu) imu.push_back(sample.t_ns);
  return coverageOf(imu, r.fused.t_ns);
}

json gnssInsReport(const io::Dataset& ds, const InsRunResult& r, const InsReportContext& ctx) {
  const fusion::InsStats& s = r.stats;
  const std::optional<Eigen::Vector2d> nhc = nhcMeanInnovation(s);
  json report;
  report["gvio_version"] = GVIO_VERSION;
  // A run in progress or cut short says so (run/run_status.hpp); one that started late, "partial".
  const Coverage coverage = insCoverage(ds, r);
  report["status"] = runStatus(coverage);
  report["coverage"] = coverageJson(coverage);
  report["command_line"] = ctx.command_line;
  report["dataset"] = datasetJson(ds);
  report["mode"] = "gnss-ins";
  report["imu_noise_source"] = ctx.imu_noise_source;
  report["imu_noise"] = io::imuNoiseJson(ctx.imu_noise);
  report["counts"] = {{"imu_samples", s.imu_samples},
                      {"imu_before_init", s.imu_before_init},
                      {"imu_gaps", s.imu_gaps},
                      {"poses_written", r.fused.size()}};
  const TimingSummary cost = summarizeTimings(s.ms_per_fix);
  report["timing_ms"] = {
      {"per_fix", {{"mean", cost.mean}, {"p95", cost.p95}, {"max", cost.max}}},
      {"per_imu_sample", s.imu_samples > 0 ? 1e3 * r.wall_s / s.imu_samples : 0.0}};
  report["wall_s"] = r.wall_s;
  report["peak_rss_mb"] = ctx.peak_rss_mb;
  const fusion::InsState& x = r.final_state;
  report["gnss"] = {
      {"requested", ctx.gnss_requested},
      {"mode", "ins"},
      {"fixes", ds.gnss.size()},
      {"used", s.fixes_used},
      {"rejected", s.fixes_rejected},
      {"forced_after_rejections", s.fixes_forced},
      {"before_init", s.fixes_before_init},
      {"skipped", r.screening.skipped()},
      {"velocity_used", s.velocity_used},
      {"velocity_rejected", s.velocity_rejected},
      {"nhc_used", s.nhc_used},
      {"nhc_rejected", s.nhc_rejected},
      {"nhc_mean_innovation_mps", nhc ? json{nhc->x(), nhc->y()} : json(nullptr)},
      {"registered", s.t_init_ns.has_value()},
      {"t_init", optionalSeconds(s.t_init_ns)},
      {"ms_per_fix", {{"mean", cost.mean}, {"p95", cost.p95}, {"max", cost.max}}},
      {"lever_arm_b",
       {r.config.lever_arm_b.x(), r.config.lever_arm_b.y(), r.config.lever_arm_b.z()}},
      {"time_offset_s",
       {{"initial", r.config.receiver_time_offset_s},
        {"estimated", r.config.estimate_time_offset},
        {"final", x.time_offset_s},
        {"final_sigma", r.time_offset_sigma_s}}},
      {"final_acc_bias_b_mps2", {x.ba_b_mps2.x(), x.ba_b_mps2.y(), x.ba_b_mps2.z()}},
      {"final_gyr_bias_b_radps", {x.bg_b_radps.x(), x.bg_b_radps.y(), x.bg_b_radps.z()}},
      {"enu_origin",
       {{"lat_deg", r.origin.lat_deg},
        {"lon_deg", r.origin.lon_deg},
        {"h_ellipsoid_m", r.origin.h_ellipsoid_m}}}};
  if (!ctx.gnss_noise.is_null()) report["gnss"]["noise_added"] = ctx.gnss_noise;
  report["gnss"]["initialisation"] = {
      {"method", s.init_method.empty() ? json(nullptr) : json(s.init_method)},
      {"t_start", optionalSeconds(s.t_init_ns)},
      {"t_heading_known", optionalSeconds(s.t_heading_ns)},
      {"heading_sigma_deg", s.t_init_ns ? json(s.init_heading_sigma_deg) : json(nullptr)},
      {"gyro_bias_from_rest", s.init_quiet_start},
      {"alignment_restarts", s.alignment_restarts}};
  if (s.init_method == "track") {  // the heading bank leaves the mount to the direction of travel
    report["gnss"]["initialisation"]["mount_yaw_from_turns_deg"] = s.align_mount_yaw_deg;
    report["gnss"]["initialisation"]["mount_yaw_from_turns_sigma_deg"] =
        s.align_mount_yaw_sigma_deg;
  }
  const Eigen::Vector3d& cfg = r.config.mount_rpy_deg;
  json mount = {{"configured_rpy_deg", {cfg.x(), cfg.y(), cfg.z()}}};
  if (s.mount) {
    const Eigen::Vector3d rpy = s.mount->rpy_rad * 180.0 / M_PI;
    mount["source"] = "estimated";
    mount["rpy_deg"] = {rpy.x(), rpy.y(), rpy.z()};
    mount["epochs"] = s.mount->samples;
    mount["concentration"] = s.mount->concentration;
  } else {
    mount["source"] = r.config.estimatesMount() ? "not yet estimated" : "config";
    mount["rpy_deg"] = {cfg.x(), cfg.y(), cfg.z()};
  }
  report["gnss"]["mount"] = std::move(mount);
  json outages = json::array();
  for (const auto& [t0, t1] : s.outages) {
    outages.push_back({{"t0", seconds(t0)}, {"t1", seconds(t1)}, {"duration_s", seconds(t1 - t0)}});
  }
  report["outages"] = std::move(outages);
  if (ctx.evaluation) {
    const InsEvaluation& e = *ctx.evaluation;
    report["evaluation_fused"] = {
        {"ape_none", optionalStats(e.fused_3d)},
        {"ape_none_horizontal", optionalStats(e.fused_h)},
        {"note", "body positions vs the truth at its stamps, no alignment, the run's ENU frame"}};
    if (!e.error.empty()) report["evaluation_fused"]["error"] = e.error;
    report["evaluation_gnss_raw"] = {
        {"ape_none", optionalStats(e.raw_3d)},
        {"ape_none_horizontal", optionalStats(e.raw_h)},
        {"note",
         "every fix vs the truth body position at the fix's own stamp, as a stand-alone solution"}};
  }
  return report;
}

}  // namespace gvio::run
