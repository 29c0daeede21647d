#include "fleet/merge_tile.hpp"

#include <octomap/OcTree.h>
#include <pcl/PCLPointCloud2.h>
#include <pcl/io/pcd_io.h>

#include <fmt/format.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <unordered_map>

#include "export/las_writer.hpp"
#include "io/atomic_write.hpp"
#include "io/input_error.hpp"
#include "io/quiet_stderr.hpp"
#include "io/run_dir.hpp"

namespace gvio::fleet {
namespace {

namespace fs = std::filesystem;

// The point's offsets from its tile's south-west corner and the spill's height origin.
Eigen::Vector3d offsets(const SpillPoint& p) {
  return Eigen::Vector3f(p.x, p.y, p.z).cast<double>();
}

// UTM easting, northing and ellipsoidal height.
Eigen::Vector3d utmOf(const TileSpill& spill, const TileKey& key, const SpillPoint& p) {
  const Eigen::Vector2d sw = spill.southWest(key);
  return Eigen::Vector3d(sw.x(), sw.y(), spill.originHeight()) + offsets(p);
}

// The map frame: UTM less the map origin's.
Eigen::Vector3d mapFrame(const MergeFrame& frame, const TileSpill& spill, const TileKey& key,
                         const SpillPoint& p) {
  const Eigen::Vector2d sw = spill.southWest(key);
  return Eigen::Vector3d(sw.x() - frame.origin_utm.x(), sw.y() - frame.origin_utm.y(),
                         spill.originHeight() - frame.origin_utm.z()) +
         offsets(p);
}

void writeTilePcd(const fs::path& file, const MergeFrame& frame, const TileSpill& spill,
                  const TileKey& key, const std::vector<SpillPoint>& points) {
  pcl::PCLPointCloud2 cloud;
  const auto field = [](const char* name, std::uint32_t offset, std::uint8_t type) {
    pcl::PCLPointField f;
    f.name = name;
    f.offset = offset;
    f.datatype = type;
    f.count = 1;
    return f;
  };
  using F = pcl::PCLPointField;
  cloud.fields = {field("x", 0, F::FLOAT32),
                  field("y", 4, F::FLOAT32),
                  field("z", 8, F::FLOAT32),
                  field("intensity", 12, F::FLOAT32),
                  field("point_source_id", 16, F::UINT16),
                  field("source", 18, F::UINT8)};
  cloud.point_step = 20;
  cloud.width = static_cast<std::uint32_t>(points.size());
  cloud.height = 1;
  cloud.row_step = cloud.point_step * cloud.width;
  cloud.is_dense = true;
  cloud.data.resize(cloud.row_step);
  std::uint8_t* out = cloud.data.data();
  for (const SpillPoint& p : points) {
    const Eigen::Vector3f m = mapFrame(frame, spill, key, p).cast<float>();
    const float intensity = static_cast<float>(p.intensity) / 257.0F;  // back to 0..255
    std::memcpy(out, m.data(), 12);
    std::memcpy(out + 12, &intensity, 4);
    std::memcpy(out + 16, &p.point_source_id, 2);
    std::memcpy(out + 18, &p.source, 1);
    out[19] = 0;
    out += cloud.point_step;
  }
  // Binary, not binary_compressed: a tile is small, and LZF would take a third of the merge.
  // PCL's header, then the records in one stream write: PCDWriter::writeBinary maps a file it
  // first truncates to size, and faulting in those pages took a quarter of a merge.
  const std::string header = pcl::PCDWriter().generateHeaderBinary(cloud, Eigen::Vector4f::Zero(),
                                                                   Eigen::Quaternionf::Identity()) +
                             "DATA binary\n";
  io::writeFileAtomic(file, [&](std::ostream& stream) {
    stream.write(header.data(), static_cast<std::streamsize>(header.size()));
    stream.write(reinterpret_cast<const char*>(cloud.data.data()),
                 static_cast<std::streamsize>(cloud.data.size()));
  });
}

// Sorts keys of 48 bits: three counting passes of 16 bits (LSD radix sort), several times faster
// than a comparison sort for the millions of voxel keys of a tile.
void radixSort48(std::vector<std::uint64_t>& keys) {
  std::vector<std::uint64_t> buffer(keys.size());
  std::vector<std::size_t> count(1 << 16);
  for (int shift = 0; shift < 48; shift += 16) {
    std::fill(count.begin(), count.end(), 0);
    for (const std::uint64_t k : keys) ++count[(k >> shift) & 0xFFFF];
    std::size_t sum = 0;
    for (auto& c : count) {
      const std::size_t n = c;
      c = sum;
      sum += n;
    }
    for (const std::uint64_t k : keys) buffer[count[(k >> shift) & 0xFFFF]++] = k;
    keys.swap(buffer);
  }
}

// Occupied voxels where points fall (no free space: the points carry no sensor origin). Each
// voxel is updated once however many points it holds (the tile's keys are sorted and made
// unique first), which is what makes this fast.
std::size_t writeTileOctomap(const fs::path& file, const MergeFrame& frame, const TileSpill& spill,
                             const TileKey& key, const std::vector<SpillPoint>& points,
                             double resolution_m, std::string& note) {
  octomap::OcTree tree(resolution_m);
  std::vector<octomap::OcTreeKey> keys;
  keys.reserve(points.size());
  for (const SpillPoint& p : points) {
    const Eigen::Vector3d m = mapFrame(frame, spill, key, p);
    octomap::OcTreeKey k;
    if (!tree.coordToKeyChecked(m.x(), m.y(), m.z(), k)) {
      note = fmt::format("outside OctoMap's key range at {} m ({:.0f} km from the map origin)",
                         resolution_m, 32768 * resolution_m / 1000.0);
      return 0;
    }
    keys.push_back(k);
  }
  // Three 16-bit key parts in one integer: sorting those is several times faster than keys.
  // Dense stereo points arrive in runs within one voxel: dropping repeats first halves the sort.
  std::vector<std::uint64_t> packed;
  packed.reserve(keys.size());
  for (const auto& k : keys) {
    const std::uint64_t v = (std::uint64_t{k[0]} << 32) | (std::uint64_t{k[1]} << 16) | k[2];
    if (packed.empty() || packed.back() != v) packed.push_back(v);
  }
  radixSort48(packed);
  packed.erase(std::unique(packed.begin(), packed.end()), packed.end());
  for (const std::uint64_t v : packed) {
    const octomap::OcTreeKey k(static_cast<octomap::key_type>(v >> 32),
                               static_cast<octomap::key_type>(v >> 16),
                               static_cast<octomap::key_type>(v));
    tree.updateNode(k, true, /*lazy_eval=*/true);
  }
  tree.updateInnerOccupancy();
  io::writeFileAtomic(file, [&](std::ostream& out) {
    const io::QuietStderr quiet;  // Debian's OctoMap prints "done." on every write
    if (!tree.writeBinary(out) && out)
      throw std::runtime_error("OctoMap could not write " + file.string());
  });
  return packed.size();
}

// Points hashed into cubes of one size: the 27 cubes around a query hold every point within
// that size of it.
class CubeHash {
 public:
  CubeHash(const std::vector<Eigen::Vector3f>& points, double cube_m)
      : points_(points), cube_m_(cube_m) {
    cubes_.reserve(points.size() / 4 + 1);
    for (std::size_t k = 0; k < points.size(); ++k) {
      cubes_[key(cube(points[k]))].push_back(static_cast<std::uint32_t>(k));
    }
  }
  // The squared distance to the nearest point within the cube size, or +inf.
  [[nodiscard]] double nearest2(const Eigen::Vector3f& q) const {
    const Eigen::Vector3i c = cube(q);
    double best2 = cube_m_ * cube_m_;
    bool found = false;
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = cubes_.find(key(c + Eigen::Vector3i(dx, dy, dz)));
          if (it == cubes_.end()) continue;
          for (const std::uint32_t k : it->second) {
            const double d2 = (points_[k] - q).cast<double>().squaredNorm();
            if (d2 <= best2) {
              best2 = d2;
              found = true;
            }
          }
        }
      }
    }
    return found ? best2 : std::numeric_limits<double>::infinity();
  }

 private:
  [[nodiscard]] Eigen::Vector3i cube(const Eigen::Vector3f& p) const {
    return (p.cast<double>() / cube_m_).array().floor().cast<int>();
  }
  static std::uint64_t key(const Eigen::Vector3i& c) {
    // 21 bits a coordinate: a tile's cubes lie well within +-2^20 of its corner.
    const auto part = [](int v) { return static_cast<std::uint64_t>(v + (1 << 20)) & 0x1FFFFF; };
    return (part(c.x()) << 42) | (part(c.y()) << 21) | part(c.z());
  }
  const std::vector<Eigen::Vector3f>& points_;
  double cube_m_;
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> cubes_;
};

