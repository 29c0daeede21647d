#include "mapping/view_flags.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "mapping/consistency.hpp"
#include "odometry/error.hpp"

namespace gvio::mapping {
namespace {

// 1.4826 MAD is the standard deviation of a normal distribution (Rousseeuw & Croux 1993).
constexpr double kMadToSigma = 1.4826;
constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

// The median (mapping::percentile's), NaN without values.
double median(std::vector<double> v) {
  return v.empty() ? kNan : percentile(v, 0.5);
}

std::vector<double> finiteOf(const std::vector<double>& values) {
  std::vector<double> finite;
  for (const double v : values) {
    if (std::isfinite(v)) finite.push_back(v);
  }
  return finite;
}

// 1.4826 MAD around the median of the finite values.
double robustSpread(const std::vector<double>& values) {
  const std::vector<double> finite = finiteOf(values);
  if (finite.empty()) return kNan;
  const double m = median(finite);
  std::vector<double> dev;
  dev.reserve(finite.size());
  for (const double v : finite) dev.push_back(std::abs(v - m));
  return kMadToSigma * median(dev);
}

// Per view: the median of the scored views within +-window/2 (two pointers: the times ascend);
// NaN where the window holds fewer than min_views_to_flag.
std::vector<double> localMedians(const std::vector<double>& values, const std::vector<double>& t_s,
                                 const ImageConsistencyConfig& c) {
  std::vector<double> out(values.size(), kNan);
  std::size_t lo = 0, hi = 0;
  for (std::size_t i = 0; i < values.size(); ++i) {
    while (t_s[lo] < t_s[i] - 0.5 * c.local_window_s) ++lo;
    while (hi < values.size() && t_s[hi] <= t_s[i] + 0.5 * c.local_window_s) ++hi;
    std::vector<double> window;
    for (std::size_t j = lo; j < hi; ++j) {
      if (std::isfinite(values[j])) window.push_back(values[j]);
    }
    if (window.size() >= c.min_views_to_flag) out[i] = median(window);
  }
  return out;
}

// tau^2 = (1.4826 MAD of the residuals)^2 - the median se^2: the spread beyond the errors.
double spreadBeyondErrors(const std::vector<double>& residuals, const std::vector<double>& se2) {
  const double spread = robustSpread(residuals);
  return std::sqrt(std::max(spread * spread - median(se2), 0.0));
}

// What views like each one show: the median shift and the spread tau of the residuals of the
// `similar` views whose covariate is nearest its own, among the views more than apart_s away in
// time (so that a faulty stretch is never its own reference: its views are alike too); ties by
// index, so the result does not depend on the order of equal covariates. NaN for views without a
// residual or a covariate, or with fewer than `similar` such views. The views sorted by covariate
// once, each one's neighbours are a window grown around it from the nearer side.
struct Similar {
  std::vector<double> shift, tau;
};

Similar similarViews(const std::vector<double>& residual, const std::vector<double>& se2,
                     const std::vector<double>& covariate, const std::vector<double>& t_s,
                     std::size_t similar, double apart_s) {
  const std::size_t n = residual.size();
  Similar out{std::vector<double>(n, kNan), std::vector<double>(n, kNan)};
  if (similar == 0) return out;
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < n; ++i) {
    if (std::isfinite(residual[i]) && std::isfinite(covariate[i])) order.push_back(i);
  }
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return std::make_pair(covariate[a], a) < std::make_pair(covariate[b], b);
  });
  std::vector<double> r, e2;
  for (std::size_t pos = 0; pos < order.size(); ++pos) {
    const std::size_t i = order[pos];
    const double a = covariate[i];
    r.clear();
    e2.clear();
    std::size_t lo = pos, hi = pos + 1;  // order[lo, hi) has been looked at
    while (r.size() < similar && (lo > 0 || hi < order.size())) {
      const bool take_lower = hi == order.size() ||
                              (lo > 0 && a - covariate[order[lo - 1]] <= covariate[order[hi]] - a);
      const std::size_t j = take_lower ? order[--lo] : order[hi++];
      if (std::abs(t_s[j] - t_s[i]) <= apart_s) continue;
      r.push_back(residual[j]);
      e2.push_back(se2[j]);
    }
    if (r.size() < similar) continue;
    out.shift[i] = median(r);
    out.tau[i] = spreadBeyondErrors(r, e2);
  }
  return out;
}

// One comparison (with the local medians or the drive's): per view the shift and spread tau that
// views like it show (similarViews; tau never below the drive's; the drive's tau and no shift
// where too few views are like it), the scale of its residual d = max(sqrt(tau^2 + se^2),
// min_flag_sigma), the standardised residual z = (v - ref - shift) / d, and the robust spread of
// z over the drive (at least 1: a drive is never trusted to be tighter than its own errors say).
struct Comparison {
  std::vector<double> d, z, shift;
  double tau = kNan, z_spread = kNan;
};

