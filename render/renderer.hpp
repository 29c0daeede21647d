#pragma once
// Uploads a Scene to GPU buffers once (GpuScene) and draws it with any number of cameras into an
// off-screen Framebuffer (Renderer). One context renders many frames: the simulator keeps its world
// uploaded and moves the camera.
#include <memory>
#include <vector>

#include "render/egl_context.hpp"
#include "render/framebuffer.hpp"
#include "render/gl_objects.hpp"
#include "render/scene.hpp"

namespace gvio::render {

struct UploadOptions {
  // Anisotropic texture filtering keeps grazing-angle texture (the road) sharp, but on llvmpipe
  // 8x costs ~6x the frame time of a KITTI-sized view (docs/how-it-works/renderer.md); 1 = off.
  float max_anisotropy = 1.0F;
};

class GpuScene {
 public:
  // Needs a current context. Throws RenderError for inconsistent per-item vectors or textures.
  explicit GpuScene(const Scene& scene, const UploadOptions& options = {});

  [[nodiscard]] const Eigen::AlignedBox3d& bounds() const { return bounds_; }
  [[nodiscard]] bool empty() const;

 private:
  friend class Renderer;
  struct Range {
    GLint first = 0;
    GLsizei count = 0;
    bool round = true;
    std::size_t source = 0;  // index of the point cloud (or polyline) in the Scene
  };
  struct Voxels {
    GlVertexArray vao;
    GlBuffer instances;
    GLsizei count = 0;
    float size_m = 0.0F;
  };
  struct Mesh {
    GlVertexArray vao;
    GlBuffer vertices, indices;
    GLsizei index_count = 0;
    std::size_t texture = 0;
  };
  void uploadLines(const Scene& scene);
  void uploadPoints(const Scene& scene);
  void uploadVoxels(const Scene& scene);
  void uploadMeshes(const Scene& scene, float max_anisotropy);
  void uploadBatch(const std::vector<float>& vertices, const std::vector<std::uint32_t>& indices,
                   std::size_t texture);

  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();  // vertices are stored relative to it (float)
  Eigen::AlignedBox3d bounds_;
  Color background_;
  GlVertexArray line_vao_, point_vao_;
  GlBuffer line_vbo_, point_vbo_, cube_vbo_;
  std::vector<Range> strips_, segments_, point_ranges_;
  std::vector<Voxels> voxels_;
  std::vector<GlTexture> textures_;
  std::vector<bool> texture_grey_;
  std::vector<Mesh> meshes_;
};

struct DrawOptions {
  float exposure_gain = 1.0F;  // multiplies mesh texture intensities
  // Which of the scene's point clouds to draw (Scene::point_clouds order); empty: all. A large map
  // uploaded once as tiles draws only the tiles near the camera this way (render --video).
  std::vector<bool> point_clouds;
};

class Renderer {
 public:
  explicit Renderer(const EglContext& context);  // compiles the shader programs

  // Draws into `target` (its size must match the camera's).
  void draw(const GpuScene& scene, const RenderCamera& camera, Framebuffer& target,
            const DrawOptions& options = {}) const;
  ImageRgba renderColor(const GpuScene& scene, const RenderCamera& camera, Framebuffer& target,
                        const DrawOptions& options = {}) const;
  // Metric depth (camera z), 0 where nothing was drawn.
  DepthImage renderDepth(const GpuScene& scene, const RenderCamera& camera,
                         Framebuffer& target) const;

 private:
  const EglContext& context_;
  GlProgram points_, lines_, mesh_, voxels_;
};

}  // namespace gvio::render
