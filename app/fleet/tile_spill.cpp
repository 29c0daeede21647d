#include "fleet/tile_spill.hpp"

#include <fmt/format.h>

#include <cstdio>
#include <memory>

#include "io/input_error.hpp"

namespace gvio::fleet {
namespace {

namespace fs = std::filesystem;

constexpr std::size_t kTileBuffer = 8192;
constexpr std::size_t kTotalBuffer = 2'000'000;

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

}  // namespace

TileSpill::TileSpill(fs::path scratch_dir, double tile_size_m, double origin_h_m)
    : dir_(std::move(scratch_dir)), tile_size_m_(tile_size_m), origin_h_m_(origin_h_m) {
  std::error_code ec;
  fs::create_directories(dir_, ec);
  if (ec)
    throw io::InputError(dir_, 0, "cannot create the merge's scratch folder: " + ec.message());
}

TileSpill::~TileSpill() {
  std::error_code ec;
  fs::remove_all(dir_, ec);
}

fs::path TileSpill::fileOf(const TileKey& k) const {
  return dir_ / fmt::format("{}_{}.bin", k.i, k.j);
}

void TileSpill::add(const Eigen::Vector3d& p_utm, std::uint16_t intensity,
                    std::uint16_t point_source_id, std::uint8_t source) {
  const TileKey k = keyOf(p_utm.x(), p_utm.y());
  const Eigen::Vector2d sw = southWest(k);
  SpillPoint s;
  s.x = static_cast<float>(p_utm.x() - sw.x());
  s.y = static_cast<float>(p_utm.y() - sw.y());
  s.z = static_cast<float>(p_utm.z() - origin_h_m_);
  s.intensity = intensity;
  s.point_source_id = point_source_id;
  s.source = source;
  if (!last_buffer_ || k != last_key_) {
    last_key_ = k;
    last_buffer_ = &buffers_[k];
    last_count_ = &counts_[k];
  }
  std::vector<SpillPoint>& buffer = *last_buffer_;
  buffer.push_back(s);
  ++*last_count_;
  ++buffered_;
  if (buffer.size() >= kTileBuffer) flush(k, buffer);
  if (buffered_ >= kTotalBuffer) flushAll();
}

void TileSpill::flush(const TileKey& k, std::vector<SpillPoint>& buffer) {
  if (buffer.empty()) return;
  const fs::path file = fileOf(k);
  const File f(std::fopen(file.c_str(), "ab"));
  if (!f ||
      std::fwrite(buffer.data(), sizeof(SpillPoint), buffer.size(), f.get()) != buffer.size()) {
    throw io::InputError(file, 0, "cannot write the merge's scratch file (disk full?)");
  }
  buffered_ -= buffer.size();
  buffer.clear();
  buffer.shrink_to_fit();
}

void TileSpill::flushAll() {
  for (auto& [k, buffer] : buffers_) flush(k, buffer);
  buffers_.clear();
  buffered_ = 0;
  last_buffer_ = nullptr;
}

std::vector<SpillPoint> TileSpill::read(const TileKey& k) const {
  const auto it = counts_.find(k);
  if (it == counts_.end()) return {};
  std::vector<SpillPoint> points(it->second);
  const fs::path file = fileOf(k);
  const File f(std::fopen(file.c_str(), "rb"));
  if (!f ||
      std::fread(points.data(), sizeof(SpillPoint), points.size(), f.get()) != points.size()) {
    throw io::InputError(file, 0, "cannot read back the merge's scratch file");
  }
  return points;
}

}  // namespace gvio::fleet
