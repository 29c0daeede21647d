#include "run/map_passes.hpp"

#include <spdlog/spdlog.h>

#include <cmath>
#include <regex>

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

}  // namespace

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
