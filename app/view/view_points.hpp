#pragma once
// The viewer's point octree: the nodes of mapping::buildPointLod written as data files that the
// page loads as the camera comes near them (Potree's scheme: Schuetz 2016, "Potree: Rendering
// Large Point Clouds in Web Browsers", sec. 3), so a map of any size opens with its root node
// alone and the page holds only the nodes it draws.
//
// Each node NAME with points becomes `points/NAME.js`, one call
//   gvioChunk("NAME", N, "BASE64")
// whose bytes are, for its N points in the node's order:
//   uint16[3N]  x y z quantised in the node's cube: p = cube_min + q / 65535 * cube_size
//               (a step of size / 65535: 1.5 mm in a 100 m cube, always far below the
//               node's own spacing);
//   uint16[N]   drive (a merged map's point source id; 0 for one run);
//   uint8[N]    intensity (0..255);
//   uint8[N]    kind (0 sparse landmark, 1 dense stereo).
// Scripts rather than binary files, so the page also works opened from the folder (file://).
#include <Eigen/Core>

#include <cstdint>
#include <filesystem>
#include <vector>

#include <nlohmann/json.hpp>

#include "mapping/point_lod.hpp"

namespace gvio::view {

// The points, one entry per point in each array (structure of arrays: the octree reads `p`
// in place).
struct ViewCloud {
  std::vector<Eigen::Vector3d> p;  // the scene frame, metres
  std::vector<std::uint8_t> intensity;
  std::vector<std::uint8_t> kind;  // 0 sparse landmark, 1 dense stereo
  std::vector<std::uint16_t> drive;
  [[nodiscard]] std::size_t size() const { return p.size(); }
  void reserve(std::size_t n);
  void push(const Eigen::Vector3d& point, std::uint8_t intensity_0_255, std::uint8_t kind_id,
            std::uint16_t drive_id);
};

struct PointChunks {
  nlohmann::json index = nlohmann::json::array();  // per node: name, cube, bounds, points, ...
  std::size_t points = 0;                          // written (the finite ones)
  std::size_t nodes = 0;
  int depth = 0;  // the deepest node's level (0: the root alone)
};

// The bytes of one node's chunk (as above, before base64).
std::string chunkBytes(const ViewCloud& cloud, const mapping::PointLodNode& node);

// Builds the octree and writes its chunks into `dir` (an existing, empty folder). The index
// lists every node (root first) as {"name", "depth", "cube": [min x y z, size], "bounds":
// [min x y z, max x y z], "points", "spacing", "children": [node indices]}.
PointChunks writePointChunks(const std::filesystem::path& dir, const ViewCloud& cloud,
                             const mapping::PointLodConfig& lod);

}  // namespace gvio::view
