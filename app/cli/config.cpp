#include "cli/config.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <yaml-cpp/yaml.h>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <map>

#include "io/input_error.hpp"

namespace gvio::cli {
namespace {

double parseDouble(std::string_view key, std::string_view text) {
  double value = 0.0;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || ec != std::errc() || ptr != text.data() + text.size() ||
      !std::isfinite(value)) {
    throw InvalidInput(fmt::format("bad value '{}' for {}: expected a finite number", text, key));
  }
  return value;
}

bool parseBool(std::string_view key, std::string_view text) {
  if (text == "true" || text == "yes" || text == "on" || text == "1") return true;
  if (text == "false" || text == "no" || text == "off" || text == "0") return false;
  throw InvalidInput(fmt::format("bad value '{}' for {}: expected true or false", text, key));
}

std::string formatDouble(double v) {
  return fmt::format("{}", v);
}  // shortest round-trip form

ConfigKey number(std::string name, double& field) {
  return {name, [name, &field](std::string_view v) { field = parseDouble(name, v); },
          [&field] { return formatDouble(field); }};
}

ConfigKey boolean(std::string name, bool& field) {
  return {name, [name, &field](std::string_view v) { field = parseBool(name, v); },
          [&field] { return std::string(field ? "true" : "false"); }};
}

ConfigKey integer(std::string name, int& field) {
  return {
      name,
      [name, &field](std::string_view v) {
        const double d = parseDouble(name, v);
        if (d != std::floor(d) || std::abs(d) > 1e9) {
          throw InvalidInput(fmt::format("bad value '{}' for {}: expected an integer", v, name));
        }
        field = static_cast<int>(d);
      },
      [&field] { return std::to_string(field); }};
}

// "auto" (stored as 0: the library picks by mode) or an integer >= 1.
ConfigKey integerOrAuto(std::string name, int& field) {
  return {name,
          [name, &field](std::string_view v) {
            int parsed = 0;
            if (v != "auto") {
              integer(name, parsed).set(v);
              if (parsed < 1) {
                throw InvalidInput(fmt::format(
                    "bad value '{}' for {}: expected auto or an integer >= 1", v, name));
              }
            }
            field = parsed;  // only once the value is known good
          },
          [&field] { return field == 0 ? std::string("auto") : std::to_string(field); }};
}

// "auto" (stored as 0: the run picks by mode) or a number > 0.
ConfigKey numberOrAuto(std::string name, double& field) {
  return {name,
          [name, &field](std::string_view v) {
            double parsed = 0.0;
            if (v != "auto") {
              parsed = parseDouble(name, v);
              if (parsed <= 0.0) {
                throw InvalidInput(fmt::format(
                    "bad value '{}' for {}: expected auto or a positive number", v, name));
              }
            }
            field = parsed;  // only once the value is known good
          },
          [&field] { return field == 0.0 ? std::string("auto") : formatDouble(field); }};
}

ConfigKey foldedLandmarks(std::string name, odometry::FoldedLandmarks& field) {
  return {name,
          [name, &field](std::string_view v) {
            // The library's parser decides which names exist; the message takes this file's form.
            try {
              field = odometry::parseFoldedLandmarks(std::string(v));
            } catch (const InvalidInput&) {
              throw InvalidInput(
                  fmt::format("bad value '{}' for {}: expected auto, drop or reanchor", v, name));
            }
          },
          [&field] { return odometry::toString(field); }};
}

// Vectors are written "x,y,z" (a YAML sequence flattens to that form).
ConfigKey vector3(std::string name, Eigen::Vector3d& field) {
  return {
      name,
      [name, &field](std::string_view v) {
        if (v.size() >= 2 && v.front() == '[' && v.back() == ']') v = v.substr(1, v.size() - 2);
        Eigen::Vector3d out;
        std::size_t start = 0;
        for (int i = 0; i < 3; ++i) {
          const auto comma = v.find(',', start);
          if ((i < 2) != (comma != std::string_view::npos)) {
            throw InvalidInput(fmt::format("bad value '{}' for {}: expected 3 numbers", v, name));
          }
          std::string_view part = v.substr(start, i < 2 ? comma - start : std::string_view::npos);
          while (!part.empty() && part.front() == ' ') part.remove_prefix(1);
          while (!part.empty() && part.back() == ' ') part.remove_suffix(1);
          out[i] = parseDouble(name, part);
          start = comma + 1;
        }
        field = out;
      },
      [&field] { return fmt::format("[{}, {}, {}]", field.x(), field.y(), field.z()); }};
}

ConfigKey text(std::string name, std::string& field) {
  return {name, [&field](std::string_view v) { field = std::string(v); },
          [&field] { return field; }};
}

struct FlatEntry {
  std::string value;
  std::size_t line = 0;
};

// Nested YAML maps become dotted keys; sequences are joined with ',' (vectors parse that form).
void flatten(const YAML::Node& node, const std::string& prefix,
             std::vector<std::pair<std::string, FlatEntry>>& out,
             const std::filesystem::path& file) {
  const auto line = static_cast<std::size_t>(node.Mark().line + 1);
  if (node.IsMap()) {
    for (const auto& kv : node) {
      const std::string key = kv.first.Scalar();
      flatten(kv.second, prefix.empty() ? key : prefix + "." + key, out, file);
    }
  } else if (node.IsSequence()) {
    std::string joined;
    for (const auto& item : node) joined += (joined.empty() ? "" : ",") + item.Scalar();
    out.emplace_back(prefix, FlatEntry{joined, line});
  } else if (node.IsScalar()) {
    out.emplace_back(prefix, FlatEntry{node.Scalar(), line});
  } else if (!prefix.empty()) {
    throw io::InputError(file, line, "key '" + prefix + "' has no value");
  }
}

// Where each key's value came from: the config file's line, or --set (line 0).
using KeyOrigins = std::map<std::string, std::size_t>;

// Keys that were replaced by one with another unit: their message says what to write instead.
// In --set they are an error; in a file a warning (the key is ignored, as an unknown one), so the
// config.yaml of a run made before the change still opens (gvio render, gvio consistency).
const char* replacementOf(const std::string& key) {
  if (key == "vio.keyframe_parallax_px") {
    return "'vio.keyframe_parallax_px' was replaced by 'vio.keyframe_parallax_deg' (an angle: "
           "pixels / focal length; 10 px on KITTI's 718 px camera is 0.8 deg)";
  }
  return nullptr;
}

void applyFile(const std::filesystem::path& file, std::map<std::string, ConfigKey*>& keys,
               std::vector<std::string>* unknown_keys, KeyOrigins* origins = nullptr) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(file.string());
  } catch (const YAML::BadFile&) {
    throw io::InputError(file, 0, "config file not found or unreadable");
  } catch (const YAML::Exception& e) {
    throw io::InputError(file, static_cast<std::size_t>(e.mark.line + 1), "YAML syntax: " + e.msg);
  }
  if (root.IsNull()) return;  // an empty file keeps the defaults
  if (!root.IsMap()) throw io::InputError(file, 1, "expected a mapping of config keys");
  std::vector<std::pair<std::string, FlatEntry>> entries;
  flatten(root, "", entries, file);
  for (const auto& [key, entry] : entries) {
    const auto it = keys.find(key);
    if (it == keys.end()) {  // a replaced key is not among them either: it says what replaced it
      const char* why = replacementOf(key);
      spdlog::warn("{}:{}: {} ignored", file.string(), entry.line,
                   why ? std::string(why) + ":" : "unknown config key '" + key + "'");
      if (unknown_keys) unknown_keys->push_back(key);
      continue;
    }
    try {
      it->second->set(entry.value);
    } catch (const InvalidInput& e) {
      throw io::InputError(file, entry.line, e.what());
    }
    if (origins) (*origins)[key] = entry.line;
  }
}

