#pragma once
// Monocular structure from motion over the sliding window, the visual half of VINS-Mono's
// initialisation (Qin et al. 2018, sec. V-A): a reference pair with enough parallax gives the
// relative pose up to scale (Nister's 5-point essential matrix via OpenCV, RANSAC, and the
// cheirality test of recoverPose), its common features are triangulated (DLT), every other frame
// is located by PnP against those points and adds more points, and a bundle adjustment (Ceres)
// polishes the whole window. The result is in the "visual frame" (the reference camera) at an
// arbitrary scale; the visual-inertial alignment (vi_alignment.hpp) then finds the metric scale.
// Pure geometry on normalised image coordinates: no state, no I/O, and it never throws on data.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <optional>
#include <utility>
#include <vector>

namespace gvio::odometry {

// One feature track: its observations in the window frames, as (frame index, normalised image
// coordinates (x/z, y/z) in that frame's camera), in increasing frame index.
struct SfmTrack {
  std::uint64_t id = 0;
  std::vector<std::pair<int, Eigen::Vector2d>> observations;
};

struct SfmOptions {
  double focal_px = 500.0;        // converts the pixel thresholds below to normalised units
  int min_common_features = 30;   // features shared by the reference pair
  double min_parallax_px = 20.0;  // mean feature displacement within the reference pair
  double ransac_threshold_px = 1.0;
  int min_pnp_points = 10;  // triangulated points a frame must see to be located
  double min_triangulation_deg = 0.5;
  bool bundle_adjust = true;
  double max_rms_px = 2.0;  // reprojection RMS above this after adjustment: failure
};

struct SfmResult {
  int reference = 0;                                  // frame whose camera is the visual frame
  std::vector<Eigen::Isometry3d> T_v_c;               // camera of every frame in the visual frame
  std::map<std::uint64_t, Eigen::Vector3d> points_v;  // triangulated tracks, visual frame
  double rms_px = 0.0;                                // reprojection RMS over all used observations
};

// Solves the window of `num_frames` frames; the newest frame is num_frames - 1. Returns nullopt
// when no frame pair has enough common features and parallax, the geometry is degenerate (pure
// rotation, too few points), or some frame cannot be located.
std::optional<SfmResult> solveMonoSfm(const std::vector<SfmTrack>& tracks, int num_frames,
                                      const SfmOptions& options = {});

}  // namespace gvio::odometry
