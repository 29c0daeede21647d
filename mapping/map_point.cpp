#include "mapping/map_point.hpp"

namespace gvio::mapping {

MapPoint makeMapPoint(float x, float y, float z, float intensity, std::uint32_t observations,
                      MapPointSource source) {
  MapPoint p;
  p.x = x;
  p.y = y;
  p.z = z;
  p.data[3] = 1.0f;  // homogeneous coordinate, as pcl::PointXYZ sets it
  p.intensity = intensity;
  p.observations = observations;
  p.source = static_cast<std::uint8_t>(source);
  return p;
}

}  // namespace gvio::mapping
