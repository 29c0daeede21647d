#include "eval/image_check_report.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "mapping/consistency.hpp"

namespace gvio::eval {
namespace {

// The stamp as the dataset gives it (integer nanoseconds), not through a double.
std::string stamp(std::int64_t t_ns) {
  const std::int64_t s = t_ns / 1'000'000'000, ns = t_ns % 1'000'000'000;
  return t_ns < 0 ? fmt::format("{:.9f}", static_cast<double>(t_ns) * 1e-9)
                  : fmt::format("{}.{:09d}", s, ns);
}

// Mean of the finite values; NaN when there are none.
double meanOf(const std::vector<double>& v) {
  double sum = 0.0;
  std::size_t n = 0;
  for (const double x : v) {
    if (!std::isfinite(x)) continue;
    sum += x;
    ++n;
  }
  return n > 0 ? sum / static_cast<double>(n) : std::numeric_limits<double>::quiet_NaN();
}

// The revisit scores flagged among themselves: their level is the two passes' agreement, not the
// neighbouring keyframes' (its own statistics, its own thresholds).
void flagRevisits(ImageCheckResult& c, const mapping::ImageConsistencyConfig& config) {
  std::vector<mapping::ViewScore> scores;
  std::vector<double> t_s;
  for (std::size_t i = 0; i < c.rows.size(); ++i) {
    if (c.rows[i].view.revisit_sources == 0) continue;
    c.revisit_rows.push_back(i);
    scores.push_back(c.rows[i].view.revisit);
    t_s.push_back(c.t_s[i]);
  }
  c.revisit_flags = mapping::flagOutliers(scores, t_s, config);
}

std::size_t flaggedCount(const ImageCheckResult& c) {
  return static_cast<std::size_t>(std::count_if(c.rows.begin(), c.rows.end(),
                                                [](const ImageCheckRow& r) { return r.flagged; }));
}

std::vector<double> scoresOf(const ImageCheckResult& c, bool ncc) {
  std::vector<double> v;
  for (const ImageCheckRow& r : c.rows)
    v.push_back(ncc ? r.view.score.ncc : r.view.score.depth_agreement);
  return v;
}

double msMean(const ImageCheckResult& c) {
  std::vector<double> ms;
  for (const ImageCheckRow& row : c.rows) ms.push_back(row.view.ms);
  return meanOf(ms);
}

// The keyframes at a revisit, checked against the other passes' map alone. The paired difference
// (other passes minus every source, on the same keyframes) is near zero where the passes agree.
nlohmann::json revisitsJson(const ImageCheckResult& c) {
  std::vector<double> ncc, depth, ncc_difference;
  nlohmann::json flags = nlohmann::json::array();
  for (std::size_t n = 0; n < c.revisit_rows.size(); ++n) {
    const std::size_t i = c.revisit_rows[n];
    const viz::CheckedView& v = c.rows[i].view;
    ncc.push_back(v.revisit.ncc);
    depth.push_back(v.revisit.depth_agreement);
    if (v.revisit.hasNcc() && v.score.hasNcc())
      ncc_difference.push_back(v.revisit.ncc - v.score.ncc);
    if (c.revisit_flags.flagged[n]) {
      flags.push_back({{"t_from_start_s", c.t_s[i]}, {"reason", c.revisit_flags.reason[n]}});
    }
  }
  const auto& st = c.revisit_flags.status;
  return {
      {"keyframes", c.revisit_rows.size()},
      {"flagged", flags.size()},
      {"not_enough_evidence",
       std::count(st.begin(), st.end(), mapping::ViewStatus::kNotEnoughEvidence)},
      {"ncc",
       {{"mean", jsonNumber(meanOf(ncc))},
        {"median", jsonNumber(c.revisit_flags.ncc.median)},
        {"median_minus_all_sources",
         ncc_difference.empty() ? nlohmann::json(nullptr)
                                : nlohmann::json(mapping::percentile(ncc_difference, 0.5))}}},
      {"depth_agreement",
       {{"mean", jsonNumber(meanOf(depth))}, {"median", jsonNumber(c.revisit_flags.depth.median)}}},
      {"flags", flags}};
}

}  // namespace

nlohmann::json jsonNumber(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

std::string csvNumber(double v, int decimals) {
  return std::isfinite(v) ? fmt::format("{:.{}f}", v, decimals) : std::string("nan");
}

void applySelfCheck(ImageCheckResult& result, const std::vector<mapping::ViewScore>& self,
                    double min_depth_agreement) {
  std::vector<double> ncc, depth;
  for (const mapping::ViewScore& s : self) {
    if (s.hasNcc()) ncc.push_back(s.ncc);
    if (s.hasDepth()) depth.push_back(s.depth_agreement);
  }
  ImageCheckSelfCheck& out = result.self_check;
  out.keyframes = self.size();
  out.ncc_median = ncc.empty() ? out.ncc_median : mapping::percentile(ncc, 0.5);
  out.depth_median = depth.empty() ? out.depth_median : mapping::percentile(depth, 0.5);
  out.depth_valid = !(out.depth_median < min_depth_agreement);
  if (out.depth_valid) return;
  for (ImageCheckRow& row : result.rows) {
    row.view.score.depth_agreement = row.view.revisit.depth_agreement =
        std::numeric_limits<double>::quiet_NaN();
  }
}

void flagImageCheck(ImageCheckResult& result, const mapping::ImageConsistencyConfig& config) {
  std::vector<mapping::ViewScore> scores;
  for (const ImageCheckRow& row : result.rows) scores.push_back(row.view.score);
  result.flags = mapping::flagOutliers(scores, result.t_s, config);
  for (std::size_t i = 0; i < result.rows.size(); ++i) {
    result.rows[i].flagged = result.flags.flagged[i];
  }
  result.stretches = mapping::flaggedStretches(result.flags.flagged);
  flagRevisits(result, config);
}

std::string imageCheckCsv(const ImageCheckResult& c) {
  std::string out =
      "t_s,t_from_start_s,x_m,y_m,z_m,ncc,ncc_flag_below,patches,coverage,depth_agreement,"
      "depth_flag_below,depth_pixels,source_keyframes,points_drawn,flagged,ms,ncc_se,depth_se,"
      "depth_patches,ncc_sigmas,depth_sigmas,status,reason,"
      "revisit_sources,revisit_ncc,revisit_depth_agreement,revisit_status,revisit_reason,"
      "drawn_depth_m\n";
  std::size_t revisit = 0;  // index into c.revisit_rows
  for (std::size_t i = 0; i < c.rows.size(); ++i) {
    const ImageCheckRow& row = c.rows[i];
    const auto& s = row.view.score;
    std::string again = ",,,,";  // no other pass near this keyframe
    if (revisit < c.revisit_rows.size() && c.revisit_rows[revisit] == i) {
      const auto& v = row.view.revisit;
      again = fmt::format("{},{},{},{},\"{}\"", row.view.revisit_sources, csvNumber(v.ncc, 4),
                          csvNumber(v.depth_agreement, 4),
                          mapping::toString(c.revisit_flags.status[revisit]),
                          c.revisit_flags.reason[revisit]);
      ++revisit;
    }
    out += fmt::format(
        "{},{:.3f},{:.3f},{:.3f},{:.3f},{},{},{},{:.4f},{},{},{},{},{},{},{:.1f},{},{},{},{},{},{},"
        "\"{}\",{},{}\n",
        stamp(row.view.t_ns), c.t_s[i], row.p_map.x(), row.p_map.y(), row.p_map.z(),
        csvNumber(s.ncc, 4), csvNumber(c.flags.ncc.below[i], 4), s.patches, s.coverage,
        csvNumber(s.depth_agreement, 4), csvNumber(c.flags.depth.below[i], 4), s.depth_pixels,
        row.view.source_keyframes, row.view.points_drawn, row.flagged ? 1 : 0, row.view.ms,
        csvNumber(s.ncc_se, 4), csvNumber(s.depth_se, 4), s.depth_cells,
        csvNumber(c.flags.ncc.z[i], 2), csvNumber(c.flags.depth.z[i], 2),
        mapping::toString(c.flags.status[i]), c.flags.reason[i], again,
        csvNumber(s.drawn_depth_m, 2));
  }
  return out;
}

nlohmann::json imageCheckSummary(const ImageCheckResult& c, std::size_t map_keyframes,
                                 const std::filesystem::path& run,
                                 const viz::ImageCheckOptions& options, std::size_t every) {
  std::vector<double> ms;
  for (const ImageCheckRow& row : c.rows) ms.push_back(row.view.ms);
  nlohmann::json stretches = nlohmann::json::array();
  for (const auto& s : c.stretches) {
    stretches.push_back(
        {{"from_s", c.t_s[s.first]}, {"to_s", c.t_s[s.last]}, {"keyframes", s.last - s.first + 1}});
  }
  const auto scored = [&](bool ncc) {
    const std::vector<double> v = scoresOf(c, ncc);
    return std::count_if(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
  };
  nlohmann::json j;
  j["run"] = run.string();
  const auto count = [&](mapping::ViewStatus status) {
    return std::count(c.flags.status.begin(), c.flags.status.end(), status);
  };
  j["keyframes"] = {{"map", map_keyframes},
                    {"checked", c.rows.size()},
                    {"flagged", flaggedCount(c)},
                    {"not_enough_evidence", count(mapping::ViewStatus::kNotEnoughEvidence)},
                    {"ncc_scored", scored(true)},
                    {"depth_scored", scored(false)}};
  const auto scoreJson = [&](bool ncc) {
    const mapping::ScoreThresholds& th = ncc ? c.flags.ncc : c.flags.depth;
    return nlohmann::json{{"mean", jsonNumber(meanOf(scoresOf(c, ncc)))},
                          {"median", jsonNumber(th.median)},
                          {"spread_beyond_error", jsonNumber(th.tau)},
                          {"standardised_spread", jsonNumber(th.z_spread)}};
  };
  j["ncc"] = scoreJson(true);
  j["depth_agreement"] = scoreJson(false);
  // A normal score falls below k of its sigmas with probability Phi(-k) = erfc(k / sqrt 2) / 2.
  const auto normalRate = [](double k) { return 0.5 * std::erfc(k / std::sqrt(2.0)); };
  const mapping::ImageConsistencyConfig& score = options.score;
  j["flag_rule"] = {{"ncc_sigmas", score.flag_sigmas},
                    {"depth_sigmas", score.depth_flag_sigmas},
                    {"ncc_normal_false_alarm_rate", normalRate(score.flag_sigmas)},
                    {"depth_normal_false_alarm_rate", normalRate(score.depth_flag_sigmas)},
                    {"local_window_s", score.local_window_s},
                    {"similar_views", score.similar_views},
                    {"min_ncc", score.min_ncc}};
  nlohmann::json flags = nlohmann::json::array();
  for (std::size_t i = 0; i < c.rows.size(); ++i) {
    if (c.rows[i].flagged) {
      flags.push_back({{"t_from_start_s", c.t_s[i]}, {"reason", c.flags.reason[i]}});
    }
  }
  j["flags"] = flags;
  j["flagged_stretches"] = stretches;
  j["revisits"] = revisitsJson(c);
  j["self_check"] = {{"keyframes", c.self_check.keyframes},
                     {"ncc_median", jsonNumber(c.self_check.ncc_median)},
                     {"depth_agreement_median", jsonNumber(c.self_check.depth_median)},
                     {"depth_comparable", c.self_check.depth_valid}};
  j["ms_per_keyframe"] = {{"mean", jsonNumber(meanOf(ms))},
                          {"median", mapping::percentile(ms, 0.5)},
                          {"p90", mapping::percentile(ms, 0.9)}};
  j["options"] = {{"exclude_s", options.exclude_s},
                  {"neighbour_radius_m", options.neighbour_radius_m},
                  {"max_view_angle_deg", options.max_view_angle_deg},
                  {"max_depth_m", options.max_depth_m},
                  {"patch_px", options.score.patch_px},
                  {"revisits", options.revisits},
                  {"every", every}};
  return j;
}

std::string imageCheckSummaryLine(const ImageCheckResult& result) {
  const auto no_evidence = std::count(result.flags.status.begin(), result.flags.status.end(),
                                      mapping::ViewStatus::kNotEnoughEvidence);
  return fmt::format(
      "ZNCC mean {} (median {}), depth agreement mean {} (median {}); {} of {} keyframes "
      "flagged in {} stretches, {} without enough evidence; at revisits {} checked, {} flagged; "
      "{} ms per keyframe",
      csvNumber(meanOf(scoresOf(result, true)), 3), csvNumber(result.flags.ncc.median, 3),
      csvNumber(meanOf(scoresOf(result, false)), 3), csvNumber(result.flags.depth.median, 3),
      flaggedCount(result), result.rows.size(), result.stretches.size(), no_evidence,
      result.revisit_rows.size(),
      std::count(result.revisit_flags.flagged.begin(), result.revisit_flags.flagged.end(), true),
      csvNumber(msMean(result), 0));
}

}  // namespace gvio::eval
