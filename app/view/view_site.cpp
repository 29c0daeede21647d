#include "view/view_site.hpp"

#include <fmt/format.h>

#include <string>

#include "fleet/merged_map.hpp"
#include "io/atomic_write.hpp"
#include "io/input_error.hpp"
#include "io/run_dir.hpp"
#include "view/base64.hpp"
#include "view/view_points.hpp"
#include "view/view_scene.hpp"

namespace gvio::view {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr const char* kPageFiles[] = {"index.html", "viewer.js"};

std::string bytesOf(const void* data, std::size_t n) {
  return {static_cast<const char*>(data), n};
}

void writeVoxels(const fs::path& file, const ViewInput& in) {
  const std::size_t n = in.voxel_rgb.size() / 3;
  std::string script = "gvioVoxels(" + std::to_string(n) + ",\"";
  appendBase64(script, bytesOf(in.voxels.data(), in.voxels.size() * sizeof(float)));
  script += "\",\"";
  appendBase64(script, bytesOf(in.voxel_rgb.data(), in.voxel_rgb.size()));
  script += "\");\n";
  io::writeTextAtomic(file, script);
}

std::size_t writeKeyframeImages(const fs::path& dir, ViewInput& in) {
  if (in.keyframe_jpeg.empty()) return 0;
  fs::create_directories(dir);
  json images = json::array();
  std::size_t written = 0;
  for (std::size_t k = 0; k < in.keyframe_jpeg.size(); ++k) {
    if (in.keyframe_jpeg[k].empty()) {
      images.push_back(nullptr);
      continue;
    }
    const std::string name = fmt::format("{:05d}.jpg", k);
    io::writeTextAtomic(dir / name, in.keyframe_jpeg[k]);
    images.push_back("data/keyframes/" + name);
    ++written;
  }
  in.scene["keyframes"]["images"] = std::move(images);
  return written;
}

void copyPage(const fs::path& page_dir, const fs::path& to) {
  for (const char* name : kPageFiles) {
    std::error_code ec;
    fs::copy_file(page_dir / name, to / name, ec);
    if (ec)
      throw io::InputError(page_dir / name, 0, "cannot copy the viewer page: " + ec.message());
  }
}

}  // namespace

fs::path builtViewerPage() {
#ifdef GVIO_VIEWER_PAGE_DIR
  const fs::path dir = GVIO_VIEWER_PAGE_DIR;
  std::error_code ec;
  for (const char* name : kPageFiles) {
    if (!fs::is_regular_file(dir / name, ec)) return {};
  }
  return dir;
#else
  return {};
#endif
}

bool isViewSite(const fs::path& dir) {
  std::error_code ec;
  return fs::is_regular_file(dir / "index.html", ec) &&
         fs::is_regular_file(dir / "data" / "scene.js", ec);
}

ViewInput readViewInput(const fs::path& input) {
  return fleet::isMergedMap(input) ? readMergedForView(input)
                                   : readRunForView(io::readRunDir(input));
}

ViewSiteSummary writeViewSite(ViewInput& in, const fs::path& out, const fs::path& page_dir,
                              const mapping::PointLodConfig& lod) {
  std::error_code ec;
  if (fs::exists(out, ec) &&
      (!fs::is_directory(out, ec) || (!fs::is_empty(out, ec) && !isViewSite(out)))) {
    throw io::InputError(out, 0, "exists and is not a gvio view site; choose another --out");
  }
  ViewSiteSummary summary;
  summary.trajectories = in.scene["trajectories"].size();
  summary.voxels = in.voxel_rgb.size() / 3;
  io::writeFolderAtomic(out, [&](const fs::path& tmp) {
    copyPage(page_dir, tmp);
    fs::create_directories(tmp / "data" / "points");
    if (in.cloud.size() > 0) {
      const PointChunks chunks = writePointChunks(tmp / "data" / "points", in.cloud, lod);
      summary.points = chunks.points;
      summary.nodes = chunks.nodes;
      summary.depth = chunks.depth;
      in.scene["points"] = {{"count", chunks.points}, {"nodes", chunks.index}};
    }
    if (summary.voxels > 0) {
      writeVoxels(tmp / "data" / "voxels.js", in);
      in.scene["voxels"] = {{"count", summary.voxels}};
    }
    summary.images = writeKeyframeImages(tmp / "data" / "keyframes", in);
    io::writeTextAtomic(tmp / "data" / "scene.js", "gvioScene(" + in.scene.dump() + ");\n");
  });
  return summary;
}

}  // namespace gvio::view
