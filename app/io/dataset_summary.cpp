#include "io/dataset_summary.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "fusion/geodesy.hpp"
#include "io/text.hpp"

namespace gvio::io {
namespace {

using nlohmann::json;

double seconds(std::int64_t t_ns) {
  return 1e-9 * static_cast<double>(t_ns);
}

json statsJson(const StreamStats& s) {
  json gaps = json::array();
  for (std::size_t i = 0; i < s.gaps.size() && i < 20; ++i) {  // the first 20; count is complete
    gaps.push_back({{"t0", formatSeconds(s.gaps[i].first)},
                    {"t1", formatSeconds(s.gaps[i].second)},
                    {"duration_s", seconds(s.gaps[i].second - s.gaps[i].first)}});
  }
  return {{"count", s.count},
          {"rate_hz", s.rate_hz},
          {"t_first", formatSeconds(s.t_first_ns)},
          {"t_last", formatSeconds(s.t_last_ns)},
          {"duration_s", seconds(s.t_last_ns - s.t_first_ns)},
          {"gap_count", s.gaps.size()},
          {"max_period_s", s.max_gap_s},
          {"gaps", gaps}};
}

template <typename T>
std::vector<std::int64_t> stampsOf(const std::vector<T>& records) {
  std::vector<std::int64_t> t;
  t.reserve(records.size());
  for (const auto& r : records) t.push_back(r.t_ns);
  return t;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

json cameraJson(const CameraModel& cam) {
  const Eigen::AngleAxisd aa(cam.T_b_c.rotation());
  return {{"name", cam.name},
          {"width", cam.width_px},
          {"height", cam.height_px},
          {"fx", cam.fx},
          {"fy", cam.fy},
          {"cx", cam.cx},
          {"cy", cam.cy},
          {"distortion_model", hasLensDistortion(cam) ? toString(cam.distortion_model) : "none"},
          {"distortion", cam.distortion},
          {"p_b_c_m",
           {cam.T_b_c.translation().x(), cam.T_b_c.translation().y(), cam.T_b_c.translation().z()}},
          {"R_b_c_angle_deg", aa.angle() * 180.0 / M_PI}};
}

json gnssJson(const Dataset& ds, double gap_factor) {
  json j = statsJson(streamStats(stampsOf(ds.gnss), gap_factor));
  j["source"] = ds.gnss_source;
  std::vector<double> sigma_h;
  std::map<int, std::size_t> quality;
  const fusion::EnuFrame enu(
      {ds.gnss.front().lat_deg, ds.gnss.front().lon_deg, ds.gnss.front().h_ellipsoid_m});
  double track_m = 0.0;
  Eigen::Vector3d prev = Eigen::Vector3d::Zero(), lo = prev, hi = prev;
  for (const auto& f : ds.gnss) {
    sigma_h.push_back(f.sigma_h_m);
    ++quality[f.quality];
    const Eigen::Vector3d p = enu.toEnu({f.lat_deg, f.lon_deg, f.h_ellipsoid_m});
    track_m += (p - prev).norm();
    prev = p;
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  json q = json::object();
  for (const auto& [k, n] : quality) q[std::to_string(k)] = n;
  j["first_fix"] = {{"lat_deg", ds.gnss.front().lat_deg},
                    {"lon_deg", ds.gnss.front().lon_deg},
                    {"h_ellipsoid_m", ds.gnss.front().h_ellipsoid_m}};
  j["track_length_m"] = track_m;
  j["extent_enu_m"] = {hi.x() - lo.x(), hi.y() - lo.y(), hi.z() - lo.z()};
  j["sigma_h_median_m"] = median(sigma_h);
  j["quality_counts"] = q;
  return j;
}

}  // namespace

StreamStats streamStats(const std::vector<std::int64_t>& t, double gap_factor) {
  StreamStats s;
  s.count = t.size();
  if (t.empty()) return s;
  s.t_first_ns = t.front();
  s.t_last_ns = t.back();
  if (t.size() < 2) return s;
  std::vector<double> periods;
  periods.reserve(t.size() - 1);
  for (std::size_t i = 1; i < t.size(); ++i) periods.push_back(seconds(t[i] - t[i - 1]));
  s.max_gap_s = *std::max_element(periods.begin(), periods.end());
  s.median_period_s = median(periods);
  s.rate_hz = s.median_period_s > 0.0 ? 1.0 / s.median_period_s : 0.0;
  for (std::size_t i = 1; i < t.size(); ++i) {
    if (periods[i - 1] > gap_factor * s.median_period_s) s.gaps.emplace_back(t[i - 1], t[i]);
  }
  return s;
}

json imuNoiseJson(const ImuNoise& noise) {
  return {{"acc_noise_density", noise.acc_noise_density},
          {"gyr_noise_density", noise.gyr_noise_density},
          {"acc_random_walk", noise.acc_random_walk},
          {"gyr_random_walk", noise.gyr_random_walk}};
}

json summarizeDataset(const Dataset& ds, double gap_factor, const ImuNoise& noise,
                      const std::string& noise_source) {
  json j;
  j["format"] = toString(ds.format);
  j["variant"] = ds.variant;
  j["path"] = ds.root.string();
  std::int64_t t0 = std::numeric_limits<std::int64_t>::max(),
               t1 = std::numeric_limits<std::int64_t>::min();
  auto span = [&](const std::vector<std::int64_t>& t) {
    if (t.empty()) return;
    t0 = std::min(t0, t.front());
    t1 = std::max(t1, t.back());
  };
  if (!ds.frames.empty()) {
    const auto t = stampsOf(ds.frames);
    span(t);
    j["cameras"] = statsJson(streamStats(t, gap_factor));
    j["cameras"]["models"] = json::array();
    for (const auto& cam : ds.cameras) j["cameras"]["models"].push_back(cameraJson(cam));
    if (ds.cameras.size() >= 2) {
      j["cameras"]["stereo_baseline_m"] =
          (ds.cameras[1].T_b_c.translation() - ds.cameras[0].T_b_c.translation()).norm();
    }
  }
  if (!ds.imu.empty()) {
    const auto t = stampsOf(ds.imu);
    span(t);
    j["imu"] = statsJson(streamStats(t, gap_factor));
    j["imu"]["noise"] = imuNoiseJson(noise);
    j["imu"]["noise"]["source"] = noise_source;
  }
  if (!ds.gnss.empty()) {
    span(stampsOf(ds.gnss));
    j["gnss"] = gnssJson(ds, gap_factor);
  }
  if (ds.groundtruth) {
    span(ds.groundtruth->t_ns);
    j["groundtruth"] = statsJson(streamStats(ds.groundtruth->t_ns, gap_factor));
    j["groundtruth"]["source"] = ds.groundtruth_source;
    j["groundtruth"]["path_length_m"] = pathLengthM(*ds.groundtruth);
  }
  j["t_first"] = formatSeconds(t0);
  j["t_last"] = formatSeconds(t1);
  j["duration_s"] = seconds(t1 - t0);
  if (!ds.bag_topics.empty()) j["bag_topics"] = bagTopicsJson(ds);
  if (!ds.calibration_sources.empty()) {
    json sources = json::array();
    for (const CalibrationSource& c : ds.calibration_sources) {
      sources.push_back({{"value", c.value}, {"source", c.source}});
    }
    j["calibration_sources"] = sources;
  }
  if (ds.gnss_lever_arm_b) {
    j["gnss_lever_arm_b_m"] = {ds.gnss_lever_arm_b->x(), ds.gnss_lever_arm_b->y(),
                               ds.gnss_lever_arm_b->z()};
  }
  j["warnings"] = ds.warnings;
  return j;
}

json bagTopicsJson(const Dataset& ds) {
  json topics = json::array();
  for (const BagTopicUse& t : ds.bag_topics) {
    topics.push_back({{"role", t.role},
                      {"topic", t.topic},
                      {"type", t.type},
                      {"messages", t.messages},
                      {"used", t.used},
                      {"out_of_order_sorted", t.out_of_order},
                      {"repeated_stamps_dropped", t.duplicate_stamps},
                      {"zero_header_stamps", t.zero_stamps}});
  }
  return topics;
}

std::string formatSummary(const json& j) {
  std::string out = fmt::format("dataset   {} ({}) {}\n", j["format"].get<std::string>(),
                                j["variant"].get<std::string>(), j["path"].get<std::string>());
  out += fmt::format("time span {} .. {} s ({:.3f} s)\n", j["t_first"].get<std::string>(),
                     j["t_last"].get<std::string>(), j["duration_s"].get<double>());
  auto stream = [&](const char* key, const char* label) {
    if (!j.contains(key)) {
      out += fmt::format("{:<9} none\n", label);
      return;
    }
    const json& s = j[key];
    out += fmt::format(
        "{:<9} {} samples at {:.2f} Hz over {:.3f} s, {} gaps (longest period {:.3f} s)\n", label,
        s["count"].get<std::size_t>(), s["rate_hz"].get<double>(), s["duration_s"].get<double>(),
        s["gap_count"].get<std::size_t>(), s["max_period_s"].get<double>());
  };
  stream("cameras", "frames");
  if (j.contains("cameras")) {
    for (const auto& m : j["cameras"]["models"]) {
      const std::string distortion = m["distortion_model"].get<std::string>();
      out += fmt::format(
          "  {:<8} {}x{} fx {:.3f} fy {:.3f} cx {:.3f} cy {:.3f}{}, p_b_c [{:.3f} {:.3f} {:.3f}] "
          "m\n",
          m["name"].get<std::string>(), m["width"].get<int>(), m["height"].get<int>(),
          m["fx"].get<double>(), m["fy"].get<double>(), m["cx"].get<double>(),
          m["cy"].get<double>(), distortion == "none" ? "" : ", " + distortion + " distortion",
          m["p_b_c_m"][0].get<double>(), m["p_b_c_m"][1].get<double>(),
          m["p_b_c_m"][2].get<double>());
    }
    if (j["cameras"].contains("stereo_baseline_m")) {
      out += fmt::format("  stereo baseline {:.4f} m\n",
                         j["cameras"]["stereo_baseline_m"].get<double>());
    }
  }
  stream("imu", "imu");
  if (j.contains("imu")) {
    const json& n = j["imu"]["noise"];
    out += fmt::format(
        "  noise ({}): acc {:.3g} m/s^2/rtHz, gyr {:.3g} rad/s/rtHz, acc rw {:.3g}, gyr rw "
        "{:.3g}\n",
        n["source"].get<std::string>(), n["acc_noise_density"].get<double>(),
        n["gyr_noise_density"].get<double>(), n["acc_random_walk"].get<double>(),
        n["gyr_random_walk"].get<double>());
  }
  stream("gnss", "gnss");
  if (j.contains("gnss")) {
    const json& g = j["gnss"];
    out += fmt::format(
        "  first fix {:.7f} {:.7f} {:.2f} m, track {:.1f} m, median sigma_h {:.3f} m\n",
        g["first_fix"]["lat_deg"].get<double>(), g["first_fix"]["lon_deg"].get<double>(),
        g["first_fix"]["h_ellipsoid_m"].get<double>(), g["track_length_m"].get<double>(),
        g["sigma_h_median_m"].get<double>());
  }
  stream("groundtruth", "truth");
  if (j.contains("groundtruth")) {
    out += fmt::format("  path length {:.1f} m\n", j["groundtruth"]["path_length_m"].get<double>());
  }
  for (const auto& t : j.value("bag_topics", json::array())) {
    out += fmt::format("topic     {:<4} {} ({}): {} messages, {} used, {} sorted, {} dropped\n",
                       t["role"].get<std::string>(), t["topic"].get<std::string>(),
                       t["type"].get<std::string>(), t["messages"].get<std::size_t>(),
                       t["used"].get<std::size_t>(), t["out_of_order_sorted"].get<std::size_t>(),
                       t["repeated_stamps_dropped"].get<std::size_t>());
  }
  for (const auto& c : j.value("calibration_sources", json::array())) {
    out += fmt::format("calib     {:<16} from {}\n", c["value"].get<std::string>(),
                       c["source"].get<std::string>());
  }
  if (j.contains("gnss_lever_arm_b_m")) {
    const json& l = j["gnss_lever_arm_b_m"];
    out += fmt::format("  GNSS antenna in the body frame [{:.3f} {:.3f} {:.3f}] m\n",
                       l[0].get<double>(), l[1].get<double>(), l[2].get<double>());
  }
  for (const auto& w : j["warnings"]) out += "warning   " + w.get<std::string>() + "\n";
  return out;
}

}  // namespace gvio::io
