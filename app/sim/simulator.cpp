#include "sim/simulator.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <yaml-cpp/yaml.h>

#include <optional>

#include "io/atomic_write.hpp"
#include "io/gnss_file.hpp"
#include "io/image_loader.hpp"
#include "io/input_error.hpp"
#include "io/kitti_calib.hpp"
#include "io/mesh_ply.hpp"
#include "io/reference_csv.hpp"
#include "io/text.hpp"
#include "io/trajectory_io.hpp"
#include "sim/bag_output.hpp"
#include "sim/camera_sim.hpp"
#include "sim/dataset_writers.hpp"
#include "sim/gnss_replay.hpp"
#include "sim/imu_synth.hpp"
#include "sim/kitti_convention.hpp"
#include "sim/ros2_bag_output.hpp"
#include "sim/world.hpp"

namespace gvio::sim {
namespace fs = std::filesystem;
namespace {

// Relative stamps (KITTI odometry times from 0) start at KITTI 00's recording time.
constexpr std::int64_t kDefaultStartNs = 1317646534000000000LL;  // 2011-10-03 12:55:34 UTC
constexpr std::int64_t kAbsoluteAfterNs = 1'000'000'000LL * 1'000'000'000LL;  // 2001-09-09

// Everything the simulator writes, removed first with --force (nothing else is touched).
const char* const kOwnedPaths[] = {"image_00",
                                   "image_01",
                                   "oxts",
                                   "gnss",
                                   "world",
                                   "mav0",
                                   "calib_cam_to_cam.txt",
                                   "calib_imu_to_velo.txt",
                                   "calib_velo_to_cam.txt",
                                   "groundtruth.tum",
                                   "imu_truth.csv",
                                   "sim.yaml"};

void prepareOutput(const SimRequest& r) {
  if (fs::exists(r.out) && !fs::is_directory(r.out))
    throw io::InputError(r.out, 0, "exists and is not a folder");
  if (fs::is_directory(r.out) && !fs::is_empty(r.out)) {
    if (!r.force)
      throw io::InputError(r.out, 0, "output folder is not empty (use --force to overwrite)");
    for (const char* p : kOwnedPaths) fs::remove_all(r.out / p);
  }
  std::error_code ec;
  fs::create_directories(r.out, ec);
  if (ec) throw io::InputError(r.out, 0, "cannot create the output folder: " + ec.message());
}

// The simulator mounts its cameras on a vehicle body (x forward). A file whose body is mounted
// another way would silently point them sideways, so it is checked; motion replaces it.
Trajectory applyOrientationSource(const Trajectory& T_w_b, const SimRequest& r,
                                  const SimConfig& c) {
  MotionOrientationOptions motion;
  motion.fit = {c.knot_spacing_s, c.smoothing};  // the drive's own spline
  const FitOptions& fit = motion.fit;
  if (r.orientation == OrientationSource::kFile) {
    const auto warning = forwardAxisWarning(checkForwardAxis(T_w_b, fit), r.trajectory.string());
    if (warning) spdlog::warn("{}", *warning);
    return T_w_b;
  }
  try {
    return orientationFromMotion(T_w_b, motion);
  } catch (const InvalidInput& e) {
    throw InvalidInput(fmt::format("--trajectory {}: {}", r.trajectory.string(), e.what()));
  }
}

// The poses to drive, and the reference CSV they came from (georeferenced) if they did.
struct Drive {
  Trajectory poses;
  std::optional<io::ReferenceCsv> reference;
};

Drive loadDrive(const SimRequest& r, const SimConfig& c) {
  const bool reference = r.trajectory_format == "reference" ||
                         (r.trajectory_format == "auto" && io::looksLikeReferenceCsv(r.trajectory));
  Drive drive;
  io::TrajectoryFormat f = io::TrajectoryFormat::kTum;
  if (reference) {
    drive.reference = io::readReferenceCsv(r.trajectory);
    const fusion::EnuFrame enu(drive.reference->epochs.front().lla);
    if (r.orientation == OrientationSource::kFile && !drive.reference->has_attitude) {
      throw io::InputError(r.trajectory, 1,
                           "no roll, pitch and heading columns: use --orientation motion");
    }
    drive.poses = r.orientation == OrientationSource::kFile
                      ? io::referenceBodyPoses(*drive.reference, enu)
                      : io::referencePositions(*drive.reference, enu);
  } else {
    f = r.trajectory_format == "auto" ? io::detectTrajectoryFormat(r.trajectory)
                                      : *io::parseTrajectoryFormat(r.trajectory_format);
    if (f == io::TrajectoryFormat::kKitti && !r.times) {
      throw InvalidInput("--trajectory " + r.trajectory.string() +
                         " is KITTI: give its --times file");
    }
    drive.poses = io::readTrajectory(r.trajectory, f,
                                     f == io::TrajectoryFormat::kKitti ? r.times : std::nullopt);
  }
  Trajectory& poses = drive.poses;
  if (poses.size() < 4)
    throw io::InputError(r.trajectory, 0,
                         fmt::format("{} poses; at least 4 are needed", poses.size()));
  if (!reference && f == io::TrajectoryFormat::kKitti) {
    poses = kittiCameraToEnuBody(poses, c.heading_deg);
  }
  poses = applyOrientationSource(poses, r, c);
  if (poses.t_ns.front() < kAbsoluteAfterNs) {
    const std::int64_t shift = kDefaultStartNs - poses.t_ns.front();
    for (auto& t : poses.t_ns) t += shift;
  }
  return drive;
}

// The fixes of the drive: the request's error model, or a real receiver's errors replayed.
std::vector<GnssSimFix> driveGnss(const SimRequest& r, const Drive& drive,
                                  const ContinuousTrajectory& traj, std::int64_t t1,
                                  const fusion::EnuFrame& enu, const GnssSimOptions& options,
                                  SimSummary& summary) {
  const auto T_w_b_at = [&](std::int64_t t) { return traj.at(t).pose(); };
  if (!r.gnss_errors_from) {
    return synthesizeGnss(T_w_b_at, traj.t0_ns(), t1, enu, options, mixSeed(r.seed, 2));
  }
  const io::GnssFileData solution = io::readGnssFile(*r.gnss_errors_from, r.gnss_reader);
  for (const std::string& w : solution.warnings) spdlog::warn("{}", w);
  std::vector<std::int64_t> ref_t;
  std::vector<Eigen::Vector3d> ref_p;
  for (const io::ReferenceEpoch& e : drive.reference->epochs) {
    ref_t.push_back(e.t_ns);
    ref_p.push_back(enu.toEnu(e.lla));
  }
  const RealGnssErrors errors = realGnssErrors(solution.fixes, ref_t, ref_p, enu);
  summary.gnss_outside_reference = errors.outside_reference + errors.in_reference_gap;
  if (summary.gnss_outside_reference > 0) {
    spdlog::warn(
        "{}: {} of {} epochs lie outside the reference's span or in its gaps: not replayed",
        r.gnss_errors_from->string(), summary.gnss_outside_reference, solution.fixes.size());
  }
  return replayGnss(T_w_b_at, traj.t0_ns(), t1, enu, options, errors);
}

std::vector<Eigen::Vector3d> routeOf(const ContinuousTrajectory& traj, std::int64_t t1_ns,
                                     double& length_m) {
  std::vector<Eigen::Vector3d> route;
  length_m = 0.0;
  for (std::int64_t t = traj.t0_ns(); t <= t1_ns; t += 50'000'000) {  // 20 Hz is ~1 m at 70 km/h
    const Eigen::Vector3d p = traj.at(t).p_w;
    if (!route.empty()) length_m += (p - route.back()).norm();
    route.push_back(p);
  }
  return route;
}

std::vector<std::pair<std::int64_t, std::int64_t>> outagesNs(const SimRequest& r, std::int64_t t0,
                                                             std::int64_t t1) {
  std::vector<std::pair<std::int64_t, std::int64_t>> out;
  const double span_s = 1e-9 * static_cast<double>(t1 - t0);
  for (const auto& [a, b] : r.outages_s) {
    if (!(a >= 0.0 && b > a && b <= span_s)) {
      throw InvalidInput(fmt::format(
          "--gnss-outage {}:{} is outside the drive (0:{:.1f} s) or empty", a, b, span_s));
    }
    out.emplace_back(t0 + std::llround(a * 1e9), t0 + std::llround(b * 1e9));
  }
  return out;
}

io::TriangleMesh worldMesh(const render::Scene& scene) {
  io::TriangleMesh mesh;
  for (const auto& m : scene.meshes) {
    const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
    mesh.vertices.insert(mesh.vertices.end(), m.vertices.begin(), m.vertices.end());
    for (std::size_t i = 0; i + 2 < m.indices.size(); i += 3) {
      mesh.triangles.push_back(
          {base + m.indices[i], base + m.indices[i + 1], base + m.indices[i + 2]});
    }
  }
  return mesh;
}

// Every parameter of the run: the request, the effective configuration, and what came out.
void writeSimYaml(const fs::path& file, const SimRequest& r, const SimSummary& s) {
  YAML::Emitter y;
  y << YAML::BeginMap << YAML::Key << "generator" << YAML::Value << "gvio simulate";
  y << YAML::Key << "seed" << YAML::Value << r.seed;
  y << YAML::Key << "world_seed" << YAML::Value << r.world_seed.value_or(r.seed);
  y << YAML::Key << "trajectory" << YAML::Value << r.trajectory.filename().string();
  y << YAML::Key << "orientation" << YAML::Value << toString(r.orientation);
  y << YAML::Key << "format" << YAML::Value << io::toString(r.output);
  y << YAML::Key << "camera" << YAML::Value << (r.stereo ? "stereo" : "mono");
  y << YAML::Key << "gnss_noise" << YAML::Value
    << (r.gnss_errors_from ? std::string("replayed") : toString(r.gnss));
  if (r.gnss_errors_from) {
    y << YAML::Key << "gnss_errors_from" << YAML::Value << r.gnss_errors_from->filename().string();
  }
  y << YAML::Key << "gnss_outages_s" << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (const auto& [a, b] : r.outages_s)
    y << YAML::Flow << YAML::BeginSeq << a << b << YAML::EndSeq;
  y << YAML::EndSeq;
  // The IMU noise the drive has (KITTI's oxts cannot state it; EuRoC's imu0/sensor.yaml does too).
  const ImuNoise& n = s.imu_noise.noise;
  y << YAML::Key << "imu_noise" << YAML::Value << YAML::BeginMap;
  y << YAML::Key << "acc_noise_density" << YAML::Value << n.acc_noise_density;
  y << YAML::Key << "gyr_noise_density" << YAML::Value << n.gyr_noise_density;
  y << YAML::Key << "acc_random_walk" << YAML::Value << n.acc_random_walk;
  y << YAML::Key << "gyr_random_walk" << YAML::Value << n.gyr_random_walk;
  y << YAML::Key << "scale" << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (const double scale : s.imu_noise.scale) y << scale;
  y << YAML::EndSeq;
  const TurnOnBias& b = s.imu_turn_on_bias;
  y << YAML::Key << "turn_on_acc_bias_mps2" << YAML::Value << YAML::Flow << YAML::BeginSeq
    << b.acc_mps2.x() << b.acc_mps2.y() << b.acc_mps2.z() << YAML::EndSeq;
  y << YAML::Key << "turn_on_gyr_bias_radps" << YAML::Value << YAML::Flow << YAML::BeginSeq
    << b.gyr_radps.x() << b.gyr_radps.y() << b.gyr_radps.z() << YAML::EndSeq;
  y << YAML::EndMap;
  // The origin actually driven in (a reference CSV's own), so sim.yaml locates the drive.
  YAML::Node config = YAML::Load(r.config_yaml);
  if (config["sim"]) {
    config["sim"]["origin_lat_deg"] = s.origin.lat_deg;
    config["sim"]["origin_lon_deg"] = s.origin.lon_deg;
    config["sim"]["origin_h_m"] = s.origin.h_ellipsoid_m;
  }
  y << YAML::Key << "config" << YAML::Value << config;
  y << YAML::Key << "result" << YAML::Value << YAML::BeginMap;
  y << YAML::Key << "duration_s" << YAML::Value << s.duration_s;
  y << YAML::Key << "path_length_m" << YAML::Value << s.path_length_m;
  y << YAML::Key << "frames" << YAML::Value << s.frames;
  y << YAML::Key << "imu_samples" << YAML::Value << s.imu_samples;
  y << YAML::Key << "gnss_fixes" << YAML::Value << s.gnss_fixes;
  y << YAML::Key << "world_triangles" << YAML::Value << s.world_triangles;
  y << YAML::Key << "fit_position_rms_m" << YAML::Value << s.fit.position_rms_m;
  y << YAML::Key << "fit_position_max_m" << YAML::Value << s.fit.position_max_m;
  y << YAML::Key << "fit_rotation_rms_deg" << YAML::Value << s.fit.rotation_rms_deg;
  y << YAML::Key << "fit_rotation_max_deg" << YAML::Value << s.fit.rotation_max_deg;
  y << YAML::EndMap << YAML::EndMap;
  io::writeTextAtomic(file, std::string(y.c_str()) + "\n");
}

}  // namespace

SimSummary simulate(const SimRequest& r, const SimConfig& config, const ImuNoise& imu_noise,
                    const ProgressFn& progress) {
  config.validate();
  if (r.output != io::DatasetFormat::kKittiRaw && r.output != io::DatasetFormat::kEuroc &&
      r.output != io::DatasetFormat::kRosbag && r.output != io::DatasetFormat::kRos2Bag) {
    throw InvalidInput("--format: the simulator writes kitti-raw, euroc, rosbag or ros2bag");
  }
  if (r.seconds && !(*r.seconds > 0.0)) throw InvalidInput("--seconds must be positive");
  const Drive drive = loadDrive(r, config);
  if (r.gnss_errors_from && !drive.reference) {
    throw InvalidInput("--gnss-errors-from needs a georeferenced --trajectory (a reference CSV: " +
                       r.trajectory.string() + " is not one)");
  }
  const ContinuousTrajectory traj =
      ContinuousTrajectory::fit(drive.poses, {config.knot_spacing_s, config.smoothing});
  std::int64_t t1 = traj.t1_ns();
  if (r.seconds) t1 = std::min<std::int64_t>(t1, traj.t0_ns() + std::llround(*r.seconds * 1e9));
  const auto outages = outagesNs(r, traj.t0_ns(), t1);
  prepareOutput(r);

  SimSummary summary;
  summary.fit = traj.report();
  summary.duration_s = 1e-9 * static_cast<double>(t1 - traj.t0_ns());
  spdlog::info(
      "trajectory fit: position rms {:.3f} m (max {:.3f}), rotation rms {:.3f} deg (max {:.3f})",
      summary.fit.position_rms_m, summary.fit.position_max_m, summary.fit.rotation_rms_deg,
      summary.fit.rotation_max_deg);

  // Truth, IMU and GNSS over [t0, t1].
  summary.imu_noise = drawImuNoise(imu_noise, config.imu_noise_scale_min,
                                   config.imu_noise_scale_max, mixSeed(r.seed, 5));
  ImuSimOptions imu_opt;
  imu_opt.rate_hz = config.imu_rate_hz;
  imu_opt.noise = summary.imu_noise.noise;
  summary.imu_turn_on_bias = drawTurnOnBias(config.imu_turn_on_acc_bias_mps2,
                                            config.imu_turn_on_gyr_bias_radps, mixSeed(r.seed, 6));
  imu_opt.initial_acc_bias = summary.imu_turn_on_bias.acc_mps2;
  imu_opt.initial_gyr_bias = summary.imu_turn_on_bias.gyr_radps;
  std::vector<ImuSimSample> imu = synthesizeImu(traj, imu_opt, mixSeed(r.seed, 1));
  std::erase_if(imu, [&](const ImuSimSample& s) { return s.measured.t_ns > t1; });
  // A georeferenced trajectory is driven where it was recorded: its first epoch is the origin.
  const fusion::EnuFrame enu(
      drive.reference
          ? drive.reference->epochs.front().lla
          : fusion::Lla{config.origin_lat_deg, config.origin_lon_deg, config.origin_h_m});
  summary.origin = enu.origin();
  GnssSimOptions gnss_opt;
  gnss_opt.noise = r.gnss;
  gnss_opt.rate_hz = config.gnss_rate_hz;
  gnss_opt.lever_arm_b = config.gnss_lever_arm_m;
  gnss_opt.outages_ns = outages;
  const auto gnss_sim = driveGnss(r, drive, traj, t1, enu, gnss_opt, summary);
  std::vector<GnssFix> fixes;
  for (const auto& g : gnss_sim) fixes.push_back(g.fix);
  summary.imu_samples = imu.size();
  summary.gnss_fixes = fixes.size();

  // World along the route.
  const std::vector<Eigen::Vector3d> route = routeOf(traj, t1, summary.path_length_m);
  WorldOptions world_opt;
  world_opt.seed = r.world_seed ? mixSeed(*r.world_seed, 3) : mixSeed(r.seed, 3);
  world_opt.style = *parseWorldStyle(config.world_style);  // validated
  world_opt.texture_size_px = config.texture_size_px;
  const World world = buildWorld(route, world_opt);
  summary.world_triangles = world.triangles;
  fs::create_directories(r.out / "world");
  io::writeMeshPly(r.out / "world" / "world.ply", worldMesh(world.scene));

  // Calibration (KITTI chain) and the cameras' poses in the body frame, read back through the same
  // reader the estimator uses, so images and calibration cannot disagree.
  const render::PinholeIntrinsics K = kittiIntrinsics();
  writeKittiCalibration(r.out, K, r.stereo);
  std::vector<int> ids = {0};
  if (r.stereo) ids.push_back(1);
  const std::vector<CameraModel> calibrated =
      io::readKittiCameras(io::findKittiCalib(r.out), ids, false);
  std::vector<Eigen::Isometry3d> T_b_c;
  for (const auto& cam : calibrated) T_b_c.push_back(cam.T_b_c);

  // Camera frames, rendered and written one at a time (memory stays flat).
  const render::EglContext context;
  summary.egl = context.info().platform + ": " + context.info().gl_renderer;
  CameraSimulator cameras(context, world.scene, K, T_b_c, config, mixSeed(r.seed, 4));
  const bool kitti = r.output == io::DatasetFormat::kKittiRaw;
  std::optional<BagOutput> bag;
  if (r.output == io::DatasetFormat::kRosbag) bag.emplace(r.out);
  std::optional<Ros2BagOutput> ros2_bag;
  if (r.output == io::DatasetFormat::kRos2Bag)
    ros2_bag.emplace(r.out, config, calibrated, imu, fixes);
  std::vector<std::int64_t> frame_t;
  const auto period_ns = static_cast<std::int64_t>(std::llround(1e9 / config.camera_rate_hz));
  for (std::int64_t t = traj.t0_ns(); t <= t1; t += period_ns) frame_t.push_back(t);
  // What the camera stamps each exposure with (its clock off by camera_time_offset_s).
  const auto camera_offset_ns =
      static_cast<std::int64_t>(std::llround(config.camera_time_offset_s * 1e9));
  std::vector<std::int64_t> stamp_t = frame_t;
  for (std::int64_t& t : stamp_t) t += camera_offset_ns;
  for (std::size_t k = 0; k < frame_t.size(); ++k) {
    for (std::size_t c = 0; c < T_b_c.size(); ++c) {
      const cv::Mat image = cameras.render(traj, frame_t[k], c, k);
      if (bag) {
        bag->writeImage(stamp_t[k], c, image);
        continue;
      }
      if (ros2_bag) {
        ros2_bag->writeImage(stamp_t[k], c, image);
        continue;
      }
      const fs::path file =
          kitti ? kittiImagePath(r.out, ids[c], k) : eurocImagePath(r.out, ids[c], stamp_t[k]);
      fs::create_directories(file.parent_path());
      io::writePng(file, image);
    }
    if (progress) progress(k + 1, frame_t.size());
  }
  summary.frames = frame_t.size();

  // Sensor logs and truth.
  if (kitti) {
    for (const int id : ids) writeKittiImageStamps(r.out, id, stamp_t);
    writeKittiOxts(r.out, imu, traj, enu);
    fs::create_directories(r.out / "gnss");
    io::writeTextAtomic(r.out / "gnss" / "fixes.nmea", toNmeaLog(fixes));
    io::writeTextAtomic(r.out / "gnss" / "data.csv", toGnssCsv(fixes));
  } else if (bag) {
    bag->finish(imu, fixes, calibrated, summary.imu_noise.noise, config.imu_rate_hz);
  } else if (ros2_bag) {
    ros2_bag->finish(summary.imu_noise.noise, config.imu_rate_hz);
  } else {
    for (std::size_t c = 0; c < ids.size(); ++c)
      writeEurocCamera(r.out, ids[c], stamp_t, K, T_b_c[c], config.camera_rate_hz);
    writeEurocImu(r.out, imu, summary.imu_noise.noise, config.imu_rate_hz);
    writeEurocGnss(r.out, fixes);
    writeEurocTruth(r.out, imu, traj);
  }
  Trajectory truth;
  for (const auto& s : imu) {
    truth.t_ns.push_back(s.measured.t_ns);
    truth.poses.push_back(traj.at(s.measured.t_ns).pose());
  }
  io::writeTum(r.out / "groundtruth.tum", truth);
  writeImuTruth(r.out / "imu_truth.csv", imu);
  writeSimYaml(r.out / "sim.yaml", r, summary);
  return summary;
}

}  // namespace gvio::sim
