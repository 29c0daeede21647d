#include "render/scene.hpp"

namespace gvio::render {

Eigen::AlignedBox3d Scene::bounds() const {
  Eigen::AlignedBox3d box;
  for (const auto& l : polylines) {
    for (const auto& p : l.points) box.extend(p);
  }
  for (const auto& c : point_clouds) {
    for (const auto& p : c.points) box.extend(p);
  }
  for (const auto& v : voxel_sets) {
    for (const auto& p : v.centers) {
      box.extend(p - Eigen::Vector3d::Constant(0.5 * v.size_m));
      box.extend(p + Eigen::Vector3d::Constant(0.5 * v.size_m));
    }
  }
  for (const auto& m : meshes) {
    for (const auto& p : m.vertices) box.extend(p);
  }
  return box;
}

}  // namespace gvio::render
