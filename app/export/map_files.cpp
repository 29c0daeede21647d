#include "export/map_files.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <octomap/AbstractOcTree.h>
#include <octomap/OcTree.h>
#include <pcl/common/io.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <memory>

#include "io/atomic_write.hpp"
#include "io/input_error.hpp"
#include "io/pcl_checks.hpp"
#include "io/quiet_pcl.hpp"
#include "io/quiet_stderr.hpp"
#include "io/run_dir.hpp"

namespace gvio::exporter {
namespace {
namespace fs = std::filesystem;

template <typename F>
auto quietly(F&& f) {
  const io::QuietStderr quiet;
  return f();
}

double fieldValue(const std::uint8_t* data, std::uint8_t datatype) {
  auto as = [data]<typename T>(T) {
    T v;
    std::memcpy(&v, data, sizeof(T));
    return static_cast<double>(v);
  };
  switch (datatype) {
    case pcl::PCLPointField::INT8:
      return as(std::int8_t{});
    case pcl::PCLPointField::UINT8:
      return as(std::uint8_t{});
    case pcl::PCLPointField::INT16:
      return as(std::int16_t{});
    case pcl::PCLPointField::UINT16:
      return as(std::uint16_t{});
    case pcl::PCLPointField::INT32:
      return as(std::int32_t{});
    case pcl::PCLPointField::UINT32:
      return as(std::uint32_t{});
    case pcl::PCLPointField::FLOAT32:
      return as(float{});
    case pcl::PCLPointField::FLOAT64:
      return as(double{});
    default:
      return std::nan("");
  }
}

const pcl::PCLPointField* findField(const pcl::PCLPointCloud2& cloud, const std::string& name) {
  const int index = pcl::getFieldIndex(cloud, name);
  return index < 0 ? nullptr : &cloud.fields[static_cast<std::size_t>(index)];
}

bool isFloat(const pcl::PCLPointField& f) {
  return f.datatype == pcl::PCLPointField::FLOAT32 || f.datatype == pcl::PCLPointField::FLOAT64;
}

// Intensity to LAS's 16-bit range (LAS 1.4: "normalized to 16 bits").
double intensityScale(const pcl::PCLPointField& f, double max_value) {
  switch (f.datatype) {
    case pcl::PCLPointField::INT8:
    case pcl::PCLPointField::UINT8:
      return 257.0;
    case pcl::PCLPointField::FLOAT32:
    case pcl::PCLPointField::FLOAT64:
      if (max_value <= 1.0) return 65535.0;
      if (max_value <= 255.0) return 257.0;
      return 1.0;
    default:
      return 1.0;
  }
}

OctreeSummary summarize(const octomap::AbstractOcTree& tree) {
  OctreeSummary s;
  s.type = tree.getTreeType();
  s.resolution_m = tree.getResolution();
  s.nodes = tree.size();
  if (const auto* occupancy = dynamic_cast<const octomap::OcTree*>(&tree)) {
    s.leaves = occupancy->getNumLeafNodes();
  }
  return s;
}

void checkReadable(const fs::path& file) {
  if (!fs::exists(file)) throw io::InputError(file, 0, "file not found");
  if (fs::is_directory(file)) throw io::InputError(file, 0, "is a folder, not a file");
}

}  // namespace

pcl::PCLPointCloud2 readPointCloud2(const fs::path& file) {
  checkReadable(file);
  if (file.extension() == ".ply") {
    io::checkPlyFile(file);
  } else {
    io::checkPcdFile(file);
  }
  pcl::PCLPointCloud2 cloud;
  int rc = -1;
  {
    const io::QuietPcl quiet;
    try {
      if (file.extension() == ".ply") {
        pcl::PLYReader reader;
        rc = reader.read(file.string(), cloud);
      } else {
        pcl::PCDReader reader;
        rc = reader.read(file.string(), cloud);
      }
    } catch (const std::exception&) {  // some PCL paths throw pcl::IOException instead
      rc = -1;
    }
  }
  if (rc < 0) throw io::InputError(file, 0, "not a readable point cloud");
  for (const char* axis : {"x", "y", "z"}) {
    const pcl::PCLPointField* f = findField(cloud, axis);
    if (f == nullptr || !isFloat(*f)) {
      throw io::InputError(file, 0, std::string("no float '") + axis + "' field");
    }
  }
  if (static_cast<std::size_t>(cloud.width) * cloud.height == 0) {
    throw io::InputError(file, 0, "map is empty (0 points)");
  }
  return cloud;
}

void writePcd(const fs::path& file, const pcl::PCLPointCloud2& cloud) {
  io::writeFileAtomic(file, [&](std::ostream& out) {
    pcl::PCDWriter writer;
    if (writer.writeBinaryCompressed(out, cloud) != 0) {
      if (!out) return;  // the stream failed (disk full, size limit): writeFileAtomic reports it
      throw io::InputError(file, 0, "PCL could not encode the cloud as binary compressed PCD");
    }
  });
}

namespace {

// What PCL's binary PLY writer (io/src/ply_io.cpp, writeBinary) puts after the header per point:
// each field but padding ("_"), a uint count first when it has several elements, a float "rgb"
// as three uchar (red, green, blue).
std::uint64_t plyBodyBytes(const pcl::PCLPointCloud2& cloud) {
  std::uint64_t point_bytes = 0;
  for (const pcl::PCLPointField& f : cloud.fields) {
    if (f.name == "_") continue;
    const std::uint64_t count = std::max<std::uint32_t>(f.count, 1);
    const bool rgb =
        f.datatype == pcl::PCLPointField::FLOAT32 && f.name.find("rgb") != std::string::npos;
    point_bytes += (count > 1 ? sizeof(std::uint32_t) : 0) +
                   count * (rgb ? 3 : static_cast<std::uint64_t>(pcl::getFieldSize(f.datatype)));
  }
  return point_bytes * cloud.width * cloud.height;
}

}  // namespace

void writePly(const fs::path& file, const pcl::PCLPointCloud2& cloud) {
  io::writeViaPathAtomic(file, ".ply", [&](const fs::path& tmp) {
    int rc = -1;
    {
      const io::QuietPcl quiet;
      rc = pcl::PLYWriter().writeBinary(tmp.string(), cloud, Eigen::Vector4f::Zero(),
                                        Eigen::Quaternionf::Identity(), false);  // no camera
    }
    if (rc != 0) throw io::InputError(file, 0, "cannot write (missing directory or no permission)");
    io::checkWrittenPly(tmp, file, plyBodyBytes(cloud));
  });
}

LasPointAt lasPointSource(const pcl::PCLPointCloud2& cloud) {
  const pcl::PCLPointField* fx = findField(cloud, "x");
  const pcl::PCLPointField* fy = findField(cloud, "y");
  const pcl::PCLPointField* fz = findField(cloud, "z");
  const pcl::PCLPointField* fi = findField(cloud, "intensity");
  if (fx == nullptr || fy == nullptr || fz == nullptr) {
    return [](std::size_t) { return std::optional<LasPoint>(); };
  }
  auto at = [&cloud](std::size_t k, const pcl::PCLPointField& f) {
    const std::size_t row = k / cloud.width, col = k % cloud.width;
    return fieldValue(&cloud.data[row * cloud.row_step + col * cloud.point_step + f.offset],
                      f.datatype);
  };
  const std::size_t n = static_cast<std::size_t>(cloud.width) * cloud.height;
  double max_intensity = 0.0;
  if (fi != nullptr) {
    for (std::size_t k = 0; k < n; ++k) max_intensity = std::max(max_intensity, at(k, *fi));
  }
  const double scale = fi != nullptr ? intensityScale(*fi, max_intensity) : 0.0;
  return [=](std::size_t k) -> std::optional<LasPoint> {
    LasPoint p;
    p.p_enu = {at(k, *fx), at(k, *fy), at(k, *fz)};
    if (!p.p_enu.allFinite()) return std::nullopt;  // PCL marks invalid points with NaN
    if (fi != nullptr) {
      const double v = at(k, *fi) * scale;
      p.intensity = std::isfinite(v)
                        ? static_cast<std::uint16_t>(std::clamp(std::round(v), 0.0, 65535.0))
                        : 0;
    }
    return p;
  };
}

LasSummary writeMapLas(const fs::path& file, const pcl::PCLPointCloud2& cloud, const Georef& georef,
                       const fs::path& source) {
  const std::size_t n = static_cast<std::size_t>(cloud.width) * cloud.height;
  const LasPointAt point_at = lasPointSource(cloud);
  std::size_t first = 0;
  while (first < n && !point_at(first)) ++first;
  if (first == n) throw io::InputError(source, 0, "map is empty (0 finite points)");
  LasOptions options;
  options.utm_zone = georef.utm_zone;
  options.utm_north = georef.utm_north;
  return writeLas(file, georef.enu_origin, n, point_at, options);
}

OctreeSummary copyOctreeBinary(const fs::path& in, const fs::path& out) {
  checkReadable(in);
  (void)io::readOccupancy(in);  // header and node stream checked before OctoMap recurses into it
  octomap::OcTree tree(0.1);    // the file's resolution replaces this
  std::ifstream stream(in, std::ios::binary);
  if (!stream || !quietly([&] { return tree.readBinary(stream); }))
    throw io::InputError(in, 0, "not an OctoMap binary OcTree (.bt)");
  if (tree.size() == 0) throw io::InputError(in, 0, "map is empty (0 nodes)");
  io::writeFileAtomic(out, [&](std::ostream& os) {
    if (!quietly([&] { return tree.writeBinary(os); }))
      throw io::InputError(out, 0, "OctoMap could not write the tree");
  });
  return summarize(tree);
}

OctreeSummary copyOctreeFull(const fs::path& in, const fs::path& out) {
  checkReadable(in);
  (void)io::readOccupancy(in);
  std::ifstream stream(in, std::ios::binary);
  const std::unique_ptr<octomap::AbstractOcTree> tree(
      stream ? quietly([&] { return octomap::AbstractOcTree::read(stream); }) : nullptr);
  if (!tree) throw io::InputError(in, 0, "not an OctoMap tree file (.ot)");
  if (tree->size() == 0) throw io::InputError(in, 0, "map is empty (0 nodes)");
  io::writeFileAtomic(out, [&](std::ostream& os) {
    if (!quietly([&] { return tree->write(os); }))
      throw io::InputError(out, 0, "OctoMap could not write the tree");
  });
  return summarize(*tree);
}

}  // namespace gvio::exporter
