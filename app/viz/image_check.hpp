#pragma once
// `gvio consistency --images`: the map checked against the recorded images without ground truth.
// For a keyframe, the map is drawn from its left camera's pose (exact rectified pinhole, points as
// splats sized by distance) using only points that came from keyframes at least `exclude_s` away
// in time, and compared with the image that keyframe recorded and with its own stereo depth
// (mapping/image_consistency.hpp).
//
// Why the map is rebuilt here instead of read from map.pcd: a fused map point is the centroid of
// a voxel that every keyframe seeing it contributed to, the checked keyframe included, so it has
// no single source to leave out. The check therefore rebuilds the map's inputs as the run does:
// the map keyframes chosen by the run's own spacing rule (map.dense.min_spacing_m /
// min_rotation_deg) along the map's trajectory (trajectory.tum), each keyframe's SGBM stereo
// points with the run's settings, voxelised per keyframe and placed with that trajectory. It is the
// same map as map.pcd before the final VoxelGrid and outlier removal, with its provenance kept;
// and a trajectory edited after the run is checked as the map it would build.
//
// Keyframe clouds are computed once and kept in a bounded cache (a sweep along the drive reuses
// them), and only the keyframes whose camera lies within neighbour_radius_m are drawn, each point
// culled to the view first. No file writes: the CLI writes the reports.
#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "io/dataset.hpp"
#include "io/run_dir.hpp"
#include "mapping/image_consistency.hpp"
#include "mapping/map_config.hpp"

namespace gvio::viz {

struct ImageCheckOptions {
  // Points from keyframes closer in time than this to the checked one are not drawn (the checked
  // keyframe's own points would repeat its image). A car's forward camera has passed its 15 m
  // stereo gate within ~2 s, so what it can be checked against comes from the keyframes 0.5-2 s
  // before and after it: leaving out 2 s left 4 % of the image covered on the demo drive (8 m/s),
  // 0.5 s leaves 40 %, each point measured from another stereo pair ~4+ m away.
  double exclude_s = 0.5;
  double neighbour_radius_m = 50.0;  // keyframes whose camera is farther are not drawn
  // ... or whose optical axis is turned farther from the checked one's. A stereo point's error lies
  // along its camera's ray (z^2 / (f b) per pixel of disparity: 0.3 m at 10 m on KITTI); seen from
  // across a 90-degree turn that error is sideways, and a facade measured at a grazing angle
  // becomes a row of streaks. With true poses on simulated KITTI-00, ZNCC fell from ~0.6 to
  // ~0.3 at every turn when all directions were drawn.
  double max_view_angle_deg = 30.0;
  double max_depth_m = 40.0;          // points farther from the camera are not drawn
  double splat_m = 0.1;               // a point is a disc of this size (the map's voxel), 1.5-12 px
  std::size_t cache_keyframes = 400;  // keyframe clouds kept (~0.4 MB each on KITTI)
  // At a revisit (a loop, a second pass), the keyframe is also checked against the map of the
  // other passes alone: the keyframes that are near it but not on its own pass, i.e. not joined to
  // it by consecutive keyframes all within neighbour_radius_m of it. No exclusion window is
  // needed there, and two passes agreeing is the strongest test of a map's consistency.
  bool revisits = true;
  // A few keyframes' own points are drawn from their own poses first (ImageCheck::selfCheck):
  // their depth agreement is what a perfectly consistent map reaches on this dataset. Below this
  // median, the drawn and the stereo depths are not comparable here, and the depth score is
  // reported as not enough evidence instead of flagging every keyframe.
  std::size_t self_check_keyframes = 5;
  double min_self_depth_agreement = 0.8;
  mapping::ImageConsistencyConfig score;

  void validate() const;  // InvalidInput naming the option
};

struct MapKeyframe {
  std::size_t frame = 0;  // index into the dataset's frames
  std::int64_t t_ns = 0;
  Eigen::Isometry3d T_map_c = Eigen::Isometry3d::Identity();  // rectified left camera
};

struct CheckedView {
  std::size_t keyframe = 0;  // index into keyframes()
  std::int64_t t_ns = 0;
  std::size_t source_keyframes = 0;  // keyframes whose points were drawn
  std::size_t points_drawn = 0;
  mapping::ViewScore score;
  // Against the other passes' map alone (ImageCheckOptions::revisits); revisit_sources == 0: the
  // keyframe has no other pass near it, and revisit is not scored.
  std::size_t revisit_sources = 0;
  mapping::ViewScore revisit;
  double ms = 0.0;  // wall time of this check (stereo of new keyframes, renders, scores)
};

// The images of one check, for the side-by-side picture.
struct CheckImages {
  cv::Mat recorded;  // CV_8UC1, rectified left
  cv::Mat rendered;  // CV_8UC1, the map's grey levels (0 where nothing was drawn)
  cv::Mat covered;   // CV_8UC1, 255 where the map was drawn
};

class ImageCheck {
 public:
  // `run`: its map trajectory places the keyframes; `dataset`: the run's recordings (stereo
  // required). Throws InvalidInput for a mono dataset, invalid options or no keyframe.
  ImageCheck(const io::RunFiles& run, const io::Dataset& dataset,
             const mapping::DenseMapConfig& dense, const ImageCheckOptions& options);
  ~ImageCheck();
  ImageCheck(const ImageCheck&) = delete;
  ImageCheck& operator=(const ImageCheck&) = delete;

  [[nodiscard]] const std::vector<MapKeyframe>& keyframes() const;
  // The map keyframe nearest in time to t_ns.
  [[nodiscard]] std::size_t keyframeNearest(std::int64_t t_ns) const;
  // Checks one keyframe; `images` gets its images when given.
  [[nodiscard]] CheckedView check(std::size_t keyframe, CheckImages* images = nullptr);
  // The keyframe's own points drawn from its own pose and scored against its own image and depth:
  // what a perfectly consistent map scores on this dataset. Far below 1, the comparison itself is
  // invalid here (a calibration or rectification the rendering does not share), whatever the
  // map. Call after the sweep of check() calls: it computes the keyframe's stereo again.
  [[nodiscard]] mapping::ViewScore selfCheck(std::size_t keyframe);

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// recorded | rendered | difference (BGR): the rendered grey levels matched to the recorded ones
// (mean and spread over the covered pixels), the absolute difference on covered pixels in
// magma, black elsewhere.
[[nodiscard]] cv::Mat sideBySide(const CheckImages& images);

}  // namespace gvio::viz
