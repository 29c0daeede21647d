#pragma once
// Building blocks of the map views: how a run's cloud, OctoMap voxels, GNSS fixes and outages
// become render primitives. Pure functions of the run's data and the view's scale.
#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <vector>

#include "io/run_dir.hpp"
#include "render/annotate.hpp"
#include "render/camera.hpp"
#include "render/scene.hpp"

namespace gvio::viz {

// Per-axis [lo, hi] quantiles of the points: the cloud's extent without its stray points (stereo
// mismatches, far sky points), which would otherwise shrink the map to a corner. Empty box for no
// points.
Eigen::AlignedBox3d quantileBounds(const std::vector<Eigen::Vector3f>& p, double lo = 0.01,
                                   double hi = 0.99);

// Median distance from a sample of points to their nearest neighbour, searched up to `max_m`
// (returns max_m when neighbours are farther apart): sizes points so a surface reads as closed.
double typicalSpacingM(const std::vector<Eigen::Vector3f>& p, double max_m);

// Disc size (pixels) that closes the gaps of a surface sampled every `spacing_m` at
// `metres_per_pixel`, between 2 and 5 px.
float pointSizePx(double spacing_m, double metres_per_pixel);

struct CloudStyle {
  double z_lo = 0.0, z_hi = 1.0;    // height colour range (viridis)
  bool shade_by_intensity = false;  // darken by the image intensity (texture in 3-D views)
  float size_px = 2.0F;
};
// `keep`: indices of the points to draw (all when null).
render::PointCloud colouredCloud(const io::MapCloud& cloud, const CloudStyle& style,
                                 const std::vector<std::uint32_t>* keep = nullptr);

// Of the points falling into one pixel only the nearest to the camera can show (from above: the
// highest), so only it is kept: a KITTI-length map at 0.4 m per pixel keeps a few percent, and a
// perspective view's distant ground far fewer. Points off the image or behind the camera go too.
// Pixels are grouped into cells of a few when the image is huge, to bound the memory.
// `among`: the candidate indices (all points when null).
std::vector<std::uint32_t> nearestPerPixel(const std::vector<Eigen::Vector3f>& p,
                                           const render::RenderCamera& camera,
                                           const std::vector<std::uint32_t>* among = nullptr);
// Indices of the dense stereo points (all points when the cloud has no `source` field).
std::vector<std::uint32_t> densePointIndices(const io::MapCloud& cloud);
// Whether the cloud has a `source` field with dense points in it.
bool hasDensePoints(const io::MapCloud& cloud);

// Heading (radians from east towards north) at the start of a trajectory: from the first pose
// to the first one at least 5 m away; nullopt when it never moves that far.
std::optional<double> startHeadingRad(const std::vector<Eigen::Vector3d>& path);

// GNSS fixes as discs with a dark rim, for a top-down view (heights only order the layers):
// used ones at z_used (beneath the trajectory), rejected and not fused ones at z_others (above
// it). Fixes without finite coordinates are counted in the legend but not drawn.
void addGnssFixes(const std::vector<io::GnssFixRecord>& fixes, double z_used, double z_others,
                  std::vector<render::PointCloud>& clouds,
                  std::vector<render::LegendEntry>& legend);

// The parts of a trajectory inside the outages (with the poses bracketing each, so the stretch
// covers the whole gap), in the outage colour, at height `z` when given.
std::vector<render::Polyline> outageStretches(const Trajectory& traj,
                                              const std::vector<io::TimeSpan>& outages,
                                              std::optional<double> z);
render::LegendEntry outageLegend();

// Occupied voxels merged into cells of at least `min_size_m` (OctoMap's lattice: cells of
// resolution * 2^k, aligned at multiples of their size, as its inner nodes are), one voxel set
// per size. Colour: the ColorOcTree's (averaged), or height (viridis over [z_lo, z_hi]).
struct VoxelStyle {
  double min_size_m = 0.0;
  bool tree_colour = true;
  double z_lo = 0.0, z_hi = 1.0;
};
std::vector<render::VoxelSet> voxelSets(const io::OccupancyMap& map, const VoxelStyle& style);
// Whether the ColorOcTree's colours carry information (not all the same).
bool hasVaryingColour(const io::OccupancyMap& map);

// The cell size voxelSets would use: resolution * 2^k, the smallest not below min_size_m.
double lodCellSize(double resolution_m, double min_size_m);

}  // namespace gvio::viz
