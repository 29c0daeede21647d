#include "run/map_passes.hpp"

#include <spdlog/spdlog.h>

#include <cmath>
#include <regex>

#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <chrono>
#include <optional>

#include "mapping/consistency.hpp"
#include "odometry/error.hpp"

namespace gvio::run {
namespace {

std::int64_t toNs(double t_s) {
  return std::llround(t_s * 1e9);
}

std::size_t keyframesIn(const MapRecorder& recorder, std::int64_t t0_ns, std::int64_t t1_ns) {
  std::size_t n = 0;
  for (const auto& kf : recorder.builder().store().keyframes()) {
    if (kf.t_ns >= t0_ns && kf.t_ns <= t1_ns) ++n;
  }
  return n;
}

struct Revisits {
  std::vector<std::vector<std::size_t>> runs;        // second-pass keyframes, consecutive runs
  std::vector<std::vector<std::size_t>> first_pass;  // per run, its first-pass keyframes
};

// Second-pass keyframes and their first passes (see revisitReport), over a kd-tree of the
// keyframes' final positions.
Revisits findRevisits(const MapRecorder& recorder, const mapping::PoseLookup& pose_of) {
  const auto& keyframes = recorder.builder().store().keyframes();
  std::vector<std::optional<Eigen::Isometry3d>> pose(keyframes.size());
  auto cloud = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  std::vector<std::size_t> cloud_index;
  for (std::size_t k = 0; k < keyframes.size(); ++k) {
    pose[k] = pose_of(keyframes[k].t_ns);
    if (!pose[k]) continue;
    const Eigen::Vector3f p = pose[k]->translation().cast<float>();
    cloud->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
    cloud_index.push_back(k);
  }
  Revisits r;
  if (cloud->empty()) return r;
  pcl::KdTreeFLANN<pcl::PointXYZ> tree;
  tree.setInputCloud(cloud);
  const double min_cos = std::cos(kRevisitMaxHeadingDeg * M_PI / 180.0);
  const auto min_sep_ns = static_cast<std::int64_t>(kRevisitMinSeparationS * 1e9);
  std::size_t last = 0;
  for (std::size_t c = 0; c < cloud->size(); ++c) {
    const std::size_t j = cloud_index[c];
    pcl::Indices found;
    std::vector<float> d2;
    tree.radiusSearch((*cloud)[c], kRevisitRadiusM, found, d2);
    std::vector<std::size_t> earlier;
    for (const auto f : found) {
      const std::size_t i = cloud_index[static_cast<std::size_t>(f)];
      if (keyframes[j].t_ns - keyframes[i].t_ns < min_sep_ns) continue;
      if (pose[i]->rotation().col(0).dot(pose[j]->rotation().col(0)) < min_cos) continue;
      earlier.push_back(i);
    }
    if (earlier.empty()) continue;
    // A gap of more than a few keyframes starts a new run.
    if (r.runs.empty() || j > last + 5) {
      r.runs.emplace_back();
      r.first_pass.emplace_back();
    }
    r.runs.back().push_back(j);
    r.first_pass.back().insert(r.first_pass.back().end(), earlier.begin(), earlier.end());
    last = j;
  }
  for (std::size_t k = 0; k < r.runs.size(); ++k) {
    std::vector<std::size_t>& f = r.first_pass[k];
    std::sort(f.begin(), f.end());
    f.erase(std::unique(f.begin(), f.end()), f.end());
    const std::vector<std::size_t>& run = r.runs[k];
    std::erase_if(f, [&](std::size_t i) { return std::binary_search(run.begin(), run.end(), i); });
  }
  return r;
}

}  // namespace

nlohmann::json revisitReport(const MapRecorder& recorder, const mapping::PoseLookup& pose_of) {
  const auto start = std::chrono::steady_clock::now();
  const Revisits revisits = findRevisits(recorder, pose_of);
  std::vector<double> d;
  std::size_t n1 = 0, n2 = 0, second = 0;
  for (std::size_t k = 0; k < revisits.runs.size(); ++k) {
    const mapping::MapCloud pass1 =
        recorder.builder().keyframePoints(revisits.first_pass[k], pose_of);
    const mapping::MapCloud pass2 = recorder.builder().keyframePoints(revisits.runs[k], pose_of);
    const std::vector<double> dk = mapping::overlapDistances(pass1, pass2, kTwoPassOverlapRadiusM);
    d.insert(d.end(), dk.begin(), dk.end());
    n1 += pass1.size();
    n2 += pass2.size();
    second += revisits.runs[k].size();
  }
  const mapping::PassAgreement a =
      mapping::agreementOf(d, n1, n2, kTwoPassOverlapRadiusM, kRevisitWithinM);
  nlohmann::json j = {
      {"radius_m", kRevisitRadiusM},
      {"min_separation_s", kRevisitMinSeparationS},
      {"max_heading_deg", kRevisitMaxHeadingDeg},
      {"runs", revisits.runs.size()},
      {"second_pass_keyframes", second},
      {"pass1_points", n1},
      {"pass2_points", n2},
      {"overlap_radius_m", a.overlap_radius_m},
      {"overlap_points", a.n_overlap},
      {"overlap_fraction", a.overlap_fraction},
      {"within_m", kRevisitWithinM},
      {"fraction_within", a.fraction_within},
      {"median_m", a.median_m},
      {"p90_m", a.p90_m},
      {"target_fraction", kRevisitTargetFraction},
      {"meets_target", a.n_overlap > 0 && a.fraction_within >= kRevisitTargetFraction},
      {"ms", std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                 .count()}};
  if (a.n_overlap > 0) {
    spdlog::info(
        "map at revisits: {} second-pass keyframes in {} runs, {:.1f} % of {} overlapping points "
        "within {} m of the first pass (median {:.3f} m)",
        second, revisits.runs.size(), 100.0 * a.fraction_within, a.n_overlap, kRevisitWithinM,
        a.median_m);
  }
  return j;
}

TwoPassSpans parseTwoPass(const std::string& text) {
  static const std::regex kSpans(
      R"(\s*([0-9.eE+]+)\s*:\s*([0-9.eE+]+)\s*,\s*([0-9.eE+]+)\s*:\s*([0-9.eE+]+)\s*)");
  const std::string usage =
      "--two-pass '" + text + "': expected T0:T1,T2:T3 in seconds since the first frame";
  std::smatch m;
  if (!std::regex_match(text, m, kSpans)) throw InvalidInput(usage);
  TwoPassSpans s;
  try {
    s = {{std::stod(m[1]), std::stod(m[2])}, {std::stod(m[3]), std::stod(m[4])}};
  } catch (const std::exception&) {
    throw InvalidInput(usage);
  }
  for (const TimeSpanS& p : {s.pass1, s.pass2}) {
    if (!(std::isfinite(p.t0_s) && std::isfinite(p.t1_s) && p.t0_s >= 0.0 && p.t1_s > p.t0_s)) {
      throw InvalidInput(usage + " (each span T0 < T1, from 0)");
    }
  }
  return s;
}

nlohmann::json twoPassReport(const MapRecorder& recorder, const mapping::PoseLookup& pose_of,
                             const TwoPassSpans& spans, std::int64_t t_first_ns) {
  nlohmann::json j;
  mapping::MapCloud clouds[2];
  const TimeSpanS* passes[2] = {&spans.pass1, &spans.pass2};
  for (int k = 0; k < 2; ++k) {
    const std::int64_t t0 = t_first_ns + toNs(passes[k]->t0_s);
    const std::int64_t t1 = t_first_ns + toNs(passes[k]->t1_s);
    clouds[k] = recorder.builder().keyframePoints(t0, t1, pose_of);
    j[k == 0 ? "pass1" : "pass2"] = {{"t0_s", passes[k]->t0_s},
                                     {"t1_s", passes[k]->t1_s},
                                     {"t0_dataset_s", 1e-9 * static_cast<double>(t0)},
                                     {"t1_dataset_s", 1e-9 * static_cast<double>(t1)},
                                     {"keyframes", keyframesIn(recorder, t0, t1)},
                                     {"points", clouds[k].size()}};
  }
  const mapping::PassAgreement a =
      mapping::twoPassAgreement(clouds[0], clouds[1], kTwoPassOverlapRadiusM);
  j["overlap_radius_m"] = a.overlap_radius_m;
  j["overlap_points"] = a.n_overlap;
  j["overlap_fraction"] = a.overlap_fraction;
  j["median_m"] = a.median_m;
  j["mean_m"] = a.mean_m;
  j["p90_m"] = a.p90_m;
  j["target_median_m"] = kTwoPassTargetMedianM;
  j["meets_target"] = a.n_overlap > 0 && a.median_m <= kTwoPassTargetMedianM;
  if (a.n_overlap == 0) {
    spdlog::warn("--two-pass: no point of pass 2 lies within {} m of pass 1 ({} and {} points)",
                 kTwoPassOverlapRadiusM, a.n_pass1, a.n_pass2);
  } else {
    spdlog::info(
        "two passes: {} of {} pass-2 points within {} m of pass 1, median {:.3f} m, p90 {:.3f} m "
        "(target <= {} m)",
        a.n_overlap, a.n_pass2, kTwoPassOverlapRadiusM, a.median_m, a.p90_m, kTwoPassTargetMedianM);
  }
  return j;
}

}  // namespace gvio::run
