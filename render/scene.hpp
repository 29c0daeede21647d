#pragma once
// What the renderer can draw, as plain data in a world frame (ENU metres for maps). Colours are
// linear RGBA in [0, 1]. Per-item colour/size vectors hold nothing (the default), one value for
// all items, or one value each.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "render/camera.hpp"

namespace gvio::render {

using Color = Eigen::Vector4f;

struct Polyline {  // trajectories
  std::vector<Eigen::Vector3d> points;
  std::vector<Color> colors;     // default white
  std::vector<float> widths_px;  // default 2 px
};

struct PointCloud {
  std::vector<Eigen::Vector3d> points;
  std::vector<Color> colors;    // default white
  std::vector<float> sizes_px;  // default 2 px
  bool round = true;            // discs instead of squares
};

// Axis-aligned cubes (OctoMap leaves), drawn instanced. Faces two opaque voxels of one set share
// on its lattice (spacing size_m, from the first centre) are never drawn: a voxel map is a solid.
struct VoxelSet {
  std::vector<Eigen::Vector3d> centers;
  std::vector<Color> colors;  // default light grey
  double size_m = 0.2;
};

struct Frustum {  // a camera's viewing pyramid cut at depth_m
  Eigen::Isometry3d T_w_c = Eigen::Isometry3d::Identity();
  PinholeIntrinsics K;
  double depth_m = 1.0;
  Color color{1, 0.5F, 0, 1};
  float width_px = 1.5F;
};

struct GroundGrid {  // square grid on the plane z = center.z()
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double spacing_m = 10.0;
  int half_cells = 10;
  Color color{0.5F, 0.5F, 0.5F, 1};
  float width_px = 1.0F;
};

struct Texture {  // 8-bit, rows top to bottom; 1 (grey), 3 (RGB) or 4 (RGBA) channels
  int width = 0, height = 0, channels = 1;
  std::vector<std::uint8_t> data;
};

struct TexturedMesh {  // triangles; uv in texture units (repeat wraps)
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Eigen::Vector2f> uv;
  std::vector<std::uint32_t> indices;
  std::size_t texture = 0;  // index into Scene::textures
};

struct Scene {
  std::vector<Polyline> polylines;
  std::vector<PointCloud> point_clouds;
  std::vector<VoxelSet> voxel_sets;
  std::vector<Frustum> frusta;
  std::vector<GroundGrid> grids;
  std::vector<Texture> textures;
  std::vector<TexturedMesh> meshes;
  Color background{1, 1, 1, 1};

  // Extent of everything drawable (frusta and grids excluded); empty when there is nothing.
  [[nodiscard]] Eigen::AlignedBox3d bounds() const;
};

}  // namespace gvio::render
