// Voxel drawing for OctoMap views: back faces are culled and faces between lattice neighbours of
// one set are dropped before rasterisation; neither may change what the image shows.
#include <gtest/gtest.h>

#include <memory>

#include "render/renderer.hpp"
#include "support/render_fixture.hpp"

namespace gvio::render {
namespace {

class RenderMapVoxels : public test::SharedRendererTest {
 protected:
  static ImageRgba draw(const Scene& s, const RenderCamera& cam) {
    const GpuScene gpu(s);
    Framebuffer fb(cam.width, cam.height);
    return renderer_->renderColor(gpu, cam, fb);
  }
};

// A seen-from-above voxel shows its top face, Lambert-lit from (0.3, 0.5, 0.8): if culling took
// the wrong winding, the inside of the bottom face (ambient 0.45 only) would show instead.
TEST_F(RenderMapVoxels, TopFaceFacesTheCamera) {
  Scene s;
  VoxelSet v;
  v.centers = {{0, 0, 0}};
  v.size_m = 2.0;
  v.colors = {Color(1.0F, 0.5F, 0.0F, 1)};
  s.voxel_sets.push_back(v);
  const RenderCamera cam = topDownCamera(
      Eigen::AlignedBox3d(Eigen::Vector3d(-2, -2, -1), Eigen::Vector3d(2, 2, 1)), 64, 64);
  const ImageRgba img = draw(s, cam);
  const double lambert = 0.8 / Eigen::Vector3d(0.3, 0.5, 0.8).norm();
  EXPECT_NEAR(img.pixel(32, 32)[0], 255.0 * (0.45 + 0.55 * lambert), 1.5);
  EXPECT_NEAR(img.pixel(32, 32)[1], 127.5 * (0.45 + 0.55 * lambert), 1.5);
}

// A solid block in one set (inner faces dropped) and the same voxels one set each (nothing
// dropped) render alike, from above and obliquely; an off-lattice voxel overlapping the block
// hides nothing of it.
TEST_F(RenderMapVoxels, DroppedInnerFacesLeaveTheImageUnchanged) {
  VoxelSet block;
  block.size_m = 1.0;
  for (int i = 0; i < 6 * 6 * 3; ++i) {
    block.centers.emplace_back(0.5 + i % 6, 0.5 + (i / 6) % 6, 0.5 + i / 36);
    block.colors.emplace_back(0.2F + 0.1F * static_cast<float>(i % 6), 0.6F, 0.3F, 1.0F);
  }
  block.centers.emplace_back(6.3, 3.5, 0.5);  // off the lattice, touching the block's +x side
  block.colors.emplace_back(0.9F, 0.1F, 0.1F, 1.0F);
  Scene one, separate;
  one.voxel_sets.push_back(block);
  for (std::size_t i = 0; i < block.centers.size(); ++i) {
    VoxelSet single;
    single.size_m = 1.0;
    single.centers = {block.centers[i]};
    single.colors = {block.colors[i]};
    separate.voxel_sets.push_back(single);
  }
  const Eigen::AlignedBox3d box(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(7, 6, 3));
  for (const RenderCamera& cam :
       {orbitCamera(box, 200, 150), orbitCamera(box, 200, 150, 150.0, 60.0),
        topDownCamera(box, 200, 150)}) {
    const ImageRgba a = draw(one, cam), b = draw(separate, cam);
    int differ = 0, drawn = 0;
    for (std::size_t i = 0; i < a.rgba.size(); i += 4) {
      int d = 0;
      for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(a.rgba[i + c] - b.rgba[i + c]));
      differ += d > 24 ? 1 : 0;
      drawn += a.rgba[i] < 250 ? 1 : 0;
    }
    EXPECT_GT(drawn, 2000);  // the block is in view
    // Inner and outer faces meet at the block's edges, where a sample may take either.
    EXPECT_LE(differ, 20) << "of " << drawn << " drawn pixels";
  }
}

}  // namespace
}  // namespace gvio::render
