#include <fmt/format.h>

#include <array>
#include <unordered_set>

#include "render/render_error.hpp"
#include "render/renderer.hpp"

namespace gvio::render {
namespace {

const Color kWhite(1, 1, 1, 1), kLightGrey(0.7F, 0.7F, 0.7F, 1);

// Interleaved vertex of lines and points: position (relative to the scene origin), colour, size.
struct StyledVertex {
  float pos[3];
  float color[4];
  float size;
};

// The i-th of n items' value: `fallback` when none is given, the single value, or its own.
template <typename T>
T pick(const std::vector<T>& values, std::size_t i, std::size_t n, const T& fallback,
       const char* what) {
  if (values.empty()) return fallback;
  if (values.size() != 1 && values.size() != n) {
    throw RenderError(
        fmt::format("{}: {} values for {} items (expected 1 or one each)", what, values.size(), n));
  }
  return values.size() == 1 ? values[0] : values[i];
}

StyledVertex styled(const Eigen::Vector3d& p, const Eigen::Vector3d& origin, const Color& c,
                    float size) {
  const Eigen::Vector3f q = (p - origin).cast<float>();
  return {{q.x(), q.y(), q.z()}, {c[0], c[1], c[2], c[3]}, size};
}

void styledLayout() {
  constexpr auto stride = static_cast<GLsizei>(sizeof(StyledVertex));
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, stride,
                        reinterpret_cast<void*>(offsetof(StyledVertex, pos)));
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 4, GL_FLOAT, GL_FALSE, stride,
                        reinterpret_cast<void*>(offsetof(StyledVertex, color)));
  glEnableVertexAttribArray(2);
  glVertexAttribPointer(2, 1, GL_FLOAT, GL_FALSE, stride,
                        reinterpret_cast<void*>(offsetof(StyledVertex, size)));
}

// The four far corners of a frustum in the camera frame, from the intrinsics (image corners).
std::array<Eigen::Vector3d, 4> frustumCorners(const Frustum& f) {
  const double w = f.K.width, h = f.K.height, d = f.depth_m;
  std::array<Eigen::Vector3d, 4> c;
  const double us[4] = {-0.5, w - 0.5, w - 0.5, -0.5}, vs[4] = {-0.5, -0.5, h - 0.5, h - 0.5};
  for (int i = 0; i < 4; ++i) {
    c[static_cast<std::size_t>(i)] =
        f.T_w_c * Eigen::Vector3d((us[i] - f.K.cx) / f.K.fx * d, (vs[i] - f.K.cy) / f.K.fy * d, d);
  }
  return c;
}

