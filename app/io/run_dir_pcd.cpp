// map.pcd of a run folder through PCL (pcl::io::loadPCDFile into a PCLPointCloud2, fields taken
// by name). PCL 1.13 reads past a header without a DATA line and crashes on such a file, and
// prints multi-line complaints of its own, so the header (PCD v0.7 spec, pointclouds.org) and the
// data length are checked here first.
#include <pcl/PCLPointCloud2.h>
#include <pcl/io/pcd_io.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "io/input_error.hpp"
#include "io/pcl_checks.hpp"
#include "io/quiet_pcl.hpp"
#include "io/run_dir.hpp"

namespace gvio::io {
namespace fs = std::filesystem;
namespace {

struct FieldReader {
  std::uint32_t offset = 0;
  std::uint8_t datatype = 0;

  template <typename T>
  static double load(const std::uint8_t* p) {
    T v;
    std::memcpy(&v, p, sizeof(T));
    return static_cast<double>(v);
  }
  [[nodiscard]] double operator()(const std::uint8_t* point) const {
    const std::uint8_t* p = point + offset;
    using F = pcl::PCLPointField;
    switch (datatype) {
      case F::INT8:
        return load<std::int8_t>(p);
      case F::UINT8:
        return load<std::uint8_t>(p);
      case F::INT16:
        return load<std::int16_t>(p);
      case F::UINT16:
        return load<std::uint16_t>(p);
      case F::INT32:
        return load<std::int32_t>(p);
      case F::UINT32:
        return load<std::uint32_t>(p);
      case F::FLOAT64:
        return load<double>(p);
      default:
        return load<float>(p);  // FLOAT32 (others are refused in findField)
    }
  }
};

std::size_t fieldBytes(std::uint8_t datatype) {
  using F = pcl::PCLPointField;
  switch (datatype) {
    case F::INT8:
    case F::UINT8:
      return 1;
    case F::INT16:
    case F::UINT16:
      return 2;
    case F::INT32:
    case F::UINT32:
    case F::FLOAT32:
      return 4;
    case F::FLOAT64:
      return 8;
    default:
      return 0;
  }
}

std::optional<FieldReader> findField(const pcl::PCLPointCloud2& cloud, const std::string& name,
                                     const fs::path& file) {
  for (const auto& f : cloud.fields) {
    if (f.name != name) continue;
    const std::size_t bytes = fieldBytes(f.datatype);
    if (bytes == 0 || f.offset + bytes > cloud.point_step) {
      throw InputError(file, 0, "PCD field '" + name + "' has an unsupported type or layout");
    }
    return FieldReader{f.offset, f.datatype};
  }
  return std::nullopt;
}

}  // namespace

MapCloud readMapCloud(const fs::path& file) {
  if (!fs::is_regular_file(file)) throw InputError(file, 0, "file not found");
  if (checkPcdFile(file) == 0) return {};  // an empty map: nothing for PCL to read
  pcl::PCLPointCloud2 cloud;
  bool loaded = false;
  try {
    const QuietPcl quiet;  // the message below is the one line users see
    loaded = pcl::io::loadPCDFile(file.string(), cloud) >= 0;
  } catch (const std::exception&) {  // some PCL paths throw pcl::IOException instead
    loaded = false;
  }
  if (!loaded) throw InputError(file, 0, "not a readable PCD file");
  const auto x = findField(cloud, "x", file), y = findField(cloud, "y", file),
             z = findField(cloud, "z", file);
  if (!x || !y || !z) throw InputError(file, 0, "PCD has no x, y and z fields");
  const auto intensity = findField(cloud, "intensity", file);
  const auto source = findField(cloud, "source", file);
  const std::size_t n = static_cast<std::size_t>(cloud.width) * cloud.height;
  if (cloud.data.size() < n * cloud.point_step) {
    throw InputError(file, 0, "PCD data is shorter than its header says");
  }
  MapCloud map;
  map.p_enu.reserve(n);
  if (intensity) map.intensity.reserve(n);
  if (source) map.source.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint8_t* p = cloud.data.data() + i * cloud.point_step;
    const Eigen::Vector3d q((*x)(p), (*y)(p), (*z)(p));
    if (!q.allFinite()) continue;  // unorganised NaN padding
    // Double fields beyond float's range would become infinite here (found by fuzzing).
    const Eigen::Vector3f q_f = q.cast<float>();
    const float value = intensity ? static_cast<float>((*intensity)(p)) : 0.0F;
    if (!q_f.allFinite() || !std::isfinite(value)) {
      throw InputError(file, 0,
                       "point " + std::to_string(i) + ": a value that is not finite as a float");
    }
    map.p_enu.push_back(q_f);
    if (intensity) map.intensity.push_back(value);
    if (source) {
      map.source.push_back(static_cast<std::uint8_t>(std::clamp((*source)(p), 0.0, 255.0)));
    }
  }
  return map;
}

}  // namespace gvio::io