void applyOverride(const std::string& assignment, std::map<std::string, ConfigKey*>& keys,
                   KeyOrigins& origins) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0) {
    throw InvalidInput("--set '" + assignment + "': expected key=value");
  }
  const std::string key = assignment.substr(0, eq);
  if (const char* why = replacementOf(key)) throw InvalidInput(std::string("--set: ") + why);
  const auto it = keys.find(key);
  if (it == keys.end()) throw InvalidInput("--set: unknown config key '" + key + "'");
  try {
    it->second->set(std::string_view(assignment).substr(eq + 1));
  } catch (const InvalidInput& e) {
    throw InvalidInput("--set " + key + ": " +
                       e.what());  // where the value came from, as a file's line
  }
  origins[key] = 0;
}

// The key a validation message is about. The libraries name their own fields ("config:
// tracker.max_features must be ..."), which is the tail of the dotted key; the key the user set
// is the one meant.
const std::string* keyOfMessage(const std::string& message, const KeyOrigins& origins) {
  const std::string prefix = "config: ";  // also "map config: "
  const std::size_t at = message.find(prefix);
  if (at == std::string::npos) return nullptr;
  const std::size_t begin = at + prefix.size();
  const std::string field = message.substr(begin, message.find(' ', begin) - begin);
  for (const auto& [key, origin] : origins) {
    if (key == field || key.ends_with("." + field)) return &key;
  }
  return nullptr;
}

