#pragma once
// Triangle meshes as binary PLY (float32 vertices, int32 triangle indices) through PCL, so
// CloudCompare, MeshLab and PCL read them. Written atomically.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <filesystem>
#include <vector>

namespace gvio::io {

struct TriangleMesh {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;
};

void writeMeshPly(const std::filesystem::path& file, const TriangleMesh& mesh);
// Throws InputError when the file is missing, unreadable or has no triangle faces.
TriangleMesh readMeshPly(const std::filesystem::path& file);

}  // namespace gvio::io