// A unit cube as 12 triangles with per-face normals: position (3) + normal (3).
std::vector<float> unitCube() {
  static const int faces[6][4][3] = {{{1, -1, -1}, {1, 1, -1}, {1, 1, 1}, {1, -1, 1}},
                                     {{-1, -1, -1}, {-1, -1, 1}, {-1, 1, 1}, {-1, 1, -1}},
                                     {{-1, 1, -1}, {-1, 1, 1}, {1, 1, 1}, {1, 1, -1}},
                                     {{-1, -1, -1}, {1, -1, -1}, {1, -1, 1}, {-1, -1, 1}},
                                     {{-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1}},
                                     {{-1, -1, -1}, {-1, 1, -1}, {1, 1, -1}, {1, -1, -1}}};
  static const float normals[6][3] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                      {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
  std::vector<float> v;
  for (int f = 0; f < 6; ++f) {
    for (const int k : {0, 1, 2, 0, 2, 3}) {
      for (int a = 0; a < 3; ++a) v.push_back(0.5F * static_cast<float>(faces[f][k][a]));
      for (int a = 0; a < 3; ++a) v.push_back(normals[f][a]);
    }
  }
  return v;
}

// Per voxel, a bit per cube face (unitCube's order: +x -x +y -y +z -z) set where the set holds the
// lattice neighbour on that side: the face is inside an opaque solid and never seen. Voxels off
// the lattice of the first centre (spacing size_m) take part in nothing. A ground slab of voxels
// then sends one face per voxel to the rasteriser instead of three.
std::vector<float> hiddenFaces(const VoxelSet& set) {
  const Eigen::Vector3d origin = set.centers.front();
  auto latticeKey = [&](const Eigen::Vector3d& c, std::uint64_t& key) {
    const Eigen::Vector3d f = (c - origin) / set.size_m;
    const Eigen::Vector3d r = f.array().round();
    if ((f - r).cwiseAbs().maxCoeff() > 1e-3 || r.cwiseAbs().maxCoeff() >= (1 << 20)) return false;
    key = 0;
    for (int a = 0; a < 3; ++a) {
      key = key << 21U |
            (static_cast<std::uint64_t>(static_cast<std::int64_t>(r[a]) + (1 << 20)) & 0x1FFFFFU);
    }
    return true;
  };
  std::unordered_set<std::uint64_t> occupied;
  occupied.reserve(set.centers.size());
  std::uint64_t key = 0;
  for (const auto& c : set.centers) {
    if (latticeKey(c, key)) occupied.insert(key);
  }
  static const int kStep[6][3] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                  {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
  std::vector<float> hidden(set.centers.size(), 0.0F);
  for (std::size_t i = 0; i < set.centers.size(); ++i) {
    if (!latticeKey(set.centers[i], key)) continue;
    int bits = 0;
    for (int f = 0; f < 6; ++f) {
      const Eigen::Vector3d n =
          set.centers[i] + set.size_m * Eigen::Vector3d(kStep[f][0], kStep[f][1], kStep[f][2]);
      if (latticeKey(n, key) && occupied.count(key) != 0) bits |= 1 << f;
    }
    hidden[i] = static_cast<float>(bits);
  }
  return hidden;
}

}  // namespace

GpuScene::GpuScene(const Scene& scene, const UploadOptions& options)
    : bounds_(scene.bounds()), background_(scene.background) {
  if (!bounds_.isEmpty()) origin_ = bounds_.center();
  uploadLines(scene);
  uploadPoints(scene);
  uploadVoxels(scene);
  uploadMeshes(scene, options.max_anisotropy);
  glBindVertexArray(0);
  checkGl("GpuScene upload");
}

bool GpuScene::empty() const {
  return strips_.empty() && segments_.empty() && point_ranges_.empty() && voxels_.empty() &&
         meshes_.empty();
}

void GpuScene::uploadLines(const Scene& scene) {
  std::vector<StyledVertex> v;
  for (const auto& l : scene.polylines) {
    if (l.points.size() < 2) continue;
    strips_.push_back({static_cast<GLint>(v.size()), static_cast<GLsizei>(l.points.size()), true});
    for (std::size_t i = 0; i < l.points.size(); ++i) {
      v.push_back(styled(l.points[i], origin_,
                         pick(l.colors, i, l.points.size(), kWhite, "polyline colours"),
                         pick(l.widths_px, i, l.points.size(), 2.0F, "polyline widths")));
    }
  }
  const auto first_segment = static_cast<GLint>(v.size());
  auto segment = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Color& c, float w) {
    v.push_back(styled(a, origin_, c, w));
    v.push_back(styled(b, origin_, c, w));
  };
  for (const auto& f : scene.frusta) {
    const auto c = frustumCorners(f);
    const Eigen::Vector3d apex = f.T_w_c.translation();
    for (std::size_t i = 0; i < 4; ++i) {
      segment(apex, c[i], f.color, f.width_px);
      segment(c[i], c[(i + 1) % 4], f.color, f.width_px);
    }
  }
  for (const auto& g : scene.grids) {
    const double half = g.spacing_m * g.half_cells;
    for (int k = -g.half_cells; k <= g.half_cells; ++k) {
      const double o = k * g.spacing_m;
      segment(g.center + Eigen::Vector3d(o, -half, 0), g.center + Eigen::Vector3d(o, half, 0),
              g.color, g.width_px);
      segment(g.center + Eigen::Vector3d(-half, o, 0), g.center + Eigen::Vector3d(half, o, 0),
              g.color, g.width_px);
    }
  }
  if (static_cast<GLint>(v.size()) > first_segment) {
    segments_.push_back({first_segment, static_cast<GLsizei>(v.size()) - first_segment, true});
  }
  if (v.empty()) return;
  line_vao_ = makeVertexArray();
  line_vbo_ = makeBuffer();
  glBindVertexArray(line_vao_.get());
  glBindBuffer(GL_ARRAY_BUFFER, line_vbo_.get());
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(v.size() * sizeof(StyledVertex)), v.data(),
               GL_STATIC_DRAW);
  styledLayout();
}

