#include "view/view_points.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>

#include "io/atomic_write.hpp"
#include "odometry/parallel_for.hpp"
#include "view/base64.hpp"

namespace gvio::view {
namespace {

static_assert(std::endian::native == std::endian::little, "the page reads little-endian arrays");

template <typename T>
void put(std::string& out, std::size_t offset, T value) {
  std::memcpy(out.data() + offset, &value, sizeof(T));
}

nlohmann::json nodeJson(const mapping::PointLodNode& node) {
  const Eigen::Vector3d c = node.cube.min(), lo = node.bounds.min(), hi = node.bounds.max();
  nlohmann::json children = nlohmann::json::array();
  for (const int k : node.children) {
    if (k >= 0) children.push_back(k);
  }
  return {{"name", node.name},
          {"depth", node.depth},
          {"cube", {c.x(), c.y(), c.z(), node.cube.sizes().x()}},
          {"bounds", {lo.x(), lo.y(), lo.z(), hi.x(), hi.y(), hi.z()}},
          {"points", node.points.size()},
          {"spacing", node.spacing_m},
          {"children", std::move(children)}};
}

}  // namespace

void ViewCloud::reserve(std::size_t n) {
  p.reserve(n);
  intensity.reserve(n);
  kind.reserve(n);
  drive.reserve(n);
}

void ViewCloud::push(const Eigen::Vector3d& point, std::uint8_t intensity_0_255,
                     std::uint8_t kind_id, std::uint16_t drive_id) {
  p.push_back(point);
  intensity.push_back(intensity_0_255);
  kind.push_back(kind_id);
  drive.push_back(drive_id);
}

std::string chunkBytes(const ViewCloud& cloud, const mapping::PointLodNode& node) {
  const std::size_t n = node.points.size();
  std::string bytes(10 * n, '\0');
  const Eigen::Vector3d lo = node.cube.min();
  const double size = node.cube.sizes().x();
  const double scale = size > 0.0 ? 65535.0 / size : 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const std::uint32_t i = node.points[k];
    for (int a = 0; a < 3; ++a) {  // rounded to nearest (non-negative: + 0.5 and truncate)
      const double q = std::clamp((cloud.p[i][a] - lo[a]) * scale + 0.5, 0.0, 65535.0);
      put(bytes, 6 * k + 2 * static_cast<std::size_t>(a), static_cast<std::uint16_t>(q));
    }
    put(bytes, 6 * n + 2 * k, cloud.drive[i]);
    bytes[8 * n + k] = static_cast<char>(cloud.intensity[i]);
    bytes[9 * n + k] = static_cast<char>(cloud.kind[i]);
  }
  return bytes;
}

PointChunks writePointChunks(const std::filesystem::path& dir, const ViewCloud& cloud,
                             const mapping::PointLodConfig& lod) {
  const mapping::PointLodTree tree = mapping::buildPointLod(cloud.p, lod);
  PointChunks out;
  out.points = tree.points;
  out.nodes = tree.nodes.size();
  for (const mapping::PointLodNode& node : tree.nodes) {
    out.depth = std::max(out.depth, node.depth);
    out.index.push_back(nodeJson(node));
  }
  // The chunks are independent files: encoded and written on every core (the same files
  // whatever the number of threads).
  parallelFor(tree.nodes.size(), threadCount(0, 8), [&](std::size_t i) {
    const mapping::PointLodNode& node = tree.nodes[i];
    if (node.points.empty()) return;
    std::string script =
        "gvioChunk(\"" + node.name + "\"," + std::to_string(node.points.size()) + ",\"";
    appendBase64(script, chunkBytes(cloud, node));
    script += "\");\n";
    io::writeTextAtomic(dir / (node.name + ".js"), script);
  });
  return out;
}

}  // namespace gvio::view