// The nearest point within `radius` of a query, exactly: a hash of fine cubes (radius / 4)
// answers the queries with a near neighbour from a few points, one of radius-sized cubes the
// rest. Cheaper to build than a k-d tree, which matters more than the query (a sample of a few
// thousand points a tile asks, against all of the reference drive's points).
class RadiusGrid {
 public:
  RadiusGrid(const std::vector<Eigen::Vector3f>& points, double radius_m)
      : fine_(points, radius_m / 4.0), coarse_(points, radius_m) {}
  [[nodiscard]] std::optional<double> nearest(const Eigen::Vector3f& q) const {
    double d2 = fine_.nearest2(q);
    if (!std::isfinite(d2)) d2 = coarse_.nearest2(q);
    if (!std::isfinite(d2)) return std::nullopt;
    return std::sqrt(d2);
  }

 private:
  CubeHash fine_, coarse_;
};

// Each drive's dense points (away from the border) against the reference drive's: the tile's
// first (lowest point source ID) drive with dense points. One k-d tree a tile whatever the number
// of drives; the reference drive itself is not compared.
void addAgreement(const std::vector<SpillPoint>& points, double tile_size_m,
                  std::map<std::uint16_t, DriveAgreement>& agreement) {
  std::map<std::uint16_t, std::vector<Eigen::Vector3f>> dense;
  for (const SpillPoint& p : points) {
    if (p.source == io::MapCloud::kDense) dense[p.point_source_id].emplace_back(p.x, p.y, p.z);
  }
  if (dense.size() < 2) return;
  constexpr double r = DriveAgreement::kOverlapRadiusM;
  const RadiusGrid reference(dense.begin()->second, r);
  for (auto it = std::next(dense.begin()); it != dense.end(); ++it) {
    DriveAgreement& a = agreement[it->first];
    const std::vector<Eigen::Vector3f>& mine = it->second;
    // An even sample of the drive's points asks (every kQueryStride-th, at most
    // kMaxQueriesPerTile a tile): the percentages of the hundreds of thousands of samples a drive
    // gets are those of all its points to well under a percent, at a fraction of the cost
    // (nearest-neighbour queries were most of a merge's time).
    const std::size_t stride = std::max(DriveAgreement::kQueryStride,
                                        (mine.size() + DriveAgreement::kMaxQueriesPerTile - 1) /
                                            DriveAgreement::kMaxQueriesPerTile);
    for (std::size_t k = 0; k < mine.size(); k += stride) {
      const Eigen::Vector3f& m = mine[k];
      const double x = m.x(), y = m.y();
      if (x < r || y < r || x > tile_size_m - r || y > tile_size_m - r) continue;
      ++a.dense_points;
      if (const auto d = reference.nearest(m)) a.add(*d);
    }
  }
}

}  // namespace