void GpuScene::uploadPoints(const Scene& scene) {
  std::vector<StyledVertex> v;
  for (std::size_t k = 0; k < scene.point_clouds.size(); ++k) {
    const PointCloud& c = scene.point_clouds[k];
    if (c.points.empty()) continue;
    point_ranges_.push_back(
        {static_cast<GLint>(v.size()), static_cast<GLsizei>(c.points.size()), c.round, k});
    for (std::size_t i = 0; i < c.points.size(); ++i) {
      v.push_back(styled(c.points[i], origin_,
                         pick(c.colors, i, c.points.size(), kWhite, "point colours"),
                         pick(c.sizes_px, i, c.points.size(), 2.0F, "point sizes")));
    }
  }
  if (v.empty()) return;
  point_vao_ = makeVertexArray();
  point_vbo_ = makeBuffer();
  glBindVertexArray(point_vao_.get());
  glBindBuffer(GL_ARRAY_BUFFER, point_vbo_.get());
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(v.size() * sizeof(StyledVertex)), v.data(),
               GL_STATIC_DRAW);
  styledLayout();
}

void GpuScene::uploadVoxels(const Scene& scene) {
  for (const auto& set : scene.voxel_sets) {
    if (set.centers.empty()) continue;
    if (!(set.size_m > 0.0)) throw RenderError("voxel size must be positive");
    if (cube_vbo_.get() == 0) {
      const auto cube = unitCube();
      cube_vbo_ = makeBuffer();
      glBindBuffer(GL_ARRAY_BUFFER, cube_vbo_.get());
      glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(cube.size() * sizeof(float)),
                   cube.data(), GL_STATIC_DRAW);
    }
    // Per instance: centre (3), colour (4), hidden-face bits (1, a float the shader truncates).
    const std::vector<float> hidden = hiddenFaces(set);
    std::vector<float> inst;
    inst.reserve(set.centers.size() * 8);
    for (std::size_t i = 0; i < set.centers.size(); ++i) {
      const Eigen::Vector3f c = (set.centers[i] - origin_).cast<float>();
      const Color col = pick(set.colors, i, set.centers.size(), kLightGrey, "voxel colours");
      // A see-through voxel shows its inner faces: hide faces between opaque ones only.
      const float h = col[3] >= 1.0F ? hidden[i] : 0.0F;
      inst.insert(inst.end(), {c.x(), c.y(), c.z(), col[0], col[1], col[2], col[3], h});
    }
    Voxels vox;
    vox.vao = makeVertexArray();
    vox.instances = makeBuffer();
    vox.count = static_cast<GLsizei>(set.centers.size());
    vox.size_m = static_cast<float>(set.size_m);
    glBindVertexArray(vox.vao.get());
    glBindBuffer(GL_ARRAY_BUFFER, cube_vbo_.get());
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), nullptr);
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float),
                          reinterpret_cast<void*>(3 * sizeof(float)));
    glBindBuffer(GL_ARRAY_BUFFER, vox.instances.get());
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(inst.size() * sizeof(float)), inst.data(),
                 GL_STATIC_DRAW);
    constexpr GLsizei stride = 8 * sizeof(float);
    glEnableVertexAttribArray(2);
    glVertexAttribPointer(2, 3, GL_FLOAT, GL_FALSE, stride, nullptr);
    glVertexAttribDivisor(2, 1);
    glEnableVertexAttribArray(3);
    glVertexAttribPointer(3, 4, GL_FLOAT, GL_FALSE, stride,
                          reinterpret_cast<void*>(3 * sizeof(float)));
    glVertexAttribDivisor(3, 1);
    glEnableVertexAttribArray(4);
    glVertexAttribPointer(4, 1, GL_FLOAT, GL_FALSE, stride,
                          reinterpret_cast<void*>(7 * sizeof(float)));
    glVertexAttribDivisor(4, 1);
    voxels_.push_back(std::move(vox));
  }
}

