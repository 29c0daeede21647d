#include "mapping/loop_closure.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>

#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_types.h>

#include "odometry/error.hpp"
#include "odometry/lie.hpp"

namespace gvio::mapping {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double degrees(double rad) {
  return rad * 180.0 / std::numbers::pi;
}

double angleDeg(const Eigen::Matrix3d& R) {
  return degrees(odometry::logSo3(R).norm());
}

// 1-sigma uncertainty of the prior relative position of two keyframes (see the header).
double relativeSigmaM(const KeyframePrior& a, const KeyframePrior& b,
                      const fusion::RelativeNoise& drift) {
  const double by_gnss = std::hypot(a.sigma_m, b.sigma_m);  // infinite without GNSS
  if (a.segment != b.segment) return by_gnss;               // no VIO path joins two drives
  return std::min(drift.positionSigmaM(std::abs(b.path_m - a.path_m)), by_gnss);
}

// 1-sigma uncertainty (deg) of their prior relative rotation: the VIO's rotation drift within a
// drive; between drives the two GNSS-fused rotation uncertainties (the heading of a short or
// straight drive is known to a few degrees only).
double relativeSigmaDeg(const KeyframePrior& a, const KeyframePrior& b,
                        const fusion::RelativeNoise& drift) {
  if (a.segment != b.segment) return std::hypot(a.sigma_rot_deg, b.sigma_rot_deg);
  return degrees(drift.rotationSigmaRad(std::abs(b.path_m - a.path_m)));
}

// A verified loop's correction of the query's prior pose in the target frame (the candidate's
// prior held): the pose the loop implies for the query against the one it had.
struct Correction {
  Eigen::Vector3d dp_w = Eigen::Vector3d::Zero();
  Eigen::Matrix3d dR_w = Eigen::Matrix3d::Identity();
};

Correction correctionOf(const KeyframePrior& cand, const KeyframePrior& query,
                        const Eigen::Isometry3d& T_cand_query) {
  const Eigen::Isometry3d implied = cand.T_ref_b * T_cand_query;
  return {implied.translation() - query.T_ref_b.translation(),
          implied.rotation() * query.T_ref_b.rotation().transpose()};
}

class Search {
 public:
  Search(const std::vector<KeyframePrior>& priors, const LoopSearchConfig& config,
         const fusion::RelativeNoise& drift, LoopPairs pairs)
      : priors_(priors),
        config_(config),
        drift_(drift),
        pairs_(pairs),
        cloud_(new pcl::PointCloud<pcl::PointXYZ>) {
    for (const KeyframePrior& p : priors) {
      const Eigen::Vector3d t = p.T_ref_b.translation();
      cloud_->push_back(pcl::PointXYZ(static_cast<float>(t.x()), static_cast<float>(t.y()),
                                      static_cast<float>(t.z())));
    }
    for (const KeyframePrior& p : priors) max_sigma_ = std::max(max_sigma_, p.sigma_m);
    segments_ = !priors.empty() && priors.front().segment != priors.back().segment;
    if (!priors.empty()) tree_.setInputCloud(cloud_);
  }

  // Older keyframes that may show the place query j shows, in index order.
  std::vector<std::size_t> candidates(std::size_t j, LoopDetection& stats) {
    const KeyframePrior& q = priors_[j];
    const double by_gnss = std::hypot(q.sigma_m, max_sigma_);
    const double widest_sigma =
        segments_ ? by_gnss
                  : std::min(drift_.positionSigmaM(q.path_m - priors_.front().path_m), by_gnss);
    // Without GNSS between drives nothing bounds the search: every keyframe is a candidate.
    const double radius =
        std::min(config_.search_radius_m + config_.search_sigmas * widest_sigma, 1e30);
    std::vector<int> found;
    std::vector<float> sq;
    tree_.radiusSearch((*cloud_)[j], radius, found, sq);
    std::sort(found.begin(), found.end());
    std::vector<std::size_t> out;
    const double min_sep_ns = config_.min_separation_s * 1e9;
    const Eigen::Vector3d f_q = q.T_ref_b.rotation().col(0);
    for (int idx : found) {
      const auto i = static_cast<std::size_t>(idx);
      if (i >= j) continue;
      if (priors_[i].segment == q.segment) {
        if (pairs_ == LoopPairs::kAcrossSegments) continue;
        if (static_cast<double>(q.t_ns - priors_[i].t_ns) < min_sep_ns) continue;
      }
      if (distance(i, j) > radiusFor(i, j)) continue;
      ++stats.pairs_in_radius;
      const double cos_heading = f_q.dot(priors_[i].T_ref_b.rotation().col(0));
      if (degrees(std::acos(std::clamp(cos_heading, -1.0, 1.0))) > config_.max_heading_deg) {
        continue;
      }
      ++stats.pairs_heading_ok;
      out.push_back(i);
    }
    return out;
  }

