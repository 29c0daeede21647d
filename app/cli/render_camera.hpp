#pragma once
// `gvio render --view camera`: reopens the run's dataset (report.json "sources", or --dataset),
// rectifies the left image nearest the requested time as the run did, renders the map from that
// camera's pose on the run's trajectory and writes the overlay (viz/camera_view.hpp).
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include <opencv2/core/mat.hpp>

#include "io/dataset.hpp"
#include "io/run_dir.hpp"
#include "viz/camera_view.hpp"

namespace gvio::cli {

struct CameraRenderRequest {
  std::filesystem::path run, out;
  std::optional<std::filesystem::path> dataset;  // instead of report.json's sources
  double at_s = 0.0;                             // seconds from the start of the trajectory
  std::string overlay = "blend";
  std::string map_colour = "depth";
  double ahead_s = 20.0;
};

// The overlay of a run's map on its recorded left camera at any instant (one dataset, rectifier,
// EGL context for many frames: `gvio render --video ... --view camera` draws one per frame).
class RecordedCameraOverlay {
 public:
  // Reads the run (trajectory and map) and reopens its dataset; `dataset` overrides the recorded
  // sources. Throws InputError / InvalidInput naming the file.
  RecordedCameraOverlay(const std::filesystem::path& run_dir,
                        const std::optional<std::filesystem::path>& dataset,
                        const viz::CameraViewOptions& options, viz::OverlayMode overlay);
  // The same over a run already read (with its map.pcd; `gvio view` reads it once for both).
  RecordedCameraOverlay(io::RunFiles run, const std::optional<std::filesystem::path>& dataset,
                        const viz::CameraViewOptions& options, viz::OverlayMode overlay);
  ~RecordedCameraOverlay();
  RecordedCameraOverlay(const RecordedCameraOverlay&) = delete;
  RecordedCameraOverlay& operator=(const RecordedCameraOverlay&) = delete;

  [[nodiscard]] const io::RunFiles& run() const;
  [[nodiscard]] int width() const;
  [[nodiscard]] int height() const;
  // The rectified left camera the overlays are drawn for (pinhole, with its T_b_c).
  [[nodiscard]] const CameraModel& camera() const;
  // The overlay (BGR) at the image nearest `t_ns` (within 0.2 s; InvalidInput else); `frame_info`
  // gets the image's stamp and file when given.
  cv::Mat at(std::int64_t t_ns, std::string* frame_info = nullptr) const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

int renderCameraView(const CameraRenderRequest& request);

}  // namespace gvio::cli
