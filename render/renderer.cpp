#include "render/renderer.hpp"

#include <fmt/format.h>

#include "render/render_error.hpp"
#include "render/shaders.hpp"

namespace gvio::render {
namespace {

// u_mvp maps origin-relative float vertices to clip space; composed in double precision.
Eigen::Matrix4f modelViewProjection(const RenderCamera& camera, const Eigen::Vector3d& origin) {
  Eigen::Matrix4d model = Eigen::Matrix4d::Identity();
  model.topRightCorner<3, 1>() = origin;
  return (camera.projection * camera.view * model).cast<float>();
}

void setMvp(GLuint program, const Eigen::Matrix4f& mvp) {
  glUniformMatrix4fv(glGetUniformLocation(program, "u_mvp"), 1, GL_FALSE,
                     mvp.data());  // column-major
}

}  // namespace

Renderer::Renderer(const EglContext& context)
    : context_(context),
      points_(linkProgram("points", shaders::kPointsVert, shaders::kPointsFrag)),
      lines_(linkProgram("lines", shaders::kLinesVert, shaders::kLinesFrag, shaders::kLinesGeom)),
      mesh_(linkProgram("mesh", shaders::kMeshVert, shaders::kMeshFrag)),
      voxels_(linkProgram("voxels", shaders::kVoxelsVert, shaders::kVoxelsFrag)) {}

void Renderer::draw(const GpuScene& s, const RenderCamera& camera, Framebuffer& target,
                    const DrawOptions& options) const {
  if (camera.width != target.width() || camera.height != target.height()) {
    throw RenderError(fmt::format("camera is {}x{} but the target {}x{}", camera.width,
                                  camera.height, target.width(), target.height()));
  }
  context_.makeCurrent();
  target.clear(s.background_[0], s.background_[1], s.background_[2], s.background_[3]);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LEQUAL);
  glDisable(GL_CULL_FACE);  // the pinhole projection flips handedness; draw both sides
  glEnable(GL_MULTISAMPLE);
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  const Eigen::Matrix4f mvp = modelViewProjection(camera, s.origin_);

  if (!s.meshes_.empty()) {
    glUseProgram(mesh_.get());
    setMvp(mesh_.get(), mvp);
    glUniform1i(glGetUniformLocation(mesh_.get(), "u_texture"), 0);
    glUniform1f(glGetUniformLocation(mesh_.get(), "u_gain"), options.exposure_gain);
    glActiveTexture(GL_TEXTURE0);
    for (const auto& m : s.meshes_) {
      glBindTexture(GL_TEXTURE_2D, s.textures_[m.texture].get());
      glUniform1i(glGetUniformLocation(mesh_.get(), "u_grey"), s.texture_grey_[m.texture] ? 1 : 0);
      glBindVertexArray(m.vao.get());
      glDrawElements(GL_TRIANGLES, m.index_count, GL_UNSIGNED_INT, nullptr);
    }
  }
  if (!s.voxels_.empty()) {
    glUseProgram(voxels_.get());
    setMvp(voxels_.get(), mvp);
    glUniform3f(glGetUniformLocation(voxels_.get(), "u_light_dir"), 0.3F, 0.5F, 0.8F);
    // Cubes are closed and wound counter-clockwise seen from outside; every camera here maps that
    // to counter-clockwise on screen (OpenCV frame, then y flipped to NDC), so back faces can go:
    // half the triangles of a large voxel map never reach the rasteriser.
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glFrontFace(GL_CCW);
    for (const auto& v : s.voxels_) {
      glUniform1f(glGetUniformLocation(voxels_.get(), "u_size"), v.size_m);
      glBindVertexArray(v.vao.get());
      glDrawArraysInstanced(GL_TRIANGLES, 0, 36, v.count);
    }
    glDisable(GL_CULL_FACE);
  }
  if (!s.point_ranges_.empty()) {
    glEnable(GL_PROGRAM_POINT_SIZE);
    glUseProgram(points_.get());
    setMvp(points_.get(), mvp);
    glBindVertexArray(s.point_vao_.get());
    for (const auto& r : s.point_ranges_) {
      if (!options.point_clouds.empty() &&
          (r.source >= options.point_clouds.size() || !options.point_clouds[r.source])) {
        continue;
      }
      glUniform1i(glGetUniformLocation(points_.get(), "u_round"), r.round ? 1 : 0);
      glDrawArrays(GL_POINTS, r.first, r.count);
    }
  }
  if (!s.strips_.empty() || !s.segments_.empty()) {
    glUseProgram(lines_.get());
    setMvp(lines_.get(), mvp);
    glUniform2f(glGetUniformLocation(lines_.get(), "u_viewport"), static_cast<float>(camera.width),
                static_cast<float>(camera.height));
    glBindVertexArray(s.line_vao_.get());
    for (const auto& r : s.segments_) glDrawArrays(GL_LINES, r.first, r.count);
    for (const auto& r : s.strips_) glDrawArrays(GL_LINE_STRIP, r.first, r.count);
  }
  glBindVertexArray(0);
  checkGl("Renderer::draw");
}

ImageRgba Renderer::renderColor(const GpuScene& scene, const RenderCamera& camera,
                                Framebuffer& target, const DrawOptions& options) const {
  draw(scene, camera, target, options);
  return target.readColor();
}

DepthImage Renderer::renderDepth(const GpuScene& scene, const RenderCamera& camera,
                                 Framebuffer& target) const {
  draw(scene, camera, target);
  const std::vector<float> window = target.readDepth();
  DepthImage depth;
  depth.width = target.width();
  depth.height = target.height();
  depth.z_m.resize(window.size());
  for (std::size_t i = 0; i < window.size(); ++i) {
    depth.z_m[i] = static_cast<float>(windowDepthToMetric(camera, window[i]));
  }
  return depth;
}

}  // namespace gvio::render
