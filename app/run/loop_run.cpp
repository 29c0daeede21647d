#include "run/loop_run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <unordered_map>

#include <Eigen/Eigenvalues>

#include "fusion/gnss_smoother.hpp"
#include "fusion/vio_enu_alignment.hpp"
#include "odometry/error.hpp"
#include "run/stats.hpp"

namespace gvio::run {
namespace {

using Clock = std::chrono::steady_clock;
constexpr double kInfinity = std::numeric_limits<double>::infinity();

// The 1-sigma uncertainty of a 3x3 block: the square root of its largest eigenvalue (the radius
// that covers every direction).
double largestSigma(const Eigen::Matrix3d& block) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(block);
  return std::sqrt(std::max(es.eigenvalues().maxCoeff(), 0.0));
}

// What the run knew of each keyframe before the loops: the smoothed GNSS-fused pose with its
// covariance (graph mode), else the VIO pose with the drift bound alone (pure VIO, and the kf
// mode, whose filter states no covariance of its output).
std::vector<mapping::KeyframePrior> keyframePriors(const LoopRecorder& recorder,
                                                   const GnssRunResult* gnss) {
  const auto& T_w_b = recorder.vioPoses();
  const auto& frames = recorder.keyframes();
  const bool fused = gnss != nullptr && !gnss->fused_covariance.empty() &&
                     gnss->fused_covariance.size() == gnss->fused.size();
  std::vector<mapping::KeyframePrior> priors(frames.size());
  for (std::size_t k = 0; k < frames.size(); ++k) {
    mapping::KeyframePrior& p = priors[k];
    p.t_ns = frames[k].t_ns;
    p.path_m = k == 0 ? 0.0
                      : priors[k - 1].path_m +
                            (T_w_b[k].translation() - T_w_b[k - 1].translation()).norm();
    p.T_ref_b = T_w_b[k];
    p.sigma_m = kInfinity;
    if (!fused) continue;
    const auto it = std::lower_bound(gnss->fused.t_ns.begin(), gnss->fused.t_ns.end(), p.t_ns);
    if (it == gnss->fused.t_ns.end() || *it != p.t_ns) continue;
    const auto i = static_cast<std::size_t>(it - gnss->fused.t_ns.begin());
    p.T_ref_b = gnss->fused.poses[i];
    p.sigma_m = largestSigma(gnss->fused_covariance[i].bottomRightCorner<3, 3>());
    p.sigma_rot_deg =
        largestSigma(gnss->fused_covariance[i].topLeftCorner<3, 3>()) * 180.0 / std::numbers::pi;
  }
  // A keyframe without a fused pose would mix frames: then every prior stays in the VIO world.
  if (fused && std::any_of(priors.begin(), priors.end(),
                           [](const mapping::KeyframePrior& p) { return std::isinf(p.sigma_m); })) {
    for (std::size_t k = 0; k < priors.size(); ++k) {
      priors[k].T_ref_b = T_w_b[k];
      priors[k].sigma_m = kInfinity;
      priors[k].sigma_rot_deg = kInfinity;
    }
  }
  return priors;
}

std::vector<fusion::GraphNode> graphNodes(const LoopRecorder& recorder, const GnssRunResult* gnss) {
  std::vector<fusion::GraphNode> nodes(recorder.keyframes().size());
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    nodes[k].t_ns = recorder.keyframes()[k].t_ns;
    nodes[k].T_w_b = recorder.vioPoses()[k];
    nodes[k].T_init = nodes[k].T_w_b;
    if (gnss == nullptr) continue;
    const auto fused = fusion::interpolatePose(gnss->fused, nodes[k].t_ns);
    nodes[k].T_init = fused ? *fused : Eigen::Isometry3d(*gnss->T_enu_w * nodes[k].T_w_b);
  }
  return nodes;
}

