#pragma once
// The keyframes `gvio view` shows on a click: each one's recorded left image (rectified as the run
// did) with the map drawn over it (render_camera.hpp's overlay), as a JPEG. The cameras are
// keyframes.bin's when the run saved it; otherwise keyframes are placed along the map trajectory
// at even path spacing.
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>

#include "io/run_dir.hpp"
#include "view/view_scene.hpp"

namespace gvio::cli {

struct ViewImagesRequest {
  std::size_t max_images = 300;  // keyframes shown with an image, evenly spread along the drive
  int max_width_px = 800;        // images wider than this are scaled down
  std::optional<std::filesystem::path> dataset;  // instead of report.json's sources
};

// Adds the images (and, without keyframes.bin, the keyframes) of `run` (read with its map.pcd:
// the overlays draw it) to `in`. Returns why there are none instead (the run's recordings cannot
// be reopened, no camera): the site stays useful.
std::optional<std::string> addKeyframeImages(io::RunFiles run, view::ViewInput& in,
                                             const ViewImagesRequest& r);

}  // namespace gvio::cli