Comparison compare(const std::vector<double>& values, const std::vector<double>& se,
                   const std::vector<double>& reference, const std::vector<double>& covariate,
                   const std::vector<double>& t_s, const ImageConsistencyConfig& c) {
  const std::size_t n = values.size();
  Comparison out;
  out.d.assign(n, kNan);
  out.z.assign(n, kNan);
  out.shift.assign(n, 0.0);
  const auto error = [&](std::size_t i) { return std::isfinite(se[i]) ? se[i] : 0.0; };
  std::vector<double> residual(n, kNan), se2(n, kNan), residuals, se2s;
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(values[i]) || !std::isfinite(reference[i])) continue;
    residual[i] = values[i] - reference[i];
    se2[i] = error(i) * error(i);
    residuals.push_back(residual[i]);
    se2s.push_back(se2[i]);
  }
  if (residuals.size() < c.min_views_to_flag) return out;
  out.tau = spreadBeyondErrors(residuals, se2s);
  const Similar similar =
      similarViews(residual, se2, covariate, t_s, c.similar_views, c.local_window_s);
  std::vector<double> z;
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(residual[i])) continue;
    const bool like = std::isfinite(similar.tau[i]);
    out.shift[i] = like ? similar.shift[i] : 0.0;
    const double tau = like ? std::max(similar.tau[i], out.tau) : out.tau;
    out.d[i] = std::max(std::hypot(tau, error(i)), c.min_flag_sigma);
    out.z[i] = (residual[i] - out.shift[i]) / out.d[i];
    z.push_back(out.z[i]);
  }
  out.z_spread = std::max(1.0, robustSpread(z));
  return out;
}

struct Score {
  const char* name;  // "ncc", "depth agreement"
  const char* unit;  // what its support counts
  std::vector<double> value, se;
  std::vector<int> support;
  std::vector<bool> one_sided;  // judged by the floor alone
  std::vector<double> drawn_depth_m;
  double k = 4.0;  // flagged this many sigmas below what is typical
  double floor = -std::numeric_limits<double>::infinity();
};

// The standard error each judged view would have if it were correct: the drive's typical
// per-patch spread (the median of se sqrt(n) over its views) over sqrt(n) of this view's
// support. A view's own se would grow with a fault (its patches then disagree among themselves:
// some still match, some no longer do) and hide the fault it measures; the support still sets
// how far a view may stray (few patches, a larger error).
std::vector<double> nullSe(const Score& s, const std::vector<double>& judged) {
  std::vector<double> per_patch;
  for (std::size_t i = 0; i < judged.size(); ++i) {
    if (std::isfinite(judged[i]) && std::isfinite(s.se[i]) && s.support[i] > 0) {
      per_patch.push_back(s.se[i] * std::sqrt(static_cast<double>(s.support[i])));
    }
  }
  const double spread = median(per_patch);
  std::vector<double> out(judged.size(), kNan);
  for (std::size_t i = 0; i < judged.size(); ++i) {
    if (s.support[i] > 0) out[i] = spread / std::sqrt(static_cast<double>(s.support[i]));
  }
  return out;
}