// The fusion's used fixes, each on the keyframe nearest in time with the lever arm carried there
// by the VIO motion.
std::vector<fusion::GraphFix> graphFixes(const std::vector<fusion::GraphNode>& nodes,
                                         const Trajectory& vio, const GnssRunResult& gnss,
                                         const Eigen::Vector3d& lever_arm_b) {
  std::vector<fusion::GraphFix> fixes;
  for (const fusion::FixOutcome& f : gnss.stats.fixes) {
    if (f.status != fusion::FixStatus::kUsed || !(f.sigma_h_m > 0.0 && f.sigma_v_m > 0.0)) continue;
    const auto T_w_b = fusion::interpolatePose(vio, f.t_ns);
    if (!T_w_b) continue;
    const auto it =
        std::lower_bound(nodes.begin(), nodes.end(), f.t_ns,
                         [](const fusion::GraphNode& n, std::int64_t t) { return n.t_ns < t; });
    std::size_t k = static_cast<std::size_t>(it - nodes.begin());
    if (k == nodes.size() || (k > 0 && f.t_ns - nodes[k - 1].t_ns < nodes[k].t_ns - f.t_ns)) --k;
    fusion::GraphFix g;
    g.node = k;
    g.t_ns = f.t_ns;
    g.q_b = nodes[k].T_w_b.inverse() * (*T_w_b * lever_arm_b);
    g.p_enu = f.p_enu;
    g.sigma_h_m = f.sigma_h_m;
    g.sigma_v_m = f.sigma_v_m;
    g.quality = f.quality;
    g.shape_en = f.shape_en;
    fixes.push_back(g);
  }
  return fixes;
}

std::vector<io::LoopCsvRow> csvRows(const mapping::LoopDetection& detection,
                                    const LoopRecorder& recorder) {
  std::vector<io::LoopCsvRow> rows;
  rows.reserve(detection.candidates.size());
  for (const mapping::LoopCandidate& c : detection.candidates) {
    io::LoopCsvRow r;
    r.query_t_ns = recorder.keyframes()[c.query].t_ns;
    r.candidate_t_ns = recorder.keyframes()[c.candidate].t_ns;
    r.distance_m = c.distance_m;
    r.search_radius_m = c.radius_m;
    r.matches = c.measurement.matches;
    r.inliers = c.measurement.inliers;
    r.reprojection_px = c.measurement.reprojection_px;
    r.correction_m = c.correction_m;
    r.correction_deg = c.correction_deg;
    r.accepted = c.accepted;
    r.reason = c.reason;
    rows.push_back(r);
  }
  return rows;
}

// The front end's corners of the keyframe with their 3-D points in the left camera: the stereo
// match's depth (stereo rigs), else the window landmark's estimate (mono).
std::vector<mapping::LoopPointInput> loopPoints(const KeyframeInput& kf) {
  const CameraModel& cam = kf.left_camera;
  std::unordered_map<std::uint64_t, Eigen::Vector3d> landmark_c;
  if (!(kf.baseline_m > 0.0)) {
    const Eigen::Isometry3d T_c_w = (kf.T_w_b * cam.T_b_c).inverse();
    for (const odometry::LandmarkEstimate& lm : kf.landmarks) {
      landmark_c.emplace(lm.id, T_c_w * lm.p_w);
    }
  }
  std::vector<mapping::LoopPointInput> points;
  const std::vector<odometry::Feature>& features = kf.features;
  points.reserve(features.size());
  for (const odometry::Feature& f : features) {
    mapping::LoopPointInput p;
    p.px = f.px_left;
    const double disparity = f.px_left.x() - f.px_right.x();
    if (kf.baseline_m > 0.0 && f.has_right && disparity > 0.0) {
      const double z = cam.fx * kf.baseline_m / disparity;
      p.p_c = Eigen::Vector3d((f.px_left.x() - cam.cx) * z / cam.fx,
                              (f.px_left.y() - cam.cy) * z / cam.fy, z);
      p.has_point = true;
    } else if (const auto it = landmark_c.find(f.id); it != landmark_c.end()) {
      p.p_c = it->second;
      p.has_point = true;
    }
    points.push_back(p);
  }
  return points;
}

