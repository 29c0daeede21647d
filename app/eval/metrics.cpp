#include "eval/metrics.hpp"

#include <fmt/format.h>

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numeric>
#include <utility>

#include "io/text.hpp"
#include "odometry/error.hpp"

namespace gvio::eval {

Alignment parseAlignment(const std::string& name) {
  if (name == "none") return Alignment::kNone;
  if (name == "se3") return Alignment::kSe3;
  if (name == "sim3") return Alignment::kSim3;
  if (name == "origin") return Alignment::kOrigin;
  throw InvalidInput("--align: expected none, se3, sim3 or origin (got '" + name + "')");
}

Relation parseRelation(const std::string& name) {
  if (name == "trans") return Relation::kTranslation;
  if (name == "full") return Relation::kFull;
  if (name == "angle_deg") return Relation::kAngleDeg;
  throw InvalidInput("--relation: expected trans, full or angle_deg (got '" + name + "')");
}

DeltaUnit parseDeltaUnit(const std::string& name) {
  if (name == "frames") return DeltaUnit::kFrames;
  if (name == "m") return DeltaUnit::kMeters;
  throw InvalidInput("--rpe-unit: expected frames or m (got '" + name + "')");
}

std::string describe(Relation relation) {
  switch (relation) {
    case Relation::kTranslation:
      return "translation part (m)";
    case Relation::kFull:
      return "full transformation (unit-less)";
    case Relation::kAngleDeg:
      return "rotation angle in degrees (deg)";
  }
  return "";
}

Stats computeStats(const std::vector<double>& errors) {
  if (errors.empty()) throw InvalidInput("no errors to compute statistics of");
  Stats s;
  s.n = errors.size();
  const double n = static_cast<double>(s.n);
  s.sse = std::inner_product(errors.begin(), errors.end(), errors.begin(), 0.0);
  s.mean = std::accumulate(errors.begin(), errors.end(), 0.0) / n;
  s.rmse = std::sqrt(s.sse / n);
  double var = 0.0;
  for (const double e : errors) var += (e - s.mean) * (e - s.mean);
  s.std = std::sqrt(var / n);  // numpy.std: population (ddof = 0)
  std::vector<double> sorted = errors;
  std::sort(sorted.begin(), sorted.end());
  s.min = sorted.front();
  s.max = sorted.back();
  const std::size_t mid = s.n / 2;
  s.median = s.n % 2 == 1 ? sorted[mid] : 0.5 * (sorted[mid - 1] + sorted[mid]);
  return s;
}

namespace {

// The first index of the smallest |b[j] - target| (numpy argmin) when b does not decrease: a
// binary search, then the first of a run of equal stamps.
std::pair<std::size_t, std::int64_t> nearestSorted(const std::vector<std::int64_t>& b,
                                                   std::int64_t target) {
  const auto it = std::lower_bound(b.begin(), b.end(), target);  // the first of equals
  std::size_t best = 0;
  std::int64_t best_diff = std::numeric_limits<std::int64_t>::max();
  if (it != b.end()) {
    best = static_cast<std::size_t>(it - b.begin());
    best_diff = *it - target;
  }
  if (it != b.begin() && target - *(it - 1) <= best_diff) {  // ties go to the lower index
    const auto first = std::lower_bound(b.begin(), it, *(it - 1));
    best = static_cast<std::size_t>(first - b.begin());
    best_diff = target - *(it - 1);
  }
  return {best, best_diff};
}

// A stamp as evo holds it: the double nearest to its decimal seconds (what numpy parses from the
// file's text), not the double nearest to the nanoseconds / 1e9.
double evoSeconds(std::int64_t t_ns) {
  return std::strtod(io::formatSeconds(t_ns).c_str(), nullptr);
}

// The first index of runs of equal stamps next to b[best] (below and above), for re-ranking.
std::vector<std::size_t> neighbours(const std::vector<std::int64_t>& b, std::size_t best) {
  std::vector<std::size_t> out{best};
  if (best > 0) {
    const auto below = std::lower_bound(b.begin(), b.end(), b[best - 1]);
    out.push_back(static_cast<std::size_t>(below - b.begin()));
  }
  const auto above = std::upper_bound(b.begin(), b.end(), b[best]);
  if (above != b.end()) out.push_back(static_cast<std::size_t>(above - b.begin()));
  std::sort(out.begin(), out.end());
  return out;
}

// evo sync.matching_time_indices: for each stamp of `a`, the index of the nearest stamp of
// `b + offset` (numpy argmin: the first of equals), kept when |dt| <= max_diff. evo computes
// |(b + offset) - a| in float64 seconds, so where two stamps of b lie equally far from a's in
// exact nanoseconds (a 10 Hz estimate halfway between 5 Hz reference stamps), rounding decides:
// the exact search finds the nearest stamps, and those within a microsecond of the nearest are
// ranked, and the tolerance applied, by evo's float64 arithmetic.
void matchNearest(const std::vector<std::int64_t>& a, const std::vector<std::int64_t>& b,
                  std::int64_t max_diff_ns, std::int64_t offset_b_ns, std::vector<std::size_t>& ia,
                  std::vector<std::size_t>& ib) {
  constexpr std::int64_t kRerankNs = 1000;
  const bool sorted = std::is_sorted(b.begin(), b.end());
  const double offset_s = offset_b_ns >= 0 ? evoSeconds(offset_b_ns) : -evoSeconds(-offset_b_ns);
  const double max_diff_s = static_cast<double>(max_diff_ns) / 1e9;
  if (!sorted) {  // evo's scan, literally: every stamp of b in float64
    std::vector<double> b_s(b.size());
    for (std::size_t j = 0; j < b.size(); ++j) b_s[j] = evoSeconds(b[j]) + offset_s;
    for (std::size_t i = 0; i < a.size(); ++i) {
      const double a_s = evoSeconds(a[i]);
      std::size_t best = 0;
      for (std::size_t j = 1; j < b.size(); ++j) {
        if (std::abs(b_s[j] - a_s) < std::abs(b_s[best] - a_s)) best = j;
      }
      if (!b.empty() && std::abs(b_s[best] - a_s) <= max_diff_s) {
        ia.push_back(i);
        ib.push_back(best);
      }
    }
    return;
  }
  for (std::size_t i = 0; i < a.size(); ++i) {
    const std::int64_t target = a[i] - offset_b_ns;  // b[j] + offset ~ a[i]
    const auto [best, best_diff] = nearestSorted(b, target);
    if (best_diff > max_diff_ns + kRerankNs) continue;
    const double a_s = evoSeconds(a[i]);
    std::size_t chosen = best;
    double chosen_diff = std::numeric_limits<double>::infinity();
    for (const std::size_t j : neighbours(b, best)) {
      const std::int64_t exact = b[j] > target ? b[j] - target : target - b[j];
      if (exact > best_diff + kRerankNs) continue;
      const double diff = std::abs((evoSeconds(b[j]) + offset_s) - a_s);
      if (diff < chosen_diff) {
        chosen = j;
        chosen_diff = diff;
      }
    }
    if (chosen_diff <= max_diff_s) {
      ia.push_back(i);
      ib.push_back(chosen);
    }
  }
}

}  // namespace

Association associateByTime(const std::vector<std::int64_t>& ref_t_ns,
                            const std::vector<std::int64_t>& est_t_ns, std::int64_t max_diff_ns,
                            std::int64_t est_offset_ns) {
  Association a;
  // evo iterates over the shorter trajectory (the estimate when lengths are equal).
  if (est_t_ns.size() > ref_t_ns.size()) {
    matchNearest(ref_t_ns, est_t_ns, max_diff_ns, est_offset_ns, a.ref, a.est);
  } else {
    matchNearest(est_t_ns, ref_t_ns, max_diff_ns, -est_offset_ns, a.est, a.ref);
  }
  return a;
}

Sim3 umeyama(const std::vector<Eigen::Vector3d>& x, const std::vector<Eigen::Vector3d>& y,
             bool with_scale) {
  if (x.size() != y.size() || x.empty()) throw InvalidInput("umeyama: point sets differ in size");
  const double n = static_cast<double>(x.size());
  Eigen::Vector3d mean_x = Eigen::Vector3d::Zero(), mean_y = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < x.size(); ++i) {
    mean_x += x[i];
    mean_y += y[i];
  }
  mean_x /= n;
  mean_y /= n;
  double sigma_x = 0.0;                           // eq. 36
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();  // eq. 38
  for (std::size_t i = 0; i < x.size(); ++i) {
    sigma_x += (x[i] - mean_x).squaredNorm();
    cov += (y[i] - mean_y) * (x[i] - mean_x).transpose();
  }
  sigma_x /= n;
  cov /= n;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d d = svd.singularValues();
  const auto rank = (d.array() > std::numeric_limits<double>::epsilon()).count();
  if (rank < 2) {
    throw InvalidInput(fmt::format(
        "degenerate alignment: the {} associated positions are collinear or coincident", x.size()));
  }
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();  // eq. 43
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) S(2, 2) = -1.0;
  Sim3 T;
  T.R = svd.matrixU() * S * svd.matrixV().transpose();              // eq. 40
  T.s = with_scale ? (d.asDiagonal() * S).trace() / sigma_x : 1.0;  // eq. 42
  T.t = mean_y - T.s * T.R * mean_x;                                // eq. 41
  return T;
}