void DriveAgreement::add(double distance_m) {
  ++overlap;
  if (distance_m <= kWithinM) ++within;
  const int bin = std::min(kBins - 1, static_cast<int>(distance_m / kOverlapRadiusM * kBins));
  ++histogram[static_cast<std::size_t>(std::max(0, bin))];
}

double DriveAgreement::medianM() const {
  if (overlap == 0) return 0.0;
  std::uint64_t seen = 0;
  for (int b = 0; b < kBins; ++b) {
    seen += histogram[static_cast<std::size_t>(b)];
    if (2 * seen >= overlap) return (b + 0.5) * kOverlapRadiusM / kBins;
  }
  return kOverlapRadiusM;
}

std::string tileName(const TileSpill& spill, const TileKey& key) {
  const Eigen::Vector2d sw = spill.southWest(key);
  return fmt::format("E{}_N{}", sw.x(), sw.y());
}

TileResult writeTile(const fs::path& out_dir, const MergeFrame& frame, const TileSpill& spill,
                     const TileKey& key, const MergeConfig& config,
                     std::map<std::uint16_t, DriveAgreement>& agreement) {
  TileResult t;
  t.key = key;
  t.name = tileName(spill, key);
  const std::vector<SpillPoint> points = spill.read(key);
  t.points = points.size();
  std::vector<std::uint64_t> per_drive(65536, 0);  // a map lookup per point cost seconds
  for (const SpillPoint& p : points) ++per_drive[p.point_source_id];
  for (std::size_t id = 0; id < per_drive.size(); ++id) {
    if (per_drive[id] != 0) t.points_per_drive[static_cast<std::uint16_t>(id)] = per_drive[id];
  }
  const fs::path stem = out_dir / "tiles" / t.name;
  const exporter::LasSummary las = exporter::writeLasUtm(
      fs::path(stem).concat(".las"), frame.crs, points.size(),
      [&](std::size_t k) -> std::optional<exporter::LasUtmPoint> {
        const SpillPoint& p = points[k];
        return exporter::LasUtmPoint{utmOf(spill, key, p), p.intensity, 0, p.point_source_id};
      });
  for (int a = 0; a < 3; ++a) {
    t.min_utm[static_cast<std::size_t>(a)] = las.min[a];
    t.max_utm[static_cast<std::size_t>(a)] = las.max[a];
  }
  writeTilePcd(fs::path(stem).concat(".pcd"), frame, spill, key, points);
  t.occupied_voxels = writeTileOctomap(fs::path(stem).concat(".bt"), frame, spill, key, points,
                                       config.octomap_resolution_m, t.octomap_note);
  t.octomap = t.octomap_note.empty();
  addAgreement(points, spill.tileSize(), agreement);
  return t;
}

}  // namespace gvio::fleet
