#pragma once
// The map of a run. During the run, addKeyframe() stores what each keyframe contributes in the
// keyframe's own frames (keyframe_store.hpp). After the run, build() places everything with the
// final poses (T_enu_b from GNSS fusion, or the VIO poses), so corrections of past poses move
// the map with them: sparse landmark cloud, dense stereo cloud (VoxelGrid + SOR), OctoMap OcTree
// and ColorOcTree. No file I/O: app/ writes the files.
#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include <octomap/ColorOcTree.h>
#include <octomap/OcTree.h>
#include <opencv2/core/mat.hpp>

#include "mapping/keyframe_store.hpp"
#include "mapping/map_config.hpp"
#include "mapping/map_point.hpp"
#include "mapping/stereo_depth.hpp"
#include "odometry/measurements.hpp"
#include "odometry/vio_estimator.hpp"

namespace gvio::mapping {

// The dense map's spacing rule: a keyframe at T_now gets stereo depth once the camera rig has moved
// dense.min_spacing_m or turned dense.min_rotation_deg since T_last, the last keyframe with depth
// (any frame, as long as both poses are in it). Also how `gvio consistency --images` chooses the
// map's keyframes again.
[[nodiscard]] bool depthSpacingReached(const DenseMapConfig& dense, const Eigen::Isometry3d& T_last,
                                       const Eigen::Isometry3d& T_now);

// T_target_b of the keyframe at t_ns, or nullopt when the target frame has no pose for it.
using PoseLookup = std::function<std::optional<Eigen::Isometry3d>(std::int64_t t_ns)>;

struct KeyframeTimings {
  double ms_sparse = 0.0;        // landmark re-expression, intensity sampling, store update
  double ms_dense = 0.0;         // SGBM + back-projection + per-keyframe VoxelGrid (0 when not run)
  std::size_t dense_points = 0;  // points kept for this keyframe
};

struct MapCounts {
  std::size_t keyframes = 0;          // keyframes in the store
  std::size_t keyframes_used = 0;     // with a pose in the target frame
  std::size_t keyframes_skipped = 0;  // pose_of returned nullopt
  std::size_t landmarks_stored = 0;
  // too few observations, too large a reprojection error, or too far (sparse.max_landmark_range_m)
  std::size_t landmarks_rejected = 0;
  std::size_t landmarks_unplaced = 0;  // their keyframe had no pose
  std::size_t sparse_points = 0;
  std::size_t dense_points_raw = 0;    // keyframe points placed in the target frame
  std::size_t dense_points_voxel = 0;  // after the global VoxelGrid
  std::size_t dense_points = 0;        // after StatisticalOutlierRemoval
  std::size_t occupied_leaves = 0;     // OcTree leaves that are occupied (after pruning)
  std::size_t store_bytes = 0;         // KeyframeStore::memoryBytes() at build time
  std::size_t octree_bytes = 0;        // OcTree memoryUsage() (maximum likelihood, pruned)
  std::size_t color_octree_bytes = 0;  // ColorOcTree memoryUsage()
};

struct MapBuildResult {
  MapCloud sparse;                                        // source kSparseLandmark
  MapCloud dense;                                         // source kDenseStereo
  std::unique_ptr<octomap::OcTree> occupancy;             // null after buildClouds alone
  std::unique_ptr<octomap::ColorOcTree> occupancy_color;  // null after buildClouds alone
  MapCounts counts;
  std::vector<double> ms_octomap_per_keyframe;  // per used keyframe, in keyframe order
  double ms_dense_fusion = 0.0;                 // global VoxelGrid + SOR
};

class MapBuilder {
 public:
  // `left` is the rectified left camera (T_b_c: camera in body); baseline_m > 0 for a stereo rig
  // (the right camera is the left one moved by +baseline_m along its x axis), 0 for mono. Throws
  // InvalidInput for an invalid config or camera.
  MapBuilder(const MapConfig& config, const CameraModel& left, double baseline_m);

