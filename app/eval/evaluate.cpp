#include "eval/evaluate.hpp"

#include <fmt/format.h>

#include "odometry/error.hpp"

namespace gvio::eval {
namespace {

constexpr std::size_t kMinPoses = 3;

void associate(const Trajectory& ref, const Trajectory& est, const EvalOptions& opt,
               EvalResult& r) {
  r.paired_by_index = !ref.hasTimestamps() || !est.hasTimestamps();
  Association a;
  if (r.paired_by_index) {
    if (ref.size() != est.size()) {
      throw InvalidInput(fmt::format(
          "reference has {} poses and estimate {}: without timestamps on both sides poses pair by "
          "index, so the counts must match (give --ref-times/--est-times to associate by time)",
          ref.size(), est.size()));
    }
    for (std::size_t i = 0; i < ref.size(); ++i) {
      a.ref.push_back(i);
      a.est.push_back(i);
    }
  } else {
    a = associateByTime(ref.t_ns, est.t_ns, opt.t_max_diff_ns, opt.t_offset_ns);
  }
  if (a.ref.size() < kMinPoses) {
    throw InvalidInput(fmt::format(
        "only {} associated poses (need at least {}); check --t-max-diff ({} s) and --t-offset",
        a.ref.size(), kMinPoses, 1e-9 * static_cast<double>(opt.t_max_diff_ns)));
  }
  for (std::size_t k = 0; k < a.ref.size(); ++k) {
    r.ref.push_back(ref.poses[a.ref[k]].matrix());
    r.est.push_back(est.poses[a.est[k]].matrix());
    r.est_index.push_back(a.est[k]);
    if (ref.hasTimestamps()) r.t_ns.push_back(ref.t_ns[a.ref[k]]);
  }
}

// evo PosePath3D.align / align_origin: the estimate is moved, never the reference.
void align(const EvalOptions& opt, EvalResult& r) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  double s = 1.0;
  if (opt.align == Alignment::kSe3 || opt.align == Alignment::kSim3) {
    std::vector<Eigen::Vector3d> x, y;
    for (std::size_t i = 0; i < r.ref.size(); ++i) {
      x.emplace_back(r.est[i].topRightCorner<3, 1>());
      y.emplace_back(r.ref[i].topRightCorner<3, 1>());
    }
    r.alignment = umeyama(x, y, opt.align == Alignment::kSim3);
    s = r.alignment.s;
    T.topLeftCorner<3, 3>() = r.alignment.R;
    T.topRightCorner<3, 1>() = r.alignment.t;
  } else if (opt.align == Alignment::kOrigin) {
    T = r.ref.front() * relativeSe3(r.est.front(), Eigen::Matrix4d::Identity());
    r.alignment.R = T.topLeftCorner<3, 3>();
    r.alignment.t = T.topRightCorner<3, 1>();
  }
  for (auto& P : r.est) {
    P.topRightCorner<3, 1>() *= s;  // evo scales positions first, then transforms
    P = (T * P).eval();
  }
}

}  // namespace

EvalResult evaluate(const Trajectory& ref, const Trajectory& est, const EvalOptions& opt) {
  EvalResult r;
  r.ref_poses = ref.size();
  r.est_poses = est.size();
  associate(ref, est, opt, r);
  align(opt, r);
  r.ape = apeErrors(r.ref, r.est, opt.relation);
  r.ape_stats = computeStats(r.ape);
  if (opt.rpe_delta) {
    RpeResult rpe;
    rpe.pairs = rpePairs(r.est, *opt.rpe_delta, opt.rpe_unit);  // evo picks pairs on the estimate
    rpe.errors = rpeErrors(r.ref, r.est, rpe.pairs, opt.relation);
    rpe.stats = computeStats(rpe.errors);
    r.rpe = std::move(rpe);
  }
  return r;
}

}  // namespace gvio::eval
