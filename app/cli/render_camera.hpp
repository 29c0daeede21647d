#pragma once
// `gvio render --view camera`: reopens the run's dataset (report.json "sources", or --dataset),
// rectifies the left image nearest the requested time as the run did, renders the map from that
// camera's pose on the run's trajectory and writes the overlay (viz/camera_view.hpp).
#include <filesystem>
#include <optional>
#include <string>

namespace gvio::cli {

struct CameraRenderRequest {
  std::filesystem::path run, out;
  std::optional<std::filesystem::path> dataset;  // instead of report.json's sources
  double at_s = 0.0;                             // seconds from the start of the trajectory
  std::string overlay = "blend";
  std::string map_colour = "depth";
  double ahead_s = 20.0;
};

int renderCameraView(const CameraRenderRequest& request);

}  // namespace gvio::cli