nlohmann::json summaryJson(const std::vector<double>& samples) {
  const TimingSummary s = summarizeTimings(samples);
  return {{"mean", s.mean}, {"p95", s.p95}, {"max", s.max}, {"n", samples.size()}};
}

}  // namespace

void LoopStageConfig::validate() const {
  detection.validate();
  if (!(std::isfinite(graph_tilt_sigma_deg) && graph_tilt_sigma_deg > 0.0)) {
    throw InvalidInput("config: loops.graph_tilt_sigma_deg must be > 0");
  }
  graphConfig(fusion::FusionConfig{}).validate();
}

fusion::GlobalGraphConfig LoopStageConfig::graphConfig(const fusion::FusionConfig& fusion) const {
  fusion::GlobalGraphConfig g;
  g.vio = fusion.relativeNoise();
  g.huber_sigmas = fusion.huber_sigmas;
  g.bias_ratio = fusion.smoother.bias_ratio;
  g.bias_tau_s = fusion.smoother.bias_tau_s;
  g.tilt_sigma_rad = graph_tilt_sigma_deg * std::numbers::pi / 180.0;
  g.loop_chi2 = graph_chi2;
  g.max_rounds = graph_max_rounds;
  g.max_iterations = graph_max_iterations;
  return g;
}

LoopRecorder::LoopRecorder(const mapping::LoopFeatureConfig& config) : config_(config) {
  config_.validate();
}

void LoopRecorder::addKeyframe(const KeyframeInput& kf) {
  const auto start = Clock::now();
  if (keyframes_.empty()) camera_ = kf.left_camera;
  keyframes_.push_back(mapping::makeLoopKeyframe(kf.t_ns, kf.left, loopPoints(kf), config_));
  T_w_b_.push_back(kf.T_w_b);
  ms_features_.push_back(msSince(start));
}

std::size_t LoopRecorder::memoryBytes() const {
  std::size_t bytes = T_w_b_.capacity() * sizeof(Eigen::Isometry3d);
  for (const auto& k : keyframes_) bytes += k.memoryBytes();
  return bytes;
}

void LoopRecorder::release() {
  std::vector<mapping::LoopKeyframe>().swap(keyframes_);
}

LoopRunResult closeLoops(const LoopRecorder& recorder, const Trajectory& vio,
                         const GnssRunResult* gnss, bool has_imu, const LoopStageConfig& config,
                         const fusion::FusionConfig& fusion) {
  LoopRunResult r;
  const bool georeferenced = gnss != nullptr && gnss->T_enu_w && !gnss->fused.empty();
  if (!georeferenced) gnss = nullptr;
  r.frame = georeferenced ? "enu" : "vio_world";
  r.records_bytes = recorder.memoryBytes();
  r.ms_features = recorder.msFeatures();
  if (recorder.empty() || vio.empty()) return r;
  const auto start = Clock::now();
  r.detection = mapping::detectLoops(recorder.keyframes(), keyframePriors(recorder, gnss),
                                     recorder.camera(), config.detection, fusion.relativeNoise());
  r.ms_detection_total = msSince(start);
  std::vector<std::size_t> loop_candidate;
  const std::vector<fusion::GraphLoop> loops =
      mapping::acceptedGraphLoops(r.detection, config.detection, loop_candidate);
  r.rows = csvRows(r.detection, recorder);
  if (loops.empty()) return r;  // nothing to close: the earlier stages' trajectory stands
  const std::vector<fusion::GraphNode> nodes = graphNodes(recorder, gnss);
  const std::vector<fusion::GraphFix> fixes =
      gnss ? graphFixes(nodes, vio, *gnss, fusion.lever_arm_b) : std::vector<fusion::GraphFix>{};
  r.graph_fixes = fixes.size();
  r.graph = fusion::solveGlobalGraph(nodes, fixes, loops, has_imu, config.graphConfig(fusion));
  bool any_active = false;
  for (std::size_t k = 0; k < loops.size(); ++k) {
    any_active = any_active || r.graph.loops[k].active;
    if (r.graph.loops[k].active) continue;
    mapping::LoopCandidate& c = r.detection.candidates[loop_candidate[k]];
    c.accepted = false;
    c.reason = "graph_outlier";
  }
  r.rows = csvRows(r.detection, recorder);
  if (!any_active) return r;
  std::vector<fusion::SmootherFix> spread_nodes(nodes.size());
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    spread_nodes[k].t_ns = nodes[k].t_ns;
    spread_nodes[k].T_w_b = nodes[k].T_w_b;
  }
  fusion::SmoothedNodes solved;
  solved.T_enu_b = r.graph.T;
  r.trajectory = fusion::spreadOverVio(vio, spread_nodes, solved);
  return r;
}