Eigen::Matrix4d relativeSe3(const Eigen::Matrix4d& a, const Eigen::Matrix4d& b) {
  Eigen::Matrix4d a_inv = Eigen::Matrix4d::Identity();
  a_inv.topLeftCorner<3, 3>() = a.topLeftCorner<3, 3>().transpose();
  a_inv.topRightCorner<3, 1>() = -a.topLeftCorner<3, 3>().transpose() * a.topRightCorner<3, 1>();
  return a_inv * b;
}

double rotationAngleRad(const Eigen::Matrix3d& m) {
  // scipy Rotation.from_matrix (Markley 2008 quaternion extraction), then as_rotvec's angle
  // 2 atan2(|xyz|, |w|); the quaternion need not be normalised for the ratio.
  const double trace = m.trace();
  const double decision[4] = {m(0, 0), m(1, 1), m(2, 2), trace};
  const int choice = static_cast<int>(std::max_element(decision, decision + 4) - decision);
  Eigen::Vector4d q;  // x y z w
  if (choice != 3) {
    const int i = choice, j = (i + 1) % 3, k = (j + 1) % 3;
    q[i] = 1.0 - trace + 2.0 * m(i, i);
    q[j] = m(j, i) + m(i, j);
    q[k] = m(k, i) + m(i, k);
    q[3] = m(k, j) - m(j, k);
  } else {
    q[0] = m(2, 1) - m(1, 2);
    q[1] = m(0, 2) - m(2, 0);
    q[2] = m(1, 0) - m(0, 1);
    q[3] = 1.0 + trace;
  }
  return 2.0 * std::atan2(q.head<3>().norm(), std::abs(q[3]));
}