// A value that passed its own parse but not the configuration's checks: the error names where the
// user wrote it (the file's line or --set), not only the key.
[[noreturn]] void rethrowAtOrigin(const InvalidInput& e, const KeyOrigins& origins,
                                  const std::optional<std::filesystem::path>& file) {
  const std::string* key = keyOfMessage(e.what(), origins);
  if (!key) {
    // A rule over several keys, or a default the file's values conflict with: the file is the
    // place to look.
    if (file) throw io::InputError(*file, 0, e.what());
    throw e;
  }
  const std::size_t line = origins.at(*key);
  if (line > 0 && file) throw io::InputError(*file, line, e.what());
  throw InvalidInput("--set " + *key + ": " + e.what());
}

}  // namespace

void AppConfig::validate() const {
  RunConfig::validate();
  sim.validate();
}

std::vector<ConfigKey> configKeys(AppConfig& c) {
  odometry::EstimatorConfig& e = c.vio.estimator;
  mapping::MapConfig& m = c.map.map;
  mapping::LoopConfig& l = c.loops.detection;
  return {
      text("dataset.kitti_gnss_source", c.dataset.kitti_gnss_source),
      number("dataset.gap_factor", c.dataset.gap_factor),
      number("dataset.nmea_uere_spp_m", c.dataset.nmea_uere_spp_m),
      number("dataset.nmea_uere_dgps_m", c.dataset.nmea_uere_dgps_m),
      number("dataset.nmea_uere_rtk_float_m", c.dataset.nmea_uere_rtk_float_m),
      number("dataset.nmea_uere_rtk_fixed_m", c.dataset.nmea_uere_rtk_fixed_m),
      number("dataset.nmea_vertical_factor", c.dataset.nmea_vertical_factor),
      text("dataset.nmea_checksum", c.dataset.nmea_checksum),
      text("dataset.gnss_ellipse", c.dataset.gnss_ellipse),
      number("dataset.comma2k19_sigma_h_m", c.dataset.comma2k19_sigma_h_m),
      number("dataset.comma2k19_sigma_v_m", c.dataset.comma2k19_sigma_v_m),
      text("dataset.topics.cam0", c.dataset.topic_cam0),
      text("dataset.topics.cam1", c.dataset.topic_cam1),
      text("dataset.topics.imu", c.dataset.topic_imu),
      text("dataset.topics.gnss", c.dataset.topic_gnss),
      number("dataset.stereo_sync_tolerance_s", c.dataset.stereo_sync_tolerance_s),
      boolean("imu.prefer_dataset_noise", c.imu.prefer_dataset_noise),
      number("imu.dataset_noise_scale", c.imu.dataset_noise_scale),
      number("imu.acc_noise_density", c.imu.noise.acc_noise_density),
      number("imu.gyr_noise_density", c.imu.noise.gyr_noise_density),
      number("imu.acc_random_walk", c.imu.noise.acc_random_walk),
      number("imu.gyr_random_walk", c.imu.noise.gyr_random_walk),
      text("vio.mode", c.vio.mode),
      integer("vio.window_size", e.window_size),
      number("vio.keyframe_parallax_deg", e.keyframe_parallax_deg),
      integer("vio.keyframe_min_tracked", e.keyframe_min_tracked),
      number("vio.pixel_sigma_px", e.pixel_sigma_px),
      number("vio.huber_sigmas", e.huber_sigmas),
      integerOrAuto("vio.max_iterations", e.max_iterations),
      number("vio.min_depth_m", e.min_depth_m),
      number("vio.max_depth_m", e.max_depth_m),
      foldedLandmarks("vio.folded_landmarks", e.folded_landmarks),
      number("vio.max_reprojection_px", e.max_reprojection_px),
      number("vio.static_gyr_radps", e.static_gyr_radps),
      number("vio.static_acc_mps2", e.static_acc_mps2),
      number("vio.static_pixel_motion_px", e.static_pixel_motion_px),
      number("vio.init_window_s", e.init_window_s),
      number("vio.init_max_tilt_sigma_deg", e.init_max_tilt_sigma_deg),
      number("vio.init_max_wait_s", e.init_max_wait_s),
      number("vio.init_alignment_span_s", e.init_alignment_span_s),
      number("vio.max_imu_gap_s", e.max_imu_gap_s),
      integer("vio.min_features_tracking", e.min_features_tracking),
      number("vio.init_tilt_sigma_deg", e.init_tilt_sigma_deg),
      number("vio.init_velocity_sigma_mps", e.init_velocity_sigma_mps),
      number("vio.acc_bias_prior_mps2", e.acc_bias_prior_mps2),
      boolean("vio.estimate_time_offset", e.estimate_time_offset),
      number("vio.time_offset_sigma_s", e.time_offset_sigma_s),
      number("vio.time_offset_random_walk_s", e.time_offset_random_walk_s),
      number("vio.time_offset_min_rate_change_radps", e.time_offset_min_rate_change_radps),
      number("vio.time_offset_min_force_change_mps2", e.time_offset_min_force_change_mps2),
      integer("vio.time_offset_hold_median_solves", e.time_offset_hold_median_solves),
      number("vio.gyr_bias_prior_radps", e.gyr_bias_prior_radps),
      integer("vio.tracker.max_features", e.tracker.max_features),
      number("vio.tracker.quality_level", e.tracker.quality_level),
      integer("vio.tracker.min_distance_px", e.tracker.min_distance_px),
      integer("vio.tracker.grid_cols", e.tracker.grid_cols),
      integer("vio.tracker.grid_rows", e.tracker.grid_rows),
      integer("vio.tracker.klt_window_px", e.tracker.klt_window_px),
      integer("vio.tracker.klt_levels", e.tracker.klt_levels),
      integer("vio.tracker.detect_level", e.tracker.detect_level),
      number("vio.tracker.min_eigen_ratio", e.tracker.min_eigen_ratio),
      integer("vio.tracker.klt_iterations", e.tracker.klt_iterations),
      integer("vio.tracker.klt_refine_window_px", e.tracker.klt_refine_window_px),
      number("vio.tracker.fb_threshold_px", e.tracker.fb_threshold_px),
      number("vio.tracker.ransac_threshold_px", e.tracker.ransac_threshold_px),
      number("vio.tracker.stereo_max_vertical_px", e.tracker.stereo_max_vertical_px),
      number("vio.tracker.stereo_min_zncc", e.tracker.stereo_min_zncc),
      number("vio.tracker.gain_threshold", e.tracker.gain_threshold),
      number("vio.tracker.klt_predict_min_px", e.tracker.klt_predict_min_px),
      text("fusion.origin", c.fusion.origin),
      vector3("fusion.lever_arm_b", c.fusion.fusion.lever_arm_b),
      number("fusion.receiver_time_offset_s", c.fusion.fusion.receiver_time_offset_s),
      integer("fusion.alignment_min_fixes", c.fusion.fusion.alignment_min_fixes),
      number("fusion.alignment_min_extent_m", c.fusion.fusion.alignment_min_extent_m),
      number("fusion.alignment_min_cross_extent_m", c.fusion.fusion.alignment_min_cross_extent_m),
      numberOrAuto("fusion.vio_drift_fraction", c.fusion.vio_drift_fraction),
      numberOrAuto("fusion.vio_sigma_floor_m", c.fusion.vio_sigma_floor_m),
      number("fusion.vio_rot_drift_rad_per_m", c.fusion.fusion.vio_rot_drift_rad_per_m),
      numberOrAuto("fusion.vio_rot_floor_rad", c.fusion.vio_rot_floor_rad),
      number("fusion.tilt_sigma_deg", c.fusion.fusion.tilt_sigma_deg),
      integer("fusion.window_nodes", c.fusion.fusion.window_nodes),
      number("fusion.huber_sigmas", c.fusion.fusion.huber_sigmas),
      number("fusion.gate_chi2", c.fusion.fusion.gate_chi2),
      number("fusion.gate_floor_m", c.fusion.fusion.gate_floor_m),
      integer("fusion.max_consecutive_rejections", c.fusion.fusion.max_consecutive_rejections),
      number("fusion.outage_s", c.fusion.fusion.outage_s),
      boolean("fusion.smoother.enabled", c.fusion.fusion.smoother.enabled),
      number("fusion.smoother.bias_ratio", c.fusion.fusion.smoother.bias_ratio),
      number("fusion.smoother.bias_tau_s", c.fusion.fusion.smoother.bias_tau_s),
      integer("fusion.smoother.max_iterations", c.fusion.fusion.smoother.max_iterations),
      boolean("fusion.smoother.learn_noise", c.fusion.fusion.smoother.learn_noise),
      integer("fusion.smoother.min_fixes_to_learn", c.fusion.fusion.smoother.min_fixes_to_learn),
      number("fusion.smoother.outlier_chi2", c.fusion.fusion.smoother.outlier_chi2),
      number("fusion.smoother.min_learned_scale", c.fusion.fusion.smoother.min_learned_scale),
      integer("fusion.smoother.max_rounds", c.fusion.fusion.smoother.max_rounds),
      number("fusion.kf.q_position", c.fusion.fusion.kf.q_position),
      number("fusion.kf.q_velocity", c.fusion.fusion.kf.q_velocity),
      number("fusion.kf.initial_position_sigma_m", c.fusion.fusion.kf.initial_position_sigma_m),
      number("fusion.kf.initial_velocity_sigma_mps", c.fusion.fusion.kf.initial_velocity_sigma_mps),
      boolean("fusion.kf.learn_noise", c.fusion.fusion.kf.learn_noise),
      boolean("fusion.ins.estimate_time_offset", c.fusion.ins.estimate_time_offset),
      number("fusion.ins.time_offset_sigma_s", c.fusion.ins.time_offset_sigma_s),
      number("fusion.ins.time_offset_random_walk", c.fusion.ins.time_offset_random_walk),
      boolean("fusion.ins.use_velocity", c.fusion.ins.use_velocity),
      number("fusion.ins.velocity_sigma_mps", c.fusion.ins.velocity_sigma_mps),
      number("fusion.ins.velocity_min_speed_mps", c.fusion.ins.velocity_min_speed_mps),
      number("fusion.ins.velocity_gate_chi2", c.fusion.ins.velocity_gate_chi2),
      boolean("fusion.ins.use_nhc", c.fusion.ins.use_nhc),
      number("fusion.ins.nhc_sigma_mps", c.fusion.ins.nhc_sigma_mps),
      vector3("fusion.ins.mount_rpy_deg", c.fusion.ins.mount_rpy_deg),
      number("fusion.ins.init_window_s", c.fusion.ins.init_window_s),
      number("fusion.ins.init_min_speed_mps", c.fusion.ins.init_min_speed_mps),
      number("fusion.ins.init_tilt_sigma_deg", c.fusion.ins.init_tilt_sigma_deg),
      number("fusion.ins.init_heading_sigma_deg", c.fusion.ins.init_heading_sigma_deg),
      number("fusion.ins.init_velocity_sigma_mps", c.fusion.ins.init_velocity_sigma_mps),
      number("fusion.ins.init_acc_bias_sigma_mps2", c.fusion.ins.init_acc_bias_sigma_mps2),
      number("fusion.ins.init_gyr_bias_sigma_radps", c.fusion.ins.init_gyr_bias_sigma_radps),
      number("fusion.ins.max_imu_gap_s", c.fusion.ins.max_imu_gap_s),
      boolean("fusion.ins.estimate_mount", c.fusion.ins.estimate_mount),
      number("fusion.ins.mount_min_speed_mps", c.fusion.ins.mount.min_speed_mps),
      integer("fusion.ins.mount_min_samples", c.fusion.ins.mount.min_samples),
      number("fusion.ins.mount_min_concentration", c.fusion.ins.mount.min_concentration),
      number("fusion.ins.align_chunk_s", c.fusion.ins.align.chunk_s),
      number("fusion.ins.align_max_window_s", c.fusion.ins.align.max_window_s),
      number("fusion.ins.align_max_heading_sigma_deg", c.fusion.ins.align.max_heading_sigma_deg),
      number("fusion.ins.align_min_speed_mps", c.fusion.ins.align.min_speed_mps),
      number("fusion.ins.align_quiet_gyro_std_radps", c.fusion.ins.align.quiet_gyro_std_radps),
      number("fusion.ins.align_quiet_gyro_mean_radps", c.fusion.ins.align.quiet_gyro_mean_radps),
      number("fusion.ins.align_quiet_acc_mps2", c.fusion.ins.align.quiet_acc_mps2),
      integer("fusion.ins.align_hypotheses", c.fusion.ins.align.hypotheses),
      number("fusion.ins.align_same_solution_deg", c.fusion.ins.align.same_solution_deg),
      number("fusion.ins.align_min_nll_gap", c.fusion.ins.align.min_nll_gap),
      number("fusion.ins.align_bank_max_heading_sigma_deg",
             c.fusion.ins.align.bank_max_heading_sigma_deg),
      number("fusion.ins.align_imu_orientation_max_sigma_deg",
             c.fusion.ins.align.imu_orientation_max_sigma_deg),
      boolean("map.enabled", c.map.enabled),
      integer("map.sparse.min_landmark_observations", m.sparse.min_landmark_observations),
      number("map.sparse.max_landmark_reprojection_px", m.sparse.max_landmark_reprojection_px),
      number("map.sparse.max_landmark_range_m", m.sparse.max_landmark_range_m),
      boolean("map.dense.enabled", m.dense.enabled),
      integer("map.dense.every_n_keyframes", m.dense.every_n_keyframes),
      number("map.dense.min_spacing_m", m.dense.min_spacing_m),
      number("map.dense.min_rotation_deg", m.dense.min_rotation_deg),
      number("map.dense.voxel_size_m", m.dense.voxel_size_m),
      integer("map.dense.sor_mean_k", m.dense.sor_mean_k),
      number("map.dense.sor_stddev_mul", m.dense.sor_stddev_mul),
      number("map.dense.stereo.downscale", m.dense.stereo.downscale),
      integer("map.dense.stereo.num_disparities", m.dense.stereo.num_disparities),
      integer("map.dense.stereo.block_size", m.dense.stereo.block_size),
      integer("map.dense.stereo.uniqueness_ratio", m.dense.stereo.uniqueness_ratio),
      integer("map.dense.stereo.disp12_max_diff", m.dense.stereo.disp12_max_diff),
      integer("map.dense.stereo.speckle_window_size", m.dense.stereo.speckle_window_size),
      integer("map.dense.stereo.speckle_range", m.dense.stereo.speckle_range),
      number("map.dense.stereo.min_range_m", m.dense.stereo.min_range_m),
      number("map.dense.stereo.max_range_m", m.dense.stereo.max_range_m),
      number("map.occupancy.resolution_m", m.occupancy.resolution_m),
      number("map.occupancy.max_range_m", m.occupancy.max_range_m),
      boolean("loops.enabled", l.enabled),
      number("loops.min_separation_s", l.search.min_separation_s),
      number("loops.max_heading_deg", l.search.max_heading_deg),
      number("loops.search_radius_m", l.search.search_radius_m),
      number("loops.search_sigmas", l.search.search_sigmas),
      integer("loops.max_candidates", l.search.max_candidates),
      integer("loops.orb_features", l.features.orb_features),
      integer("loops.orb_levels", l.features.orb_levels),
      integer("loops.orb_fast_threshold", l.features.orb_fast_threshold),
      number("loops.min_depth_m", l.features.min_depth_m),
      number("loops.max_depth_m", l.features.max_depth_m),
      integer("loops.max_hamming", l.match.max_hamming),
      number("loops.ratio", l.match.ratio),
      integer("loops.min_inliers", l.match.min_inliers),
      number("loops.ransac_threshold_px", l.match.ransac_threshold_px),
      integer("loops.ransac_iterations", l.match.ransac_iterations),
      number("loops.max_reprojection_px", l.match.max_reprojection_px),
      number("loops.correction_floor_m", l.search.correction_floor_m),
      number("loops.correction_floor_deg", l.search.correction_floor_deg),
      integer("loops.consistent_keyframes", l.search.consistent_keyframes),
      integer("loops.consistency_window", l.search.consistency_window),
      number("loops.consistency_m", l.search.consistency_m),
      number("loops.consistency_deg", l.search.consistency_deg),
      number("loops.sigma_floor_m", l.sigma_floor_m),
      number("loops.sigma_floor_deg", l.sigma_floor_deg),
      number("loops.graph_chi2", c.loops.graph_chi2),
      integer("loops.graph_max_rounds", c.loops.graph_max_rounds),
      integer("loops.graph_max_iterations", c.loops.graph_max_iterations),
      number("loops.graph_tilt_sigma_deg", c.loops.graph_tilt_sigma_deg),
      boolean("loops.save_keyframes", c.loops.save_keyframes),
      number("sim.origin_lat_deg", c.sim.origin_lat_deg),
      number("sim.origin_lon_deg", c.sim.origin_lon_deg),
      number("sim.origin_h_m", c.sim.origin_h_m),
      number("sim.heading_deg", c.sim.heading_deg),
      number("sim.camera_rate_hz", c.sim.camera_rate_hz),
      number("sim.imu_rate_hz", c.sim.imu_rate_hz),
      number("sim.gnss_rate_hz", c.sim.gnss_rate_hz),
      vector3("sim.gnss_lever_arm_m", c.sim.gnss_lever_arm_m),
      number("sim.image_noise_dn", c.sim.image_noise_dn),
      boolean("sim.exposure_change", c.sim.exposure_change),
      number("sim.exposure_amplitude", c.sim.exposure_amplitude),
      number("sim.exposure_period_s", c.sim.exposure_period_s),
      number("sim.right_camera_gain", c.sim.right_camera_gain),
      boolean("sim.motion_blur", c.sim.motion_blur),
      number("sim.exposure_time_s", c.sim.exposure_time_s),
      integer("sim.blur_samples", c.sim.blur_samples),
      number("sim.camera_time_offset_s", c.sim.camera_time_offset_s),
      number("sim.knot_spacing_s", c.sim.knot_spacing_s),
      number("sim.smoothing", c.sim.smoothing),
      integer("sim.texture_size_px", c.sim.texture_size_px),
      text("sim.world_style", c.sim.world_style),
      number("sim.imu_noise_scale_min", c.sim.imu_noise_scale_min),
      number("sim.imu_noise_scale_max", c.sim.imu_noise_scale_max),
      number("sim.imu_turn_on_acc_bias_mps2", c.sim.imu_turn_on_acc_bias_mps2),
      number("sim.imu_turn_on_gyr_bias_radps", c.sim.imu_turn_on_gyr_bias_radps),
      text("sim.ros2bag_storage", c.sim.ros2bag_storage),
      text("sim.ros2bag_compression", c.sim.ros2bag_compression),
      integer("fleet.retries", c.fleet.retries),
      integer("fleet.slurm.cpus_per_task", c.fleet.slurm.cpus_per_task),
      integer("fleet.slurm.mem_mb", c.fleet.slurm.mem_mb),
      integer("fleet.slurm.time_limit_min", c.fleet.slurm.time_limit_min),
      text("fleet.slurm.partition", c.fleet.slurm.partition),
      text("fleet.slurm.account", c.fleet.slurm.account),
      text("fleet.slurm.job_name", c.fleet.slurm.job_name),
      boolean("merge.align", c.merge.align),
      number("merge.tile_size_m", c.merge.tile_size_m),
      number("merge.octomap_resolution_m", c.merge.octomap_resolution_m),
      number("merge.max_zone_distance_km", c.merge.max_zone_distance_km),
  };
}