  [[nodiscard]] double radiusFor(std::size_t i, std::size_t j) const {
    return config_.search_radius_m +
           config_.search_sigmas * relativeSigmaM(priors_[i], priors_[j], drift_);
  }
  [[nodiscard]] double distance(std::size_t i, std::size_t j) const {
    return (priors_[i].T_ref_b.translation() - priors_[j].T_ref_b.translation()).norm();
  }

  // The loop's correction of the prior relative pose fits the prior's uncertainty.
  [[nodiscard]] bool plausible(const LoopCandidate& c) const {
    const KeyframePrior& a = priors_[c.candidate];
    const KeyframePrior& b = priors_[c.query];
    const double sigma_m = relativeSigmaM(a, b, drift_);
    const double sigma_deg = relativeSigmaDeg(a, b, drift_);
    return c.correction_m <= config_.search_sigmas * sigma_m + config_.correction_floor_m &&
           c.correction_deg <= config_.search_sigmas * sigma_deg + config_.correction_floor_deg;
  }

 private:
  const std::vector<KeyframePrior>& priors_;
  const LoopSearchConfig& config_;
  const fusion::RelativeNoise& drift_;
  LoopPairs pairs_;
  bool segments_ = false;  // keyframes of more than one drive
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud_;
  pcl::KdTreeFLANN<pcl::PointXYZ> tree_;
  double max_sigma_ = 0.0;
};

// Marks the best plausible loop of each query accepted when enough neighbouring queries agree on
// the correction; the others say why not.
void checkConsistency(std::vector<LoopCandidate>& candidates,
                      const std::vector<std::optional<Correction>>& corrections,
                      const std::vector<std::size_t>& best, const LoopSearchConfig& c) {
  for (std::size_t a : best) {
    const std::size_t qa = candidates[a].query;
    int agreeing = 1;
    for (std::size_t b : best) {
      const std::size_t qb = candidates[b].query;
      if (b == a ||
          (qa > qb ? qa - qb : qb - qa) > static_cast<std::size_t>(c.consistency_window)) {
        continue;
      }
      const Correction& ca = *corrections[a];
      const Correction& cb = *corrections[b];
      if ((ca.dp_w - cb.dp_w).norm() <= c.consistency_m &&
          angleDeg(ca.dR_w * cb.dR_w.transpose()) <= c.consistency_deg) {
        ++agreeing;
      }
    }
    const bool ok = agreeing >= c.consistent_keyframes;
    candidates[a].accepted = ok;
    candidates[a].reason = ok ? "ok" : "inconsistent";
  }
}

}  // namespace

void LoopSearchConfig::validate() const {
  const auto nonneg = [](double v) { return std::isfinite(v) && v >= 0.0; };
  if (!nonneg(min_separation_s)) throw InvalidInput("config: loops.min_separation_s must be >= 0");
  if (!(max_heading_deg > 0.0 && max_heading_deg <= 180.0)) {
    throw InvalidInput("config: loops.max_heading_deg must be in (0, 180]");
  }
  if (!(nonneg(search_radius_m) && search_radius_m > 0.0)) {
    throw InvalidInput("config: loops.search_radius_m must be > 0");
  }
  if (!nonneg(search_sigmas)) throw InvalidInput("config: loops.search_sigmas must be >= 0");
  if (max_candidates < 1) throw InvalidInput("config: loops.max_candidates must be >= 1");
  if (!nonneg(correction_floor_m)) {
    throw InvalidInput("config: loops.correction_floor_m must be >= 0");
  }
  if (!nonneg(correction_floor_deg)) {
    throw InvalidInput("config: loops.correction_floor_deg must be >= 0");
  }
  if (consistent_keyframes < 1) {
    throw InvalidInput("config: loops.consistent_keyframes must be >= 1");
  }
  if (consistency_window < 1) throw InvalidInput("config: loops.consistency_window must be >= 1");
  if (!nonneg(consistency_m)) throw InvalidInput("config: loops.consistency_m must be >= 0");
  if (!nonneg(consistency_deg)) throw InvalidInput("config: loops.consistency_deg must be >= 0");
}

void LoopConfig::validate() const {
  features.validate();
  match.validate();
  search.validate();
  if (!(std::isfinite(sigma_floor_m) && sigma_floor_m > 0.0)) {
    throw InvalidInput("config: loops.sigma_floor_m must be > 0");
  }
  if (!(std::isfinite(sigma_floor_deg) && sigma_floor_deg > 0.0)) {
    throw InvalidInput("config: loops.sigma_floor_deg must be > 0");
  }
}

