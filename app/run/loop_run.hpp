#pragma once
// gvio run's loop-closure stages (issue 15, DESIGN.md section 1):
//  - while the VIO runs, LoopRecorder keeps each keyframe's loop features (mapping/loop_features:
//    ORB + stereo points, no images) and its VIO pose;
//  - after the drive and the GNSS fusion, closeLoops() detects and verifies loops over the whole
//    drive (mapping/loop_closure: candidates around the fused positions, or within the VIO drift
//    bound without GNSS) and solves the global pose graph over every keyframe (fusion/global_graph:
//    VIO relative + GNSS with the receiver bias + robust loops); every VIO pose then takes the
//    loop-closed keyframes' correction (blended between keyframes). That trajectory is the run's
//    final one: trajectory.tum (ENU when georeferenced, else the VIO world) and the map's poses.
#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "fusion/global_graph.hpp"
#include "io/loops_csv.hpp"
#include "mapping/loop_closure.hpp"
#include "mapping/place_database.hpp"
#include "odometry/trajectory.hpp"
#include "run/gnss_run.hpp"
#include "run/vio_runner.hpp"

namespace gvio::run {

// loops.* of the configuration: detection (mapping::LoopConfig, with its `enabled`) and the global
// graph's own settings; the graph's VIO noise, GNSS robust loss and receiver bias model are the
// fusion's (fusion.vio_*, fusion.huber_sigmas, fusion.smoother.bias_*).
struct LoopStageConfig {
  mapping::LoopConfig detection;
  double graph_chi2 = 22.46;  // 6 DoF, 99.9 %
  int graph_max_rounds = 5;
  int graph_max_iterations = 200;
  // The VIO's own tilt error reaches ~1 deg in its initialisation transients (simulated drives):
  // a stiffer tilt prior would fight correct loops there.
  double graph_tilt_sigma_deg = 1.0;
  bool save_keyframes = true;  // keyframes.bin (the place database) in a georeferenced run
  void validate() const;       // throws InvalidInput naming the key
  [[nodiscard]] fusion::GlobalGraphConfig graphConfig(const fusion::FusionConfig& fusion) const;
};

class LoopRecorder {
 public:
  explicit LoopRecorder(const mapping::LoopFeatureConfig& config);
  // The runVio keyframe hook: stereo features with a right image, else mono features on the
  // window's landmarks.
  void addKeyframe(const KeyframeInput& keyframe);

  [[nodiscard]] bool empty() const { return keyframes_.empty(); }
  [[nodiscard]] const std::vector<mapping::LoopKeyframe>& keyframes() const { return keyframes_; }
  [[nodiscard]] const std::vector<Eigen::Isometry3d>& vioPoses() const { return T_w_b_; }
  [[nodiscard]] const CameraModel& camera() const { return camera_; }
  [[nodiscard]] const std::vector<double>& msFeatures() const { return ms_features_; }
  [[nodiscard]] std::size_t memoryBytes() const;
  void release();  // frees the features (after closeLoops)
  std::vector<mapping::LoopKeyframe> takeKeyframes() { return std::move(keyframes_); }

 private:
  mapping::LoopFeatureConfig config_;
  CameraModel camera_;
  std::vector<mapping::LoopKeyframe> keyframes_;
  std::vector<Eigen::Isometry3d> T_w_b_;
  std::vector<double> ms_features_;
};

struct LoopRunResult {
  std::string frame;  // "enu" (georeferenced) or "vio_world"
  mapping::LoopDetection detection;
  fusion::GlobalGraphResult graph;
  std::size_t graph_fixes = 0;
  std::vector<io::LoopCsvRow> rows;  // loops.csv, every verified candidate with its verdict
  // Loop-closed T_frame_b of every VIO pose; empty when no loop was accepted and kept by the
  // global graph (then the earlier stages' trajectory stands, unchanged).
  Trajectory trajectory;
  std::size_t records_bytes = 0;    // memory the loop features held
  std::vector<double> ms_features;  // per keyframe
  double ms_detection_total = 0.0;
};

// `vio`: the run's VIO trajectory; `gnss`: the fusion's result when it registered the VIO to ENU
// (its smoothed trajectory and covariances are the priors, its used fixes enter the graph), else
// null (pure VIO in its own world).
LoopRunResult closeLoops(const LoopRecorder& recorder, const Trajectory& vio,
                         const GnssRunResult* gnss, bool has_imu, const LoopStageConfig& config,
                         const fusion::FusionConfig& fusion);

// The run's place database (keyframes.bin, for gvio merge's joint alignment) of a georeferenced
// run: the recorder's features, `final_enu` at each keyframe (the poses the map was built with),
// the fusion's covariances (before the loops) and used fixes, and the loops the run's global graph
// kept (`loops`, null when loop closure failed). Empty when gnss did not register the VIO. The
// recorder's features are moved into it (no second copy at the run's peak).
std::optional<mapping::PlaceDatabase> placeDatabase(LoopRecorder& recorder, const Trajectory& vio,
                                                    const Trajectory& final_enu,
                                                    const GnssRunResult& gnss,
                                                    const LoopRunResult* loops, bool has_imu,
                                                    const LoopStageConfig& config,
                                                    const fusion::FusionConfig& fusion);

// report.json's "loops".
nlohmann::json loopsReport(const LoopRunResult& result);

}  // namespace gvio::run
