#pragma once
// The merge's first pass: every run's points, converted to UTM, appended to one file per tile in
// a scratch folder, so that the second pass holds one tile at a time (memory bounded by a tile,
// not by the number of points). Buffers are flushed per tile at 8192 points and all together
// beyond 2 M buffered points.
#include <climits>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace gvio::fleet {

// A square tile of the fixed UTM grid: south-west corner (i, j) x size.
struct TileKey {
  std::int64_t i = 0, j = 0;
  auto operator<=>(const TileKey&) const = default;
};

// One point in its tile: x, y from the tile's south-west corner, z from the map origin's height.
struct SpillPoint {
  float x = 0.0F, y = 0.0F, z = 0.0F;
  std::uint16_t intensity = 0;        // LAS's 16-bit scale
  std::uint16_t point_source_id = 0;  // the drive
  std::uint8_t source = 0;            // io::MapCloud::kSparse / kDense
  std::uint8_t reserved[3] = {0, 0, 0};
};
static_assert(sizeof(SpillPoint) == 20);

class TileSpill {
 public:
  TileSpill(std::filesystem::path scratch_dir, double tile_size_m, double origin_h_m);
  ~TileSpill();  // removes the scratch files
  TileSpill(const TileSpill&) = delete;
  TileSpill& operator=(const TileSpill&) = delete;

  [[nodiscard]] TileKey keyOf(double easting_m, double northing_m) const {
    return {static_cast<std::int64_t>(std::floor(easting_m / tile_size_m_)),
            static_cast<std::int64_t>(std::floor(northing_m / tile_size_m_))};
  }
  [[nodiscard]] Eigen::Vector2d southWest(const TileKey& k) const {
    return {static_cast<double>(k.i) * tile_size_m_, static_cast<double>(k.j) * tile_size_m_};
  }

  void add(const Eigen::Vector3d& p_utm, std::uint16_t intensity, std::uint16_t point_source_id,
           std::uint8_t source);
  void flushAll();
  // Every tile that received a point, in (i, j) order, with its count.
  [[nodiscard]] const std::map<TileKey, std::uint64_t>& counts() const { return counts_; }
  // A tile's points (after flushAll), in the order they were added.
  [[nodiscard]] std::vector<SpillPoint> read(const TileKey& k) const;
  [[nodiscard]] double tileSize() const { return tile_size_m_; }
  [[nodiscard]] double originHeight() const { return origin_h_m_; }

 private:
  [[nodiscard]] std::filesystem::path fileOf(const TileKey& k) const;
  void flush(const TileKey& k, std::vector<SpillPoint>& buffer);

  std::filesystem::path dir_;
  double tile_size_m_;
  double origin_h_m_;
  std::map<TileKey, std::vector<SpillPoint>> buffers_;
  std::map<TileKey, std::uint64_t> counts_;
  std::size_t buffered_ = 0;
  // The tile of the previous point: neighbours in a cloud mostly share one (saves two lookups).
  TileKey last_key_{INT64_MIN, INT64_MIN};
  std::vector<SpillPoint>* last_buffer_ = nullptr;
  std::uint64_t* last_count_ = nullptr;
};

}  // namespace gvio::fleet
