#include "run/gnss_run.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <utility>

#include "io/atomic_write.hpp"
#include "io/trajectory_io.hpp"
#include "run/stats.hpp"

namespace gvio::run {
namespace {

double seconds(std::int64_t t_ns) {
  return static_cast<double>(t_ns) * 1e-9;
}

// trajectory_cov.csv: per pose the E/N/U position sigmas, the heading sigma, and the full 6x6
// covariance (upper triangle, row-major) in the order rotation about E, N, U (rad), position E,
// N, U (m).
void writeCovariance(const std::filesystem::path& file, const Trajectory& poses,
                     const std::vector<fusion::PoseCovariance>& cov) {
  io::writeFileAtomic(file, [&](std::ostream& os) {
    os << "# t_s,sigma_e_m,sigma_n_m,sigma_u_m,sigma_yaw_deg, then the 6x6 covariance of "
          "(rot_e, rot_n, rot_u [rad], e, n, u [m]), upper triangle row-major (21 values)\n";
    for (std::size_t k = 0; k < cov.size() && k < poses.size(); ++k) {
      const fusion::PoseCovariance& c = cov[k];
      os << fmt::format("{:.9f},{:.4f},{:.4f},{:.4f},{:.4f}", seconds(poses.t_ns[k]),
                        std::sqrt(c(3, 3)), std::sqrt(c(4, 4)), std::sqrt(c(5, 5)),
                        std::sqrt(c(2, 2)) * 180.0 / M_PI);
      for (int i = 0; i < 6; ++i) {
        for (int j = i; j < 6; ++j) os << fmt::format(",{:.6e}", c(i, j));
      }
      os << "\n";
    }
  });
}

// Mean / p95 / max of each smoothed pose's 3-D position sigma; null without covariances.
nlohmann::json positionSigma(const std::vector<fusion::PoseCovariance>& cov) {
  if (cov.empty()) return nullptr;
  std::vector<double> sigma;
  sigma.reserve(cov.size());
  for (const auto& c : cov) sigma.push_back(std::sqrt(c.bottomRightCorner<3, 3>().trace()));
  const TimingSummary s = summarizeTimings(std::move(sigma));  // any samples, not only ms
  return {{"mean", s.mean}, {"p95", s.p95}, {"max", s.max}};
}

}  // namespace

std::optional<GnssRunResult> fuseGnss(const io::Dataset& ds, const Trajectory& vio,
                                      fusion::FusionMode mode, fusion::FusionConfig config,
                                      const std::optional<fusion::Lla>& origin, bool has_imu) {
  if (ds.gnss.empty() || vio.empty()) return std::nullopt;
  const std::int64_t begin = ds.frames.empty() ? vio.t_ns.front() : ds.frames.front().t_ns;
  const std::int64_t end = ds.frames.empty() ? vio.t_ns.back() : ds.frames.back().t_ns;
  const fusion::ScreeningResult screened = fusion::screenFixes(ds.gnss, begin, end);
  if (screened.counts.skipped() > 0) {
    spdlog::warn("{}: {}", ds.gnss_source, screened.counts.summary());
  }
  if (screened.fixes.empty()) return std::nullopt;
  GnssRunResult r;
  r.mode = mode;
  r.screening = screened.counts;
  const GnssFix& first = screened.fixes.front();
  r.origin = origin ? *origin : fusion::Lla{first.lat_deg, first.lon_deg, first.h_ellipsoid_m};
  config.mode = mode;
  config.alignment =
      has_imu ? fusion::AlignmentDof::kYawTranslation : fusion::AlignmentDof::kRotationTranslation;
  fusion::GnssFusion fusion(config, fusion::EnuFrame(r.origin));
  std::size_t f = 0;
  for (std::size_t k = 0; k < vio.size(); ++k) {
    while (f < screened.fixes.size() && screened.fixes[f].t_ns <= vio.t_ns[k]) {
      fusion.addFix(screened.fixes[f++]);
    }
    fusion.addVioPose(vio.t_ns[k], vio.poses[k]);
  }
  while (f < screened.fixes.size()) fusion.addFix(screened.fixes[f++]);
  fusion.finish();
  r.stats = fusion.stats();
  r.fused = fusion.smoothedTrajectory();
  if (r.fused.empty()) {
    r.fused = fusion.fusedTrajectory();
  } else {
    r.fused_online = fusion.fusedTrajectory();
    r.fused_covariance = fusion.smoothedCovariance();
    r.smoothed = true;
  }
  r.T_enu_w = fusion.T_enu_w();
  if (!r.T_enu_w) {
    spdlog::warn(
        "GNSS: the VIO trajectory could not be registered to ENU (too few fixes, or they "
        "span less than {} m): no georeferenced output",
        config.alignment_min_extent_m);
  }
  return r;
}

void writeGnssFixes(const std::filesystem::path& file, const GnssRunResult& r) {
  io::writeFileAtomic(file, [&](std::ostream& os) {
    os << "t_s,e_m,n_m,u_m,status\n";
    for (const fusion::FixOutcome& f : r.stats.fixes) {
      os << fmt::format("{:.9f},{:.4f},{:.4f},{:.4f},{}\n", seconds(f.t_ns), f.p_enu.x(),
                        f.p_enu.y(), f.p_enu.z(), fusion::toString(f.status));
    }
  });
}

void writeTrajectoryLla(const std::filesystem::path& file, const Trajectory& T_enu_b,
                        const fusion::Lla& origin) {
  const fusion::EnuFrame enu(origin);
  io::writeFileAtomic(file, [&](std::ostream& os) {
    os << "# t_s,lat_deg,lon_deg,h_ellipsoid_m,qw,qx,qy,qz (body in local ENU)\n";
    for (std::size_t k = 0; k < T_enu_b.size(); ++k) {
      const fusion::Lla lla = enu.toLla(T_enu_b.poses[k].translation());
      const Eigen::Quaterniond q(T_enu_b.poses[k].rotation());
      os << fmt::format("{:.9f},{:.9f},{:.9f},{:.4f},{:.9f},{:.9f},{:.9f},{:.9f}\n",
                        seconds(T_enu_b.t_ns[k]), lla.lat_deg, lla.lon_deg, lla.h_ellipsoid_m,
                        q.w(), q.x(), q.y(), q.z());
    }
  });
}

nlohmann::json georefJson(const fusion::Lla& origin) {
  const fusion::Utm utm = fusion::llaToUtm(origin);
  nlohmann::json j;
  j["enu_origin"] = {{"lat_deg", origin.lat_deg},
                     {"lon_deg", origin.lon_deg},
                     {"h_ellipsoid_m", origin.h_ellipsoid_m},
                     {"crs", "EPSG:4979"}};
  j["utm"] = {{"zone", utm.zone},
              {"north", utm.north},
              {"epsg", utm.epsg()},
              {"origin_easting_m", utm.easting_m},
              {"origin_northing_m", utm.northing_m}};
  j["frames"] = {
      {"enu", "local east-north-up tangent at enu_origin (GeographicLib LocalCartesian), metres"},
      {"body", "the IMU frame; trajectory.tum and trajectory_lla.csv give the body pose in ENU"}};
  return j;
}

void writeGeoreferencedOutputs(const std::filesystem::path& out, const GnssRunResult& r) {
  writeGnssFixes(out / "gnss_fixes.csv", r);
  if (r.fused.empty()) return;
  io::writeTum(out / "trajectory.tum", r.fused);
  if (!r.fused_online.empty()) io::writeTum(out / "trajectory_online.tum", r.fused_online);
  if (!r.fused_covariance.empty()) {
    writeCovariance(out / "trajectory_cov.csv", r.fused, r.fused_covariance);
  }
  writeTrajectoryLla(out / "trajectory_lla.csv", r.fused, r.origin);
  nlohmann::json j = georefJson(r.origin);
  j["frames"]["vio_world"] = "trajectory_vio.tum's frame; T_enu_w maps it to ENU";
  if (r.T_enu_w) {
    const Eigen::Quaterniond q(r.T_enu_w->rotation());
    const Eigen::Vector3d t = r.T_enu_w->translation();
    j["T_enu_w"] = {{"translation_m", {t.x(), t.y(), t.z()}},
                    {"quaternion_wxyz", {q.w(), q.x(), q.y(), q.z()}}};
  }
  j["heights"] =
      "ellipsoidal (WGS84); NMEA MSL heights are converted with the receiver's geoid "
      "separation";
  j["time_base"] = "dataset timestamps in seconds (the same clock as trajectory_vio.tum)";
  io::writeTextAtomic(out / "georef.json", j.dump(2) + "\n");
}

// {"quality 1": {"horizontal": ..., "vertical": ...}, ...}: the smoother's learned factors.
nlohmann::json sigmaScaleJson(const std::map<int, Eigen::Vector2d>& scale) {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& [quality, s] : scale) {
    j[std::to_string(quality)] = {{"horizontal", s.x()}, {"vertical", s.y()}};
  }
  return j;
}

