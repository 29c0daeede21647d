#pragma once
// The point type of the exported map (map.pcd, map.ply): position in the map frame (local ENU,
// float32), grey intensity 0..255, the landmark's observation count (0 for dense points) and its
// source (0 sparse VIO landmark, 1 dense stereo point). PCL_ADD_POINT4D keeps it usable by every
// PCL algorithm that needs getVector3fMap() (transforms; kd-trees and filters after
// #define PCL_NO_PRECOMPILE). 32 bytes per point, like pcl::PointXYZI.
#include <cstdint>

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/register_point_struct.h>

namespace gvio::mapping {

enum class MapPointSource : std::uint8_t { kSparseLandmark = 0, kDenseStereo = 1 };

struct EIGEN_ALIGN16 MapPoint {
  PCL_ADD_POINT4D;
  float intensity = 0.0f;
  std::uint32_t observations = 0;
  std::uint8_t source = 0;
  PCL_MAKE_ALIGNED_OPERATOR_NEW
};

using MapCloud = pcl::PointCloud<MapPoint>;

[[nodiscard]] MapPoint makeMapPoint(float x, float y, float z, float intensity,
                                    std::uint32_t observations, MapPointSource source);

}  // namespace gvio::mapping

POINT_CLOUD_REGISTER_POINT_STRUCT(
    gvio::mapping::MapPoint,
    (float, x, x)(float, y, y)(float, z, z)(float, intensity,
                                            intensity)(std::uint32_t, observations,
                                                       observations)(std::uint8_t, source, source))
