#pragma once
// Carries a map built with one set of keyframe poses onto corrected ones (gvio merge's joint
// alignment): a point moves rigidly with the keyframe nearest to it, p' = T_new T_old^-1 p. A map
// point is fused from many keyframes' views, so it has no one keyframe; but the correction varies
// slowly along a drive (the pose graph spreads it over hundreds of metres), so the nearest
// keyframe's is the correction of the place, within the change between neighbouring keyframes.
// Nearest is in the horizontal plane (a car's keyframes lie on the road below the points it saw).
// Lookups go through a grid of cell_m cells, each resolved once by a kd-tree search from its
// centre (tens of nanoseconds per point for a map of millions of points).
#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <unordered_map>
#include <vector>

namespace gvio::mapping {

class MapCorrection {
 public:
  // Parallel: the poses the map was built with and the corrected ones (same frame), >= 1.
  MapCorrection(const std::vector<Eigen::Isometry3d>& T_old,
                const std::vector<Eigen::Isometry3d>& T_new, double cell_m = 2.0);
  ~MapCorrection();
  MapCorrection(MapCorrection&&) noexcept;
  MapCorrection& operator=(MapCorrection&&) noexcept;

  [[nodiscard]] Eigen::Vector3d apply(const Eigen::Vector3d& p);
  // The keyframe whose correction applies at p.
  [[nodiscard]] std::size_t keyframeAt(const Eigen::Vector3d& p);

 private:
  struct Tree;
  std::vector<Eigen::Isometry3d> delta_;  // T_new T_old^-1 per keyframe
  std::unique_ptr<Tree> tree_;
  double cell_m_;
  std::unordered_map<std::uint64_t, std::uint32_t> cells_;
};

}  // namespace gvio::mapping
