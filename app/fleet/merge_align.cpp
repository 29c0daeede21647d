#include "fleet/merge_align.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>

#include "io/loops_csv.hpp"
#include "io/place_database_io.hpp"
#include "odometry/lie.hpp"
#include "run/stats.hpp"

namespace gvio::fleet {
namespace {

namespace fs = std::filesystem;

struct Drive {
  std::size_t run = 0;  // index in the merge's runs
  mapping::PlaceDatabase db;
  Eigen::Isometry3d T_c_r = Eigen::Isometry3d::Identity();  // its ENU frame -> the common one
};

// A verified loop between two drives: keyframe kq of drive q (the query) in keyframe kc of drive
// c's frame.
struct CrossLoop {
  std::size_t q = 0, kq = 0, c = 0, kc = 0;  // drive (index in `drives`), keyframe
  fusion::GraphLoop loop;
  std::size_t row = 0;  // its row in the csv
};

struct Row {
  std::size_t q = 0, c = 0;
  io::LoopCsvRow csv;
};

// The rigid transform from one local ENU frame to another: both are ECEF rotated and shifted
// (GeographicLib's LocalCartesian), so this is exact.
Eigen::Isometry3d enuToEnu(const fusion::Lla& common, const fusion::Lla& own) {
  const fusion::EnuFrame c(common), r(own);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = c.R_enu_ecef() * r.R_enu_ecef().transpose();
  T.translation() = c.ecefToEnu(fusion::llaToEcef(own));
  return T;
}

bool sameCamera(const CameraModel& a, const CameraModel& b) {
  const auto close = [](double x, double y) {
    return std::abs(x - y) <= 1e-6 * std::max(1.0, std::abs(x));
  };
  return a.width_px == b.width_px && a.height_px == b.height_px && close(a.fx, b.fx) &&
         close(a.fy, b.fy) && close(a.cx, b.cx) && close(a.cy, b.cy) &&
         (a.T_b_c.matrix() - b.T_b_c.matrix()).norm() < 1e-6;
}

double degrees(double rad) {
  return rad * 180.0 / std::numbers::pi;
}

// Loop detection between the drives of one camera; appends to `loops` and `rows`.
void detectBetween(std::vector<Drive>& drives, const std::vector<std::size_t>& group,
                   const run::LoopStageConfig& config, const fusion::FusionConfig& fusion,
                   std::vector<CrossLoop>& loops, std::vector<Row>& rows, MergeAlignment& out) {
  std::vector<mapping::LoopKeyframe> keyframes;
  std::vector<mapping::KeyframePrior> priors;
  std::vector<std::pair<std::size_t, std::size_t>> origin;  // drive, keyframe
  for (std::size_t d : group) {
    Drive& drive = drives[d];
    for (std::size_t k = 0; k < drive.db.priors.size(); ++k) {
      mapping::KeyframePrior p = drive.db.priors[k];
      p.T_ref_b = drive.T_c_r * p.T_ref_b;
      p.segment = static_cast<std::uint32_t>(d);
      priors.push_back(p);
      keyframes.push_back(std::move(drive.db.keyframes[k]));
      origin.emplace_back(d, k);
    }
    std::vector<mapping::LoopKeyframe>().swap(drive.db.keyframes);  // moved out
  }
  const mapping::LoopDetection det =
      mapping::detectLoops(keyframes, priors, drives[group.front()].db.camera, config.detection,
                           fusion.relativeNoise(), mapping::LoopPairs::kAcrossSegments);
  out.pairs_in_radius += det.pairs_in_radius;
  out.verified += det.candidates.size();
  const std::size_t first_row = rows.size();
  for (const mapping::LoopCandidate& c : det.candidates) {
    Row r;
    r.q = origin[c.query].first;
    r.c = origin[c.candidate].first;
    r.csv.query_t_ns = keyframes[c.query].t_ns;
    r.csv.candidate_t_ns = keyframes[c.candidate].t_ns;
    r.csv.distance_m = c.distance_m;
    r.csv.search_radius_m = c.radius_m;
    r.csv.matches = c.measurement.matches;
    r.csv.inliers = c.measurement.inliers;
    r.csv.reprojection_px = c.measurement.reprojection_px;
    r.csv.correction_m = c.correction_m;
    r.csv.correction_deg = c.correction_deg;
    r.csv.accepted = c.accepted;
    r.csv.reason = c.reason;
    rows.push_back(r);
  }
  std::vector<std::size_t> index;
  const std::vector<fusion::GraphLoop> accepted =
      mapping::acceptedGraphLoops(det, config.detection, index);
  for (std::size_t k = 0; k < accepted.size(); ++k) {
    CrossLoop l;
    std::tie(l.c, l.kc) = origin[accepted[k].i];
    std::tie(l.q, l.kq) = origin[accepted[k].j];
    l.loop = accepted[k];
    l.row = first_row + index[k];
    loops.push_back(l);
  }
}

// The drives in camera groups of two or more (each in merge order).
std::vector<std::vector<std::size_t>> cameraGroups(const std::vector<Drive>& drives,
                                                   const std::vector<MergeRun>& runs) {
  std::vector<std::vector<std::size_t>> groups;
  for (std::size_t d = 0; d < drives.size(); ++d) {
    auto it = std::find_if(groups.begin(), groups.end(), [&](const auto& g) {
      return sameCamera(drives[g.front()].db.camera, drives[d].db.camera);
    });
    if (it == groups.end()) {
      groups.push_back({d});
    } else {
      it->push_back(d);
    }
  }
  if (groups.size() > 1) {
    for (const auto& g : groups) {
      spdlog::info(
          "merge: alignment: {} and {} other drive(s) share a camera; drives of "
          "different cameras are not matched with each other",
          runs[drives[g.front()].run].name, g.size() - 1);
    }
  }
  std::erase_if(groups, [](const auto& g) { return g.size() < 2; });
  return groups;
}

// The joint graph over the drives that loops join; fills the movements and corrections.
void solveJoint(std::vector<Drive>& drives, std::vector<CrossLoop>& loops, std::vector<Row>& rows,
                const run::LoopStageConfig& config, const fusion::FusionConfig& fusion,
                MergeAlignment& out) {
  std::vector<bool> joined(drives.size(), false);
  for (const CrossLoop& l : loops) joined[l.q] = joined[l.c] = true;
  std::vector<std::size_t> offset(drives.size(), 0);
  std::vector<fusion::GraphNode> nodes;
  std::vector<fusion::GraphFix> fixes;
  std::vector<fusion::GraphLoop> graph_loops;
  bool has_imu = true;
  std::uint32_t segment = 0;
  for (std::size_t d = 0; d < drives.size(); ++d) {
    if (!joined[d]) continue;
    const Drive& drive = drives[d];
    offset[d] = nodes.size();
    has_imu = has_imu && drive.db.has_imu;
    for (std::size_t k = 0; k < drive.db.priors.size(); ++k) {
      fusion::GraphNode n;
      n.t_ns = drive.db.priors[k].t_ns;
      n.segment = segment;
      n.T_w_b = drive.db.T_vio[k];
      n.T_init = drive.T_c_r * drive.db.priors[k].T_ref_b;
      nodes.push_back(n);
    }
    for (fusion::GraphFix f : drive.db.fixes) {
      f.node += offset[d];
      f.p_enu = drive.T_c_r * f.p_enu;
      fixes.push_back(f);
    }
    for (fusion::GraphLoop l : drive.db.loops) {
      l.i += offset[d];
      l.j += offset[d];
      graph_loops.push_back(l);
    }
    ++segment;
  }
  const std::size_t own = graph_loops.size();
  for (const CrossLoop& l : loops) {
    fusion::GraphLoop g = l.loop;
    g.i = offset[l.c] + l.kc;
    g.j = offset[l.q] + l.kq;
    graph_loops.push_back(g);
  }
  out.graph =
      fusion::solveGlobalGraph(nodes, fixes, graph_loops, has_imu, config.graphConfig(fusion));
  out.solved = true;
  for (std::size_t k = 0; k < loops.size(); ++k) {
    const bool active = out.graph.loops[own + k].active;
    out.active += active ? 1 : 0;
    for (const std::size_t d : {loops[k].q, loops[k].c}) {
      DriveMovement& m = out.drives[drives[d].run];
      ++m.loops_accepted;
      m.loops_active += active ? 1 : 0;
    }
    if (active) continue;
    rows[loops[k].row].csv.accepted = false;
    rows[loops[k].row].csv.reason = "graph_outlier";
  }
  for (std::size_t d = 0; d < drives.size(); ++d) {
    if (!joined[d]) continue;
    const Drive& drive = drives[d];
    DriveMovement& m = out.drives[drive.run];
    m.aligned = true;
    std::vector<Eigen::Isometry3d> T_old, T_new;
    std::vector<double> moved;
    for (std::size_t k = 0; k < drive.db.priors.size(); ++k) {
      T_old.push_back(drive.db.priors[k].T_ref_b);
      T_new.push_back(drive.T_c_r.inverse() * out.graph.T[offset[d] + k]);
      moved.push_back((T_new.back().translation() - T_old.back().translation()).norm());
      const Eigen::Matrix3d dR = T_new.back().rotation() * T_old.back().rotation().transpose();
      m.rotated_max_deg = std::max(m.rotated_max_deg, degrees(odometry::logSo3(dR).norm()));
    }
    // The run's timing summary (mean, nearest-rank p95, max) serves distances as well.
    const run::TimingSummary summary = run::summarizeTimings(std::move(moved));
    m.moved_mean_m = summary.mean;
    m.moved_p95_m = summary.p95;
    m.moved_max_m = summary.max;
    out.corrections[drive.run].emplace(T_old, T_new);
  }
}

std::string csvText(const std::vector<MergeRun>& runs, const std::vector<Drive>& drives,
                    const std::vector<Row>& rows) {
  std::string text = alignmentLoopsHeader();
  for (const Row& r : rows) {
    text += fmt::format("{},{},{}\n", runs[drives[r.q].run].name, runs[drives[r.c].run].name,
                        io::loopsCsvLine(r.csv));
  }
  return text;
}

}  // namespace

std::string alignmentLoopsHeader() {
  return fmt::format("query_drive,candidate_drive,{}\n", io::kLoopsCsvHeader);
}

MergeAlignment alignDrives(const std::vector<MergeRun>& runs, const run::LoopStageConfig& config,
                           const fusion::FusionConfig& fusion) {
  config.validate();
  MergeAlignment out;
  out.drives.resize(runs.size());
  out.corrections.resize(runs.size());
  out.attempted = runs.size() >= 2;
  if (!out.attempted) return out;
  std::vector<Drive> drives;
  for (std::size_t r = 0; r < runs.size(); ++r) {
    const fs::path file = runs[r].dir / "keyframes.bin";
    DriveMovement& m = out.drives[r];
    if (!fs::is_regular_file(file)) {
      m.note = "no keyframes.bin (loop closure or loops.save_keyframes off, or an older gvio)";
      spdlog::warn("merge: {}: {}: merged as it is", runs[r].name, m.note);
      continue;
    }
    Drive d;
    d.run = r;
    d.db = io::readPlaceDatabase(file);
    d.T_c_r = enuToEnu(runs.front().georef.enu_origin, runs[r].georef.enu_origin);
    m.has_keyframes = true;
    m.keyframes = d.db.priors.size();
    m.fixes = d.db.fixes.size();
    m.own_loops = d.db.loops.size();
    if (d.db.priors.empty()) continue;
    drives.push_back(std::move(d));
  }
  const auto start = std::chrono::steady_clock::now();
  std::vector<CrossLoop> loops;
  std::vector<Row> rows;
  for (const auto& group : cameraGroups(drives, runs)) {
    detectBetween(drives, group, config, fusion, loops, rows, out);
  }
  out.accepted = loops.size();
  out.ms_detection =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  if (!loops.empty()) solveJoint(drives, loops, rows, config, fusion, out);
  for (DriveMovement& m : out.drives) {
    if (m.has_keyframes && !m.aligned) m.note = "no verified loop to another drive";
  }
  out.csv = csvText(runs, drives, rows);
  return out;
}

nlohmann::json alignmentJson(const std::vector<MergeRun>& runs, const MergeAlignment& a) {
  nlohmann::json drives = nlohmann::json::array();
  for (std::size_t r = 0; r < runs.size(); ++r) {
    const DriveMovement& m = a.drives[r];
    nlohmann::json d = {{"name", runs[r].name},
                        {"point_source_id", runs[r].point_source_id},
                        {"keyframes", m.keyframes},
                        {"fixes", m.fixes},
                        {"own_loops", m.own_loops},
                        {"aligned", m.aligned},
                        {"loops_accepted", m.loops_accepted},
                        {"loops_active", m.loops_active}};
    if (m.aligned) {
      d["moved_m"] = {{"mean", m.moved_mean_m}, {"p95", m.moved_p95_m}, {"max", m.moved_max_m}};
      d["rotated_max_deg"] = m.rotated_max_deg;
    } else {
      d["note"] = m.note;
    }
    drives.push_back(d);
  }
  nlohmann::json graph = nullptr;
  if (a.solved) {
    graph = {{"nodes", a.graph.T.size()},      {"loops", a.graph.loops.size()},
             {"rounds", a.graph.rounds},       {"iterations", a.graph.iterations},
             {"converged", a.graph.converged}, {"termination", a.graph.termination},
             {"ms_solve", a.graph.ms_solve}};
  }
  return {{"attempted", a.attempted},
          {"solved", a.solved},
          {"error", a.error.empty() ? nlohmann::json(nullptr) : nlohmann::json(a.error)},
          {"pairs_in_radius", a.pairs_in_radius},
          {"verified", a.verified},
          {"accepted", a.accepted},
          {"active", a.active},
          {"ms_detection", a.ms_detection},
          {"graph", graph},
          {"drives", drives}};
}

}  // namespace gvio::fleet