  // Records keyframe t_ns with its VIO pose T_w_b: its dense points when the rig is stereo,
  // `right` is not empty, dense mapping is on, this is an every_n-th keyframe and it is
  // min_spacing_m / min_rotation_deg away from the last keyframe with depth; and the window's
  // landmarks (VioEstimator::landmarks()), re-expressed in this keyframe's body frame. Images are
  // the rectified 8-bit pair. Keyframe times must increase.
  KeyframeTimings addKeyframe(std::int64_t t_ns, const Eigen::Isometry3d& T_w_b,
                              const cv::Mat& left, const cv::Mat& right,
                              const std::vector<odometry::LandmarkEstimate>& landmarks);

  // Rebuilds the whole map in the frame pose_of maps into.
  [[nodiscard]] MapBuildResult build(const PoseLookup& pose_of) const;

  // The same in two stages, for a long drive (gvio run): the clouds first (sparse, dense: no
  // trees), which the caller writes and frees, then the occupancy into the same result, freeing
  // each keyframe's stored dense points once inserted. The dense cloud and the trees, a long
  // drive's largest structures, are never held at once, and the trees' millions of small nodes
  // are allocated after the dense filters' temporaries are gone. Afterwards the keyframes
  // contribute their landmarks only (keyframePoints, build).
  [[nodiscard]] MapBuildResult buildClouds(const PoseLookup& pose_of) const;
  void buildOccupancyReleasing(const PoseLookup& pose_of, MapBuildResult& into);
  // The same occupancy without freeing anything, so it may run on another thread beside
  // buildClouds or keyframePoints (all const); then releaseDense() frees the dense points. The
  // trees are the same as buildOccupancyReleasing's.
  void buildOccupancy(const PoseLookup& pose_of, MapBuildResult& into) const;
  void releaseDense();

  // Points of the keyframes with t0_ns <= t_ns <= t1_ns in the target frame, without the global
  // filters: dense points where the keyframe has them, else the landmarks attached to it that
  // pass the sparse filters (observations left 0). For comparing passes over the same place
  // (consistency.hpp).
  [[nodiscard]] MapCloud keyframePoints(std::int64_t t0_ns, std::int64_t t1_ns,
                                        const PoseLookup& pose_of) const;
  // The same for the keyframes at `indices` (into store().keyframes()).
  [[nodiscard]] MapCloud keyframePoints(const std::vector<std::size_t>& indices,
                                        const PoseLookup& pose_of) const;

  // The stored VIO poses as a PoseLookup (maps in the VIO world frame). It refers to this
  // builder: do not use it after the builder is moved or destroyed.
  [[nodiscard]] PoseLookup vioPoses() const;

  [[nodiscard]] const KeyframeStore& store() const { return store_; }
  [[nodiscard]] const MapConfig& config() const { return config_; }

 private:
  // Each keyframe's pose in the target frame (nullopt: skipped), counted into `counts`.
  [[nodiscard]] std::vector<std::optional<Eigen::Isometry3d>> placedPoses(const PoseLookup& pose_of,
                                                                          MapCounts& counts) const;
  // `release`: this builder's store, to free each keyframe's dense points once used; or null.
  void occupancyInto(const std::vector<std::optional<Eigen::Isometry3d>>& poses,
                     MapBuildResult& result, KeyframeStore* release) const;
  [[nodiscard]] bool landmarkAccepted(const StoredLandmark& lm) const;
  // Whether keyframe `index` at T_w_b gets stereo depth (every_n, spacing and rotation rules).
  [[nodiscard]] bool denseTurn(std::size_t index, const Eigen::Isometry3d& T_w_b) const;
  // The points a keyframe contributes, in the target frame (see keyframePoints).
  [[nodiscard]] CameraCloud pointsOf(std::size_t index, const Eigen::Isometry3d& T_target_b,
                                     const std::vector<std::vector<std::uint64_t>>& attached) const;
  [[nodiscard]] std::vector<std::vector<std::uint64_t>> attachedLandmarks() const;

  MapConfig config_;
  CameraModel camera_;
  std::unique_ptr<StereoDepth> stereo_;  // null for mono or dense off
  KeyframeStore store_;
  std::optional<Eigen::Isometry3d> last_dense_T_w_b_;  // the spacing rule's reference
};

}  // namespace gvio::mapping