AppConfig loadConfig(const ConfigSources& sources, std::vector<std::string>* unknown_keys) {
  AppConfig config;
  auto keys = configKeys(config);
  std::map<std::string, ConfigKey*> by_name;
  for (auto& k : keys) by_name[k.name] = &k;
  KeyOrigins origins;
  if (sources.file) applyFile(*sources.file, by_name, unknown_keys, &origins);
  for (const auto& assignment : sources.overrides) applyOverride(assignment, by_name, origins);
  try {
    config.validate();
  } catch (const InvalidInput& e) {
    rethrowAtOrigin(e, origins, sources.file);
  }
  return config;
}

AppConfig loadRunConfig(const std::filesystem::path& run_dir) {
  ConfigSources sources;
  if (std::filesystem::exists(run_dir / "config.yaml")) sources.file = run_dir / "config.yaml";
  return loadConfig(sources);
}

std::string dumpConfigYaml(const AppConfig& config) {
  AppConfig copy = config;  // configKeys binds mutable references
  YAML::Emitter out;
  out << YAML::BeginMap;
  std::string section;
  for (const auto& key : configKeys(copy)) {
    const auto dot = key.name.find('.');
    const std::string head = key.name.substr(0, dot);
    if (head != section) {
      if (!section.empty()) out << YAML::EndMap;
      out << YAML::Key << head << YAML::Value << YAML::BeginMap;
      section = head;
    }
    // Values go through the YAML parser so lists stay lists and numbers stay unquoted.
    const std::string value = key.get();
    out << YAML::Key << key.name.substr(dot + 1) << YAML::Value;
    if (value.empty()) {
      out << YAML::DoubleQuoted << "";  // an empty text value (a topic left to auto), not null
    } else {
      out << YAML::Load(value);
    }
  }
  if (!section.empty()) out << YAML::EndMap;
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

sim::GnssErrorModel loadGnssNoiseModel(const std::string& spec) {
  if (spec == "spp" || spec == "rtk") return sim::GnssErrorModel::preset(sim::parseGnssNoise(spec));
  const std::filesystem::path file(spec);
  if (!std::filesystem::is_regular_file(file)) {
    throw InvalidInput("--gnss-noise '" + spec +
                       "': expected none, spp, rtk or a YAML noise-model file (not found)");
  }
  sim::GnssErrorModel m = sim::GnssErrorModel::preset(sim::GnssNoise::kSpp);
  std::vector<ConfigKey> list{number("white_h_m", m.white_h_m),
                              number("white_v_m", m.white_v_m),
                              number("bias_m", m.bias_m),
                              number("bias_tau_s", m.bias_tau_s),
                              number("outlier_probability", m.outlier_probability),
                              number("outlier_min_m", m.outlier_min_m),
                              number("outlier_max_m", m.outlier_max_m),
                              number("reported_sigma_h_m", m.reported_sigma_h_m),
                              number("reported_sigma_v_m", m.reported_sigma_v_m),
                              integer("quality", m.quality)};
  std::map<std::string, ConfigKey*> keys;
  for (ConfigKey& key : list) keys[key.name] = &key;
  applyFile(file, keys, nullptr);
  try {
    m.validate();
  } catch (const InvalidInput& e) {
    throw io::InputError(file, 0, e.what());
  }
  return m;
}

}  // namespace gvio::cli