LoopDetection detectLoops(const std::vector<LoopKeyframe>& keyframes,
                          const std::vector<KeyframePrior>& priors, const CameraModel& camera,
                          const LoopConfig& config, const fusion::RelativeNoise& drift,
                          LoopPairs pairs) {
  config.validate();
  if (keyframes.size() != priors.size()) {
    throw InvalidInput("loop detection: keyframes and priors differ in number");
  }
  LoopDetection out;
  if (priors.empty()) return out;
  for (std::size_t k = 1; k < priors.size(); ++k) {
    if (priors[k].segment < priors[k - 1].segment) {
      throw InvalidInput("loop detection: keyframes must be grouped by segment");
    }
  }
  Search search(priors, config.search, drift, pairs);
  std::vector<std::optional<Correction>> corrections;
  std::vector<std::size_t> best;  // per query with a plausible loop: its best candidate
  for (std::size_t j = 0; j < keyframes.size(); ++j) {
    const auto start = std::chrono::steady_clock::now();
    std::vector<std::size_t> cands = search.candidates(j, out);
    std::vector<std::pair<float, std::size_t>> ranked;
    for (std::size_t i : cands)
      ranked.emplace_back(thumbnailSimilarity(keyframes[j], keyframes[i]), i);
    std::sort(ranked.begin(), ranked.end(), [](const auto& a, const auto& b) {
      return a.first > b.first || (a.first == b.first && a.second < b.second);
    });
    if (ranked.size() > static_cast<std::size_t>(config.search.max_candidates)) {
      ranked.resize(static_cast<std::size_t>(config.search.max_candidates));
    }
    std::optional<std::size_t> query_best;
    for (const auto& [similarity, i] : ranked) {
      LoopCandidate c;
      c.query = j;
      c.candidate = i;
      c.distance_m = search.distance(i, j);
      c.radius_m = search.radiusFor(i, j);
      c.similarity = similarity;
      c.measurement = verifyLoop(keyframes[j], keyframes[i], camera, config.match);
      c.correction_m = c.correction_deg = kNaN;
      std::optional<Correction> corr;
      if (c.measurement.check != LoopCheck::kOk) {
        c.reason = toString(c.measurement.check);
      } else {
        const Eigen::Isometry3d prior_rel = priors[i].T_ref_b.inverse() * priors[j].T_ref_b;
        const Eigen::Isometry3d delta = prior_rel.inverse() * c.measurement.T_cand_query;
        c.correction_m = delta.translation().norm();
        c.correction_deg = angleDeg(delta.rotation());
        c.reason = search.plausible(c) ? "" : "implausible";
        if (c.reason.empty()) corr = correctionOf(priors[i], priors[j], c.measurement.T_cand_query);
      }
      const std::size_t index = out.candidates.size();
      out.candidates.push_back(c);
      corrections.push_back(corr);
      if (!corr) continue;
      if (!query_best || out.candidates[*query_best].measurement.inliers < c.measurement.inliers) {
        if (query_best) out.candidates[*query_best].reason = "superseded";
        query_best = index;
      } else {
        out.candidates[index].reason = "superseded";
      }
    }
    if (query_best) best.push_back(*query_best);
    out.ms_per_keyframe.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count());
  }
  checkConsistency(out.candidates, corrections, best, config.search);
  return out;
}

std::vector<fusion::GraphLoop> acceptedGraphLoops(const LoopDetection& detection,
                                                  const LoopConfig& config,
                                                  std::vector<std::size_t>& index_out) {
  std::vector<fusion::GraphLoop> loops;
  index_out.clear();
  const double rot = config.sigma_floor_deg * std::numbers::pi / 180.0;
  Matrix6d floor = Matrix6d::Zero();
  floor.diagonal() << rot * rot, rot * rot, rot * rot, config.sigma_floor_m * config.sigma_floor_m,
      config.sigma_floor_m * config.sigma_floor_m, config.sigma_floor_m * config.sigma_floor_m;
  for (std::size_t k = 0; k < detection.candidates.size(); ++k) {
    const LoopCandidate& c = detection.candidates[k];
    if (!c.accepted) continue;
    fusion::GraphLoop loop;
    loop.i = c.candidate;
    loop.j = c.query;
    loop.T_i_j = c.measurement.T_cand_query;
    loop.covariance = c.measurement.covariance + floor;
    loops.push_back(loop);
    index_out.push_back(k);
  }
  return loops;
}

}  // namespace gvio::mapping