nlohmann::json gnssReport(const GnssRunResult& r, std::size_t fixes_in_dataset) {
  const TimingSummary cost = summarizeTimings(r.stats.ms_per_fix);
  return {{"mode", fusion::toString(r.mode)},
          {"fixes", fixes_in_dataset},
          {"used", r.stats.fixes_used},
          {"rejected", r.stats.fixes_rejected},
          {"unmatched", r.stats.fixes_unmatched},
          {"skipped", r.screening.skipped()},
          {"skipped_reasons",
           {{"non_finite", r.screening.non_finite},
            {"bad_sigma", r.screening.bad_sigma},
            {"out_of_range", r.screening.out_of_range},
            {"outside_drive", r.screening.outside_drive},
            {"out_of_order", r.screening.out_of_order}}},
          {"registered", r.T_enu_w.has_value()},
          {"smoothed", r.smoothed},
          {"ms_smoothing", r.stats.ms_smoothing},
          {"smoother_outliers", r.stats.smoother_outliers},
          {"smoother_sigma_scale", sigmaScaleJson(r.stats.smoother_sigma_scale)},
          {"kf_sigma_scale", sigmaScaleJson(r.stats.kf_sigma_scale)},
          {"position_sigma_m", positionSigma(r.fused_covariance)},
          {"poses_before_registration", r.stats.poses_before_alignment},
          {"ms_per_fix", {{"mean", cost.mean}, {"p95", cost.p95}, {"max", cost.max}}},
          {"enu_origin",
           {{"lat_deg", r.origin.lat_deg},
            {"lon_deg", r.origin.lon_deg},
            {"h_ellipsoid_m", r.origin.h_ellipsoid_m}}}};
}

nlohmann::json outagesReport(const GnssRunResult& r) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& [t0, t1] : r.stats.outages) {
    a.push_back({{"t0", seconds(t0)}, {"t1", seconds(t1)}, {"duration_s", seconds(t1 - t0)}});
  }
  return a;
}

}  // namespace gvio::run
