#include "export/las_writer.hpp"

#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "export/gdal_support.hpp"
#include "io/atomic_write.hpp"
#include "odometry/error.hpp"

namespace gvio::exporter {
namespace {

// LAS is little-endian throughout; the writer copies host values byte for byte.
static_assert(std::endian::native == std::endian::little,
              "LAS writer assumes a little-endian host");

constexpr std::uint16_t kHeaderSize = 375;  // LAS 1.4 public header block
constexpr std::uint16_t kVlrHeaderSize = 54;
constexpr std::uint8_t kPointFormat = 6;  // X Y Z, intensity, returns, class, GPS time
constexpr std::uint16_t kPointSize = 30;
// Bit 0: GPS times are adjusted standard GPS time (they are all 0 here: a map point aggregates many
// keyframes); bit 3: return numbers are synthetic (not a lidar); bit 4: the CRS is OGC WKT, which
// point formats 6-10 require (GeoTIFF keys are not allowed with them).
constexpr std::uint16_t kGlobalEncoding = 0x1 | 0x8 | 0x10;
constexpr std::uint16_t kWktRecordId = 2112;  // "OGC Coordinate System WKT"

class Bytes {
 public:
  template <typename T>
  void put(T value) {
    char raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    data_.append(raw, sizeof(T));
  }
  // A fixed-width character field, null padded (and truncated to leave at least one null).
  void putText(std::string_view text, std::size_t width) {
    const std::size_t n = std::min(text.size(), width - 1);
    data_.append(text.substr(0, n));
    data_.append(width - n, '\0');
  }
  void putZeros(std::size_t n) { data_.append(n, '\0'); }
  void append(const char* raw, std::size_t n) { data_.append(raw, n); }
  [[nodiscard]] const std::string& data() const { return data_; }
  void clear() { data_.clear(); }

 private:
  std::string data_;
};

// The LAS integer grid: stored = offset + scale * steps, steps int32.
struct Quantized {
  double scale = 0.001;
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  Eigen::Vector3d min = Eigen::Vector3d::Zero(), max = Eigen::Vector3d::Zero();  // stored values