namespace {

double poseError(const Eigen::Matrix4d& E, Relation relation) {
  switch (relation) {
    case Relation::kTranslation:
      return E.topRightCorner<3, 1>().norm();
    case Relation::kFull:
      return (E - Eigen::Matrix4d::Identity()).norm();  // Frobenius
    case Relation::kAngleDeg:
      return rotationAngleRad(E.topLeftCorner<3, 3>()) * 180.0 / M_PI;
  }
  return 0.0;
}

}  // namespace

std::vector<double> apeErrors(const std::vector<Eigen::Matrix4d>& ref,
                              const std::vector<Eigen::Matrix4d>& est, Relation relation) {
  std::vector<double> errors(ref.size());
  for (std::size_t i = 0; i < ref.size(); ++i) {
    if (relation == Relation::kTranslation) {
      // evo: |p_est - p_ref| directly (no SE(3) product).
      errors[i] = (est[i].topRightCorner<3, 1>() - ref[i].topRightCorner<3, 1>()).norm();
    } else {
      errors[i] = poseError(relativeSe3(est[i], ref[i]), relation);  // evo APE.ape_base
    }
  }
  return errors;
}

std::vector<std::pair<std::size_t, std::size_t>> rpePairs(const std::vector<Eigen::Matrix4d>& poses,
                                                          double delta, DeltaUnit unit) {
  std::vector<std::size_t> ids;
  if (unit == DeltaUnit::kFrames) {
    const auto step = static_cast<std::size_t>(delta);
    if (step < 1 || static_cast<double>(step) != delta) {
      throw InvalidInput("--rpe-delta in frames must be a positive integer");
    }
    for (std::size_t i = 0; i < poses.size(); i += step) ids.push_back(i);
  } else {
    if (!(delta > 0.0)) throw InvalidInput("--rpe-delta in metres must be positive");
    double path = 0.0;  // evo accumulates from pose 0 and restarts at each accepted index
    for (std::size_t i = 0; i < poses.size(); ++i) {
      if (i > 0)
        path += (poses[i].topRightCorner<3, 1>() - poses[i - 1].topRightCorner<3, 1>()).norm();
      if (path >= delta) {
        ids.push_back(i);
        path = 0.0;
      }
    }
  }
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  for (std::size_t k = 1; k < ids.size(); ++k) pairs.emplace_back(ids[k - 1], ids[k]);
  if (pairs.empty()) {
    throw InvalidInput(fmt::format("--rpe-delta {} {} leaves no pose pair: use a smaller delta",
                                   delta, unit == DeltaUnit::kFrames ? "frames" : "m"));
  }
  return pairs;
}

std::vector<double> rpeErrors(const std::vector<Eigen::Matrix4d>& ref,
                              const std::vector<Eigen::Matrix4d>& est,
                              const std::vector<std::pair<std::size_t, std::size_t>>& pairs,
                              Relation relation) {
  std::vector<double> errors;
  errors.reserve(pairs.size());
  for (const auto& [i, j] : pairs) {
    // evo RPE.rpe_base (TUM RGB-D benchmark, Sturm et al. 2012, eq. 1)
    const Eigen::Matrix4d E = relativeSe3(relativeSe3(ref[i], ref[j]), relativeSe3(est[i], est[j]));
    errors.push_back(poseError(E, relation));
  }
  return errors;
}

}  // namespace gvio::eval