std::optional<mapping::PlaceDatabase> placeDatabase(LoopRecorder& recorder, const Trajectory& vio,
                                                    const Trajectory& final_enu,
                                                    const GnssRunResult& gnss,
                                                    const LoopRunResult* loops, bool has_imu,
                                                    const LoopStageConfig& config,
                                                    const fusion::FusionConfig& fusion) {
  if (!gnss.T_enu_w || gnss.fused.empty() || recorder.empty() || vio.empty()) return std::nullopt;
  mapping::PlaceDatabase db;
  db.camera = recorder.camera();
  db.has_imu = has_imu;
  db.priors = keyframePriors(recorder, &gnss);
  db.T_vio = recorder.vioPoses();
  for (mapping::KeyframePrior& p : db.priors) {
    const auto T = fusion::interpolatePose(final_enu, p.t_ns);
    if (!T) return std::nullopt;  // a keyframe outside the final trajectory: not the map's poses
    p.T_ref_b = *T;
  }
  db.fixes = graphFixes(graphNodes(recorder, &gnss), vio, gnss, fusion.lever_arm_b);
  if (loops != nullptr) {
    std::vector<std::size_t> index;
    db.loops = mapping::acceptedGraphLoops(loops->detection, config.detection, index);
  }
  db.keyframes = recorder.takeKeyframes();
  return db;
}

nlohmann::json loopsReport(const LoopRunResult& r) {
  std::map<std::string, int> reasons;
  int accepted = 0;
  for (const mapping::LoopCandidate& c : r.detection.candidates) {
    if (c.accepted) {
      ++accepted;
    } else {
      ++reasons[c.reason];
    }
  }
  nlohmann::json rejected = nlohmann::json::object();
  for (const auto& [reason, n] : reasons) rejected[reason] = n;
  int active = 0;
  for (const fusion::LoopVerdict& v : r.graph.loops) active += v.active ? 1 : 0;
  return {{"frame", r.frame},
          {"keyframes", r.ms_features.size()},
          {"pairs_in_radius", r.detection.pairs_in_radius},
          {"pairs_heading_ok", r.detection.pairs_heading_ok},
          {"verified", r.detection.candidates.size()},
          {"accepted", accepted},
          {"rejected", static_cast<int>(r.detection.candidates.size()) - accepted},
          {"rejected_reasons", rejected},
          {"ms_features_per_keyframe", summaryJson(r.ms_features)},
          {"ms_detection_per_keyframe", summaryJson(r.detection.ms_per_keyframe)},
          {"ms_detection_total", r.ms_detection_total},
          {"records_mb", static_cast<double>(r.records_bytes) / (1024.0 * 1024.0)},
          {"applied", !r.trajectory.empty()},
          {"graph",
           {{"solved", r.graph.rounds > 0},
            {"nodes", r.graph.T.size()},
            {"fixes", r.graph_fixes},
            {"loops", r.graph.loops.size()},
            {"active_loops", active},
            {"rounds", r.graph.rounds},
            {"iterations", r.graph.iterations},
            {"converged", r.graph.converged},
            {"termination", r.graph.termination},
            {"ms_solve", r.graph.ms_solve}}}};
}

}  // namespace gvio::run