// The thresholds of one score; `reason` gets, per view, why it is flagged ("" when it is not).
ScoreThresholds thresholdsOf(const Score& s, const std::vector<double>& t_s,
                             const ImageConsistencyConfig& c, std::vector<std::string>& reason) {
  const std::size_t n = s.value.size();
  ScoreThresholds out;
  out.reference.assign(n, kNan);
  out.below.assign(n, -std::numeric_limits<double>::infinity());
  out.z.assign(n, kNan);
  reason.assign(n, "");
  std::vector<double> judged = s.value;  // what is typical comes from two-sided views only
  for (std::size_t i = 0; i < n; ++i) {
    if (s.one_sided[i]) judged[i] = kNan;
  }
  out.median = median(finiteOf(judged));
  const std::vector<double> se = nullSe(s, judged);
  const std::vector<double> local_median = localMedians(judged, t_s, c);
  // Views are alike when their drawn maps are alike magnified: 1 / depth (pixels per metre).
  std::vector<double> magnification(n, kNan);
  for (std::size_t i = 0; i < n; ++i) {
    if (s.drawn_depth_m[i] > 0.0) magnification[i] = 1.0 / s.drawn_depth_m[i];
  }
  const Comparison local = compare(judged, se, local_median, magnification, t_s, c);
  const Comparison drive =
      compare(judged, se, std::vector<double>(n, out.median), magnification, t_s, c);
  out.tau = local.tau;
  out.z_spread = local.z_spread;
  const double k = s.k;
  // "0.214 = local median 0.552 - 0.098 as near - 4 x 0.060": the views drawn as near as this
  // one sit 0.098 below their neighbours in time.
  const auto rule = [&](double below, double ref, double shift, double scale, const char* which) {
    const std::string near =
        shift == 0.0 ? ""
                     : fmt::format(" {} {:.3f} as near", shift < 0.0 ? '-' : '+', std::abs(shift));
    return fmt::format("{:.3f} = {} median {:.3f}{} - {:g} x {:.3f}", below, which, ref, near, k,
                       scale);
  };
  for (std::size_t i = 0; i < n; ++i) {
    const double v = s.value[i];
    if (!std::isfinite(v)) continue;
    std::string why;
    if (std::isfinite(local.z[i])) {
      const double scale = local.z_spread * local.d[i];
      out.reference[i] = local_median[i] + local.shift[i];
      out.z[i] = local.z[i] / local.z_spread;
      out.below[i] = out.reference[i] - k * scale;
      if (v < out.below[i]) {
        why = rule(out.below[i], local_median[i], local.shift[i], scale, "local");
      }
    }
    // The drive's median where the neighbours are too few to tell what is typical (a drive's
    // ends with sparse keyframes): two tests on every view would double the false alarms.
    if (!std::isfinite(local.z[i]) && std::isfinite(drive.z[i])) {
      const double scale = drive.z_spread * drive.d[i];
      out.reference[i] = out.median + drive.shift[i];
      out.z[i] = drive.z[i] / drive.z_spread;
      out.below[i] = out.reference[i] - k * scale;
      if (v < out.below[i]) why = rule(out.below[i], out.median, drive.shift[i], scale, "drive");
    }
    const double e = std::isfinite(s.se[i]) ? s.se[i] : 0.0;
    if (why.empty() && v + k * e < s.floor) {
      why = fmt::format("{:.3f} = floor {:.3f} - {:g} x {:.3f}", s.floor - k * e, s.floor, k, e);
    }
    if (v + k * e < s.floor) out.below[i] = std::max(out.below[i], s.floor - k * e);
    if (!why.empty()) {
      reason[i] = fmt::format("{} {:.3f} < {} over {} {}", s.name, v, why, s.support[i], s.unit);
    }
  }
  return out;
}

}  // namespace

const char* toString(ViewStatus status) {
  switch (status) {
    case ViewStatus::kOk:
      return "ok";
    case ViewStatus::kFlagged:
      return "flagged";
    case ViewStatus::kNotEnoughEvidence:
      break;
  }
  return "not_enough_evidence";
}

FlaggedViews flagOutliers(const std::vector<ViewScore>& views, const std::vector<double>& t_s,
                          const ImageConsistencyConfig& c) {
  if (t_s.size() != views.size()) {
    throw InvalidInput("image consistency: one time per view needed");
  }
  if (!std::is_sorted(t_s.begin(), t_s.end())) {
    throw InvalidInput("image consistency: view times must ascend");
  }
  Score ncc{"ncc", "patches", {}, {}, {}, {}, {}, c.flag_sigmas, c.min_ncc};
  Score depth{"depth agreement", "patches", {}, {}, {}, {}, {}, c.depth_flag_sigmas};
  for (const ViewScore& v : views) {
    ncc.one_sided.push_back(v.one_sided);
    depth.one_sided.push_back(v.one_sided);
    ncc.drawn_depth_m.push_back(v.drawn_depth_m);
    depth.drawn_depth_m.push_back(v.drawn_depth_m);
    ncc.value.push_back(v.ncc);
    ncc.se.push_back(v.ncc_se);
    ncc.support.push_back(v.patches);
    depth.value.push_back(v.depth_agreement);
    depth.se.push_back(v.depth_se);
    depth.support.push_back(v.depth_cells);
  }
  FlaggedViews out;
  std::vector<std::string> ncc_why, depth_why;
  out.ncc = thresholdsOf(ncc, t_s, c, ncc_why);
  out.depth = thresholdsOf(depth, t_s, c, depth_why);
  const std::size_t n = views.size();
  out.flagged.assign(n, false);
  out.status.assign(n, ViewStatus::kNotEnoughEvidence);
  out.reason.assign(n, "");
  for (std::size_t i = 0; i < n; ++i) {
    out.reason[i] = ncc_why[i];
    if (!depth_why[i].empty()) {
      out.reason[i] += (out.reason[i].empty() ? "" : "; ") + depth_why[i];
    }
    out.flagged[i] = !out.reason[i].empty();
    const bool judged = std::isfinite(out.ncc.z[i]) || std::isfinite(out.depth.z[i]);
    if (out.flagged[i]) {
      out.status[i] = ViewStatus::kFlagged;
    } else if (judged) {
      out.status[i] = ViewStatus::kOk;
    }
  }
  return out;
}

std::vector<ViewStretch> flaggedStretches(const std::vector<bool>& flagged, std::size_t max_gap) {
  std::vector<ViewStretch> out;
  for (std::size_t i = 0; i < flagged.size(); ++i) {
    if (!flagged[i]) continue;
    if (!out.empty() && i - out.back().last <= max_gap + 1) {
      out.back().last = i;
    } else {
      out.push_back({i, i});
    }
  }
  return out;
}

}  // namespace gvio::mapping
