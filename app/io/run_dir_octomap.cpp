// map.ot / map.bt of a run folder through OctoMap. OctoMap prints its own (multi-line)
// complaints about bad files and recurses without bounds into a truncated tree, so the file's
// structure is checked here first and a bad one fails with one line.
#include <octomap/ColorOcTree.h>
#include <octomap/OcTree.h>

#include <fstream>
#include <iterator>
#include <optional>
#include <sstream>
#include <string>
#include <type_traits>

#include "io/input_error.hpp"
#include "io/run_dir.hpp"

namespace gvio::io {
namespace fs = std::filesystem;
namespace {

struct OctreeHeader {
  std::string id;
  std::size_t size = 0;
  double res = 0.0;
  std::size_t data_offset = 0;  // first byte of the node data
};

constexpr double kMaxResolutionM = 1000.0;

// The text header OctoMap writes ("# Octomap OcTree [binary ]file", then id / size / res lines,
// then "data"), parsed as AbstractOcTree::readHeader does.
OctreeHeader parseHeader(const std::string& bytes, bool binary, const fs::path& file) {
  const std::string magic = binary ? "# Octomap OcTree binary file" : "# Octomap OcTree file";
  if (bytes.compare(0, magic.size(), magic) != 0) {
    throw InputError(file, 1,
                     "not an OctoMap " + std::string(binary ? ".bt" : ".ot") + " file (expected '" +
                         magic + "')");
  }
  OctreeHeader h;
  std::size_t pos = 0, line = 0;
  while (pos < bytes.size()) {
    const std::size_t eol = bytes.find('\n', pos);
    if (eol == std::string::npos) break;
    const std::string text = bytes.substr(pos, eol - pos);
    pos = eol + 1;
    ++line;
    std::istringstream fields(text);
    std::string key;
    fields >> key;
    if (key.empty() || key[0] == '#') continue;
    if (key == "data") {
      h.data_offset = pos;
      if (h.id.empty() || !(h.res > 0.0)) {
        throw InputError(file, line, "header lacks a tree id or a positive resolution");
      }
      return h;
    }
    bool ok = true;
    if (key == "id") ok = static_cast<bool>(fields >> h.id);
    if (key == "size") ok = static_cast<bool>(fields >> h.size);
    if (key == "res") ok = static_cast<bool>(fields >> h.res);
    if (!ok) throw InputError(file, line, "bad header line '" + text + "'");
    // OctoMap keeps voxel centres in float: a resolution of 1e150 (found by fuzzing) makes them
    // infinite. No map has voxels of a kilometre.
    if (key == "res" && !(h.res > 0.0 && h.res <= kMaxResolutionM)) {
      throw InputError(file, line, "resolution must be in (0, 1000] m");
    }
  }
  throw InputError(file, 0, "header has no 'data' line");
}

// Walks the node stream as OcTreeBaseImpl::readNodesRecurs (.ot: value, then a child-bit byte)
// or OccupancyOcTreeBase::readBinaryNode (.bt: 2 bytes, 2 bits per child, 0b11 = inner node)
// read it, checking that it stays inside the file and the tree's 16 levels.
class NodeWalker {
 public:
  NodeWalker(const std::string& bytes, std::size_t offset, std::size_t value_bytes)
      : bytes_(bytes), pos_(offset), value_bytes_(value_bytes) {}

  bool walkOt(int depth) {
    ++nodes_;
    if (depth > 16 || pos_ + value_bytes_ + 1 > bytes_.size()) return false;
    pos_ += value_bytes_;
    const auto children = static_cast<unsigned char>(bytes_[pos_++]);
    for (int i = 0; i < 8; ++i) {
      if (((children >> i) & 1U) != 0 && !walkOt(depth + 1)) return false;
    }
    return true;
  }

  bool walkBt(int depth) {
    if (depth > 15 || pos_ + 2 > bytes_.size()) return false;
    const auto lo = static_cast<unsigned char>(bytes_[pos_]),
               hi = static_cast<unsigned char>(bytes_[pos_ + 1]);
    pos_ += 2;
    const unsigned bits = lo | (hi << 8U);
    for (int i = 0; i < 8; ++i) {
      const unsigned pair = (bits >> (2 * i)) & 3U;
      if (pair != 0) ++nodes_;
      if (pair == 3U && !walkBt(depth + 1)) return false;
    }
    return true;
  }

  [[nodiscard]] std::size_t nodes() const { return nodes_; }

 private:
  const std::string& bytes_;
  std::size_t pos_;
  std::size_t value_bytes_;
  std::size_t nodes_ = 0;
};

template <typename Tree>
void collectOccupied(const Tree& tree, bool color, OccupancyMap& map) {
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    if (!tree.isNodeOccupied(*it)) continue;
    OccupiedVoxel v;
    const octomap::point3d c = it.getCoordinate();
    v.center_enu = Eigen::Vector3f(c.x(), c.y(), c.z());
    v.size_m = static_cast<float>(it.getSize());
    if constexpr (std::is_same_v<Tree, octomap::ColorOcTree>) {
      if (color) {
        const auto rgb = it->getColor();
        v.rgb = {rgb.r, rgb.g, rgb.b};
      }
    }
    map.voxels.push_back(v);
  }
}

}  // namespace

OccupancyMap readOccupancy(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file, 0, "cannot open for reading");
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const bool binary = file.extension() == ".bt";
  const OctreeHeader h = parseHeader(bytes, binary, file);
  const bool color = h.id == "ColorOcTree";
  if (h.id != "OcTree" && !(color && !binary)) {
    throw InputError(file, 0, "tree type '" + h.id + "' is not supported (OcTree, ColorOcTree)");
  }
  NodeWalker walker(bytes, h.data_offset, color ? 7 : 4);  // float log-odds (+ 3 colour bytes)
  const bool ok = h.size == 0 || (binary ? walker.walkBt(0) : walker.walkOt(0));
  if (!ok || (h.size > 0 && walker.nodes() + (binary ? 1 : 0) != h.size)) {
    throw InputError(file, 0,
                     "OctoMap data is truncated or inconsistent with its header (size " +
                         std::to_string(h.size) + ")");
  }
  OccupancyMap map;
  map.file = file;
  map.resolution_m = h.res;
  map.has_color = color;
  if (h.size == 0) return map;
  std::string().swap(bytes);  // checked: read the tree from the file, not a second copy
  std::ifstream data(file, std::ios::binary);
  data.seekg(static_cast<std::streamoff>(h.data_offset));
  if (color) {
    octomap::ColorOcTree tree(h.res);
    tree.readData(data);
    collectOccupied(tree, true, map);
  } else {
    octomap::OcTree tree(h.res);
    if (binary) {
      tree.readBinaryData(data);
    } else {
      tree.readData(data);
    }
    collectOccupied(tree, false, map);
  }
  return map;
}

}  // namespace gvio::io
