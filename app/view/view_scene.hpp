#pragma once
// What `gvio view` shows, read from a run folder or a merged map: the points (for the octree),
// the occupied OctoMap voxels, and a JSON scene with everything small enough to load at once
// (trajectories, GNSS fixes with their screening result, loop edges, keyframe cameras, the
// report). Every position is in one scene frame, z up:
//   - a run: its map frame (local ENU when georeferenced, else the VIO world);
//   - a merged map: its map frame (UTM easting, northing, height less tiles.json's origin).
#include <Eigen/Geometry>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/run_dir.hpp"
#include "odometry/measurements.hpp"
#include "view/view_points.hpp"

namespace gvio::view {

struct ViewInput {
  nlohmann::json scene = nlohmann::json::object();
  ViewCloud cloud;
  std::vector<float> voxels;            // per occupied OctoMap leaf: centre x y z, edge (metres)
  std::vector<std::uint8_t> voxel_rgb;  // per leaf: r g b
  // JPEG bytes per entry of scene["keyframes"] (empty: no images); filled by the caller that can
  // reopen the run's recordings (the CLI).
  std::vector<std::string> keyframe_jpeg;
};

// A keyframe's camera: its stamp and its rectified left camera's pose in the scene frame.
struct KeyframeCamera {
  std::int64_t t_ns = 0;
  Eigen::Isometry3d T_scene_c = Eigen::Isometry3d::Identity();
};

// The scene's "keyframes": {"camera": {width, height, fx, fy, cx, cy} (pinhole), "t": [s],
// "pose": [x y z qw qx qy qz per keyframe]} (camera axes: x right, y down, z forward).
nlohmann::json keyframesJson(const CameraModel& camera,
                             const std::vector<KeyframeCamera>& keyframes);

// A run folder (`gvio run --out`) as io::readRunDir reads it: every file present is shown, none
// but a trajectory is required. Throws InputError naming the file that is missing or malformed.
ViewInput readRunForView(const io::RunFiles& run);

// A `gvio merge` folder: its tiles' points (every one) and the drives' tracks.
ViewInput readMergedForView(const std::filesystem::path& map_dir);

}  // namespace gvio::view