  [[nodiscard]] Eigen::Matrix<std::int32_t, 3, 1> steps(const Eigen::Vector3d& p) const {
    return ((p - offset) / scale).array().round().cast<std::int32_t>();
  }
};

// Offsets at the centre of the data (UTM bounds lo..hi), rounded to whole metres, keep the 32-bit
// records small and the stored coordinates exact multiples of the scale. Rounding is monotonic,
// so the stored bounds are the bounds' own grid values, and a grid that holds them holds every
// point.
Quantized quantizer(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double scale) {
  Quantized q;
  q.scale = scale;
  if (!lo.allFinite() || !hi.allFinite()) return q;  // no point
  q.offset = (0.5 * (lo + hi)).array().round();
  constexpr double kMax = std::numeric_limits<std::int32_t>::max();
  for (const Eigen::Vector3d& p : {lo, hi}) {
    const Eigen::Vector3d steps = ((p - q.offset) / scale).array().round();
    if (!steps.allFinite() || steps.cwiseAbs().maxCoeff() > kMax) {
      throw InvalidInput("LAS: map spans more than the 32-bit coordinate grid holds at scale " +
                         std::to_string(scale) + " m");
    }
  }
  q.min = q.steps(lo).cast<double>() * scale + q.offset;
  q.max = q.steps(hi).cast<double>() * scale + q.offset;
  return q;
}

std::pair<std::uint16_t, std::uint16_t> todayDayOfYearAndYear() {
  using namespace std::chrono;
  const sys_days today = floor<days>(system_clock::now());
  const year_month_day ymd(today);
  const sys_days jan1 = ymd.year() / January / 1;
  return {static_cast<std::uint16_t>((today - jan1).count() + 1),
          static_cast<std::uint16_t>(static_cast<int>(ymd.year()))};
}

std::string header(const Quantized& q, std::uint64_t n, std::uint32_t offset_to_points) {
  Bytes b;
  for (const char c : std::string_view("LASF")) b.put(c);  // 4 characters, no terminator
  b.put<std::uint16_t>(0);  // file source ID: an aggregate map, none assigned
  b.put(kGlobalEncoding);
  b.putZeros(16);  // project GUID
  b.put<std::uint8_t>(1);
  b.put<std::uint8_t>(4);
  b.putText("OTHER", 32);  // system identifier for software-generated data
  b.putText(std::string("gvio ") + GVIO_VERSION, 32);
  const auto [day, year] = todayDayOfYearAndYear();
  b.put(day);
  b.put(year);
  b.put(kHeaderSize);
  b.put(offset_to_points);
  b.put<std::uint32_t>(1);  // VLRs
  b.put(kPointFormat);
  b.put(kPointSize);
  // Legacy point counts must be 0 for point formats >= 6 (LAS 1.4 R15, "Legacy Number of Point
  // Records"): readers take the 64-bit counts below.
  b.putZeros(4 + 5 * 4);
  for (int i = 0; i < 3; ++i) b.put(q.scale);
  for (int i = 0; i < 3; ++i) b.put(q.offset[i]);
  for (int i = 0; i < 3; ++i) {
    b.put(q.max[i]);
    b.put(q.min[i]);
  }
  b.put<std::uint64_t>(0);  // no waveform data
  b.put<std::uint64_t>(0);  // no EVLRs
  b.put<std::uint32_t>(0);
  b.put(n);
  b.put(n);  // every point is a first (and only) return
  b.putZeros(14 * 8);
  if (b.data().size() != kHeaderSize) throw std::logic_error("LAS header layout");
  return b.data();
}

std::string wktVlr(const std::string& wkt) {
  Bytes b;
  b.put<std::uint16_t>(0);
  b.putText("LASF_Projection", 16);
  b.put(kWktRecordId);
  b.put(static_cast<std::uint16_t>(wkt.size() + 1));  // the WKT is null-terminated
  b.putText("OGC WKT coordinate system", 32);
  if (b.data().size() != kVlrHeaderSize) throw std::logic_error("LAS VLR header layout");
  return b.data() + wkt + '\0';
}

// One record of point format 6, assembled in place (a merge writes hundreds of millions).
void putPoint(Bytes& b, const Eigen::Matrix<std::int32_t, 3, 1>& xyz, const LasUtmPoint& p) {
  char r[kPointSize] = {};
  std::memcpy(r, xyz.data(), 12);
  std::memcpy(r + 12, &p.intensity, 2);
  r[14] = 0x11;  // return 1 of 1; r[15]: classification flags, channel, scan direction, edge
  std::memcpy(r + 16, &p.classification, 1);
  // r[17] user data, r[18..19] scan angle: 0
  std::memcpy(r + 20, &p.point_source_id, 2);
  // r[22..29] GPS time: 0
  b.append(r, kPointSize);
}

}  // namespace

Eigen::Vector3d enuToUtm(const fusion::EnuFrame& enu, const Eigen::Vector3d& p_enu, int zone,
                         bool north) {
  const fusion::Lla lla = enu.toLla(p_enu);
  const fusion::Utm utm = fusion::llaToUtm(lla, zone, north);
  return {utm.easting_m, utm.northing_m, lla.h_ellipsoid_m};
}

LasSummary writeLasUtm(const std::filesystem::path& file, const fusion::Utm& crs, std::size_t n,
                       const LasUtmPointAt& point_at, double scale_m) {
  if (!(scale_m > 0.0)) throw InvalidInput("LAS: scale must be positive");
  LasSummary summary;
  summary.crs = crs;
  const std::string wkt = wktFromEpsg(summary.crs.epsg());
  // Pass 1: the bounds.
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (std::size_t k = 0; k < n; ++k) {
    const std::optional<LasUtmPoint> p = point_at(k);
    if (!p) continue;
    if (!p->p_utm.allFinite()) throw InvalidInput("LAS: a point has a non-finite coordinate");
    lo = lo.cwiseMin(p->p_utm);
    hi = hi.cwiseMax(p->p_utm);
    ++summary.points;
  }
  const Quantized q = quantizer(lo, hi, scale_m);
  summary.min = q.min;
  summary.max = q.max;

  // Pass 2: the records, in chunks of about 1 MB.
  const std::string vlr = wktVlr(wkt);
  const auto offset_to_points = static_cast<std::uint32_t>(kHeaderSize + vlr.size());
  io::writeFileAtomic(file, [&](std::ostream& out) {
    out << header(q, summary.points, offset_to_points) << vlr;
    Bytes chunk;
    for (std::size_t k = 0; k < n; ++k) {
      const std::optional<LasUtmPoint> p = point_at(k);
      if (!p) continue;
      putPoint(chunk, q.steps(p->p_utm), *p);
      if (chunk.data().size() >= (1u << 20)) {
        out << chunk.data();
        chunk.clear();
      }
    }
    out << chunk.data();
  });
  return summary;
}

LasSummary writeLas(const std::filesystem::path& file, const fusion::Lla& enu_origin, std::size_t n,
                    const LasPointAt& point_at, const LasOptions& options) {
  fusion::Utm crs = options.utm_zone ? fusion::llaToUtm(enu_origin, *options.utm_zone)
                                     : fusion::llaToUtm(enu_origin);
  if (options.utm_north) crs.north = *options.utm_north;
  const fusion::EnuFrame enu(enu_origin);
  LasSummary summary = writeLasUtm(
      file, crs, n,
      [&](std::size_t k) -> std::optional<LasUtmPoint> {
        const std::optional<LasPoint> p = point_at(k);
        if (!p) return std::nullopt;
        return LasUtmPoint{enuToUtm(enu, p->p_enu, crs.zone, crs.north), p->intensity,
                           p->classification, p->point_source_id};
      },
      options.scale_m);
  summary.crs = crs;  // with the origin's easting and northing
  return summary;
}

LasSummary writeLas(const std::filesystem::path& file, const fusion::Lla& enu_origin,
                    std::span<const LasPoint> points, const LasOptions& options) {
  return writeLas(
      file, enu_origin, points.size(),
      [points](std::size_t k) { return std::optional<LasPoint>(points[k]); }, options);
}

}  // namespace gvio::exporter
