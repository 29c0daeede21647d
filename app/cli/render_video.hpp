#pragma once
// `gvio render --video FILE --view follow|topdown|camera`: a video along the drive, rendered
// headless frame by frame (viz/video_views.hpp) and encoded with OpenCV's VideoWriter (FFmpeg):
// `.mp4` as H.264 (avc1, else MPEG-4 part 2), `.avi` as Motion JPEG. Written atomically.
#include <filesystem>
#include <optional>
#include <string>

#include "cli/progress.hpp"
#include "viz/video_views.hpp"

namespace gvio::cli {

struct VideoRequest {
  std::filesystem::path run, out;
  std::string view = "follow";
  int width = 1280, height = 720;  // follow and topdown; camera videos have the camera's size
  double fps = 10.0;               // frames per second of video
  double speed = 1.0;              // seconds of drive per second of video
  viz::DriveSpan span;             // --from / --to
  // --view camera
  std::optional<std::filesystem::path> dataset;
  std::string overlay = "blend", map_colour = "depth";
  ProgressStyle progress = ProgressStyle::kOff;
};

int renderVideo(const VideoRequest& request);

}  // namespace gvio::cli