void GpuScene::uploadMeshes(const Scene& scene, float max_anisotropy) {
  for (const auto& t : scene.textures) {
    if (t.width < 1 || t.height < 1 || (t.channels != 1 && t.channels != 3 && t.channels != 4) ||
        t.data.size() != static_cast<std::size_t>(t.width) * static_cast<std::size_t>(t.height) *
                             static_cast<std::size_t>(t.channels)) {
      throw RenderError(fmt::format("texture {}x{}x{} with {} bytes is inconsistent", t.width,
                                    t.height, t.channels, t.data.size()));
    }
    GlTexture tex = makeTexture();
    glBindTexture(GL_TEXTURE_2D, tex.get());
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    const GLenum format = t.channels == 1 ? GL_RED : (t.channels == 3 ? GL_RGB : GL_RGBA);
    const GLint internal = t.channels == 1 ? GL_R8 : (t.channels == 3 ? GL_RGB8 : GL_RGBA8);
    glTexImage2D(GL_TEXTURE_2D, 0, internal, t.width, t.height, 0, format, GL_UNSIGNED_BYTE,
                 t.data.data());
    // Mipmaps with trilinear (optionally anisotropic) filtering: distant texture must not alias
    // into false corners for the feature tracker.
    glGenerateMipmap(GL_TEXTURE_2D);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
    if (max_anisotropy > 1.0F && epoxy_has_gl_extension("GL_EXT_texture_filter_anisotropic")) {
      glTexParameterf(GL_TEXTURE_2D, GL_TEXTURE_MAX_ANISOTROPY_EXT, max_anisotropy);
    }
    textures_.push_back(std::move(tex));
    texture_grey_.push_back(t.channels == 1);
  }
  // Meshes sharing a texture are batched into one buffer pair and one draw call: procedural worlds
  // are made of thousands of small pieces.
  struct Batch {
    std::vector<float> vertices;  // x y z u v
    std::vector<std::uint32_t> indices;
  };
  std::vector<Batch> batches(textures_.size());
  for (const auto& m : scene.meshes) {
    if (m.indices.empty()) continue;
    if (m.uv.size() != m.vertices.size() || m.texture >= textures_.size() ||
        m.indices.size() % 3 != 0) {
      throw RenderError("textured mesh: uv count, texture index or triangle count is inconsistent");
    }
    Batch& b = batches[m.texture];
    const auto base = static_cast<std::uint32_t>(b.vertices.size() / 5);
    for (std::size_t i = 0; i < m.vertices.size(); ++i) {
      const Eigen::Vector3f p = (m.vertices[i] - origin_).cast<float>();
      b.vertices.insert(b.vertices.end(), {p.x(), p.y(), p.z(), m.uv[i].x(), m.uv[i].y()});
    }
    for (const auto idx : m.indices) {
      if (idx >= m.vertices.size()) throw RenderError("textured mesh: index out of range");
      b.indices.push_back(base + idx);
    }
  }
  for (std::size_t t = 0; t < batches.size(); ++t) {
    if (!batches[t].indices.empty()) uploadBatch(batches[t].vertices, batches[t].indices, t);
  }
}

void GpuScene::uploadBatch(const std::vector<float>& vertices,
                           const std::vector<std::uint32_t>& indices, std::size_t texture) {
  Mesh mesh;
  mesh.vao = makeVertexArray();
  mesh.vertices = makeBuffer();
  mesh.indices = makeBuffer();
  mesh.index_count = static_cast<GLsizei>(indices.size());
  mesh.texture = texture;
  glBindVertexArray(mesh.vao.get());
  glBindBuffer(GL_ARRAY_BUFFER, mesh.vertices.get());
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertices.size() * sizeof(float)),
               vertices.data(), GL_STATIC_DRAW);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, mesh.indices.get());
  glBufferData(GL_ELEMENT_ARRAY_BUFFER,
               static_cast<GLsizeiptr>(indices.size() * sizeof(std::uint32_t)), indices.data(),
               GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 5 * sizeof(float), nullptr);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 2, GL_FLOAT, GL_FALSE, 5 * sizeof(float),
                        reinterpret_cast<void*>(3 * sizeof(float)));
  meshes_.push_back(std::move(mesh));
}

}  // namespace gvio::render
