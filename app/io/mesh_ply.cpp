#include "io/mesh_ply.hpp"

#include <fmt/format.h>

#include <pcl/PolygonMesh.h>
#include <pcl/conversions.h>
#include <pcl/io/ply_io.h>
#include <pcl/point_types.h>
#include <algorithm>
#include <string>

#include "io/atomic_write.hpp"
#include "io/input_error.hpp"
#include "io/pcl_checks.hpp"
#include "io/quiet_pcl.hpp"

namespace gvio::io {

void writeMeshPly(const std::filesystem::path& file, const TriangleMesh& mesh) {
  pcl::PointCloud<pcl::PointXYZ> cloud;
  cloud.reserve(mesh.vertices.size());
  for (const auto& v : mesh.vertices) {
    cloud.emplace_back(static_cast<float>(v.x()), static_cast<float>(v.y()),
                       static_cast<float>(v.z()));
  }
  pcl::PolygonMesh pm;
  pcl::toPCLPointCloud2(cloud, pm.cloud);
  pm.polygons.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    pcl::Vertices face;
    for (const std::uint32_t idx : t) face.vertices.push_back(static_cast<pcl::index_t>(idx));
    pm.polygons.push_back(face);
  }
  // x, y, z as float per vertex; per face a uchar count and its int indices.
  const std::uint64_t body = mesh.vertices.size() * 3 * sizeof(float) +
                             mesh.triangles.size() * (1 + 3 * sizeof(std::int32_t));
  // PCL writes to a path (and picks the format by extension).
  writeViaPathAtomic(file, ".ply", [&](const std::filesystem::path& tmp) {
    if (pcl::io::savePLYFileBinary(tmp.string(), pm) != 0) {
      throw InputError(file, 0, "cannot write (missing directory or no permission)");
    }
    checkWrittenPly(tmp, file, body);
  });
}

namespace {

// pcl::fromPCLPointCloud2 trusts the blob's layout: a vertex element without float x/y/z, with
// fields beyond its stride, with no vertices or with less data than it declares would be read out
// of bounds (found by fuzzing), so the layout is checked first.
bool hasFloatXyz(const pcl::PCLPointCloud2& cloud) {
  for (const char* name : {"x", "y", "z"}) {
    const auto f = std::find_if(cloud.fields.begin(), cloud.fields.end(),
                                [&](const pcl::PCLPointField& p) { return p.name == name; });
    if (f == cloud.fields.end() || f->datatype != pcl::PCLPointField::FLOAT32 || f->count < 1 ||
        std::size_t{f->offset} + 4 > cloud.point_step) {
      return false;
    }
  }
  const std::size_t n = std::size_t{cloud.width} * cloud.height;
  return n > 0 && cloud.data.size() >= n * cloud.point_step;
}

}  // namespace

TriangleMesh readMeshPly(const std::filesystem::path& file) {
  if (!std::filesystem::is_regular_file(file)) throw InputError(file, 0, "file not found");
  checkPlyFile(file);
  pcl::PolygonMesh pm;
  bool loaded = false;
  try {
    const QuietPcl quiet;
    loaded = pcl::io::loadPLYFile(file.string(), pm) == 0;
  } catch (const std::exception&) {  // some PCL paths throw pcl::IOException instead
    loaded = false;
  }
  if (!loaded) throw InputError(file, 0, "not a readable PLY mesh");
  if (!hasFloatXyz(pm.cloud)) throw InputError(file, 0, "no vertices with float x, y and z");
  pcl::PointCloud<pcl::PointXYZ> cloud;
  pcl::fromPCLPointCloud2(pm.cloud, cloud);
  TriangleMesh mesh;
  for (const auto& p : cloud) {
    mesh.vertices.emplace_back(p.x, p.y, p.z);
    if (!mesh.vertices.back().allFinite()) {
      throw InputError(file, 0, fmt::format("vertex {} is not finite", mesh.vertices.size() - 1));
    }
  }
  for (const auto& poly : pm.polygons) {
    if (poly.vertices.size() != 3) throw InputError(file, 0, "faces must be triangles");
    std::array<std::uint32_t, 3> tri{};
    for (std::size_t k = 0; k < 3; ++k) {
      const auto idx = poly.vertices[k];
      if (idx < 0 || static_cast<std::size_t>(idx) >= mesh.vertices.size()) {
        throw InputError(file, 0, "face index out of range");
      }
      tri[k] = static_cast<std::uint32_t>(idx);
    }
    mesh.triangles.push_back(tri);
  }
  if (mesh.triangles.empty()) throw InputError(file, 0, "no triangle faces");
  return mesh;
}

}  // namespace gvio::io
