#pragma once
// Procedural grey textures of the simulated street, deterministic by seed. Each carries the
// metres one repeat covers, so geometry can map uv in metres / tile (GL_REPEAT tiles it). They
// have detail at several scales (Shi-Tomasi + KLT work on image pyramids) and jitter wherever a
// pattern repeats, so the tracker sees no perfectly periodic high-frequency texture.
#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "render/scene.hpp"

namespace gvio::sim {

struct ProceduralTexture {
  render::Texture image;                             // size_px x size_px, 1 channel
  Eigen::Vector2d tile_m = Eigen::Vector2d::Ones();  // metres covered by one repeat (u, v)
};

// Ground level. size_px: a power of two >= 64.
ProceduralTexture asphaltTexture(int size_px, std::uint64_t seed);  // noise, stones, cracks
ProceduralTexture markingTexture(int size_px, std::uint64_t seed);  // worn white road paint
ProceduralTexture pavingTexture(int size_px, std::uint64_t seed);   // sidewalk slabs
ProceduralTexture curbTexture(int size_px, std::uint64_t seed);     // concrete curb stones
ProceduralTexture groundTexture(int size_px, std::uint64_t seed);   // grass and dirt

// Objects.
ProceduralTexture roofTexture(int size_px, std::uint64_t seed);     // tar roofs, cornices
ProceduralTexture foliageTexture(int size_px, std::uint64_t seed);  // tree crowns, hedges
ProceduralTexture barkTexture(int size_px, std::uint64_t seed);
ProceduralTexture metalTexture(int size_px, std::uint64_t seed);    // poles
ProceduralTexture tyreTexture(int size_px, std::uint64_t seed);     // one wheel per face
ProceduralTexture manholeTexture(int size_px, std::uint64_t seed);  // round cover, one per disc
ProceduralTexture grateTexture(int size_px, std::uint64_t seed);    // gutter drain, one per quad
ProceduralTexture signTexture(int size_px, std::uint64_t seed);     // round traffic sign on a plate

enum class FacadeMaterial { kBrick, kPlaster };
struct FacadeTextures {
  ProceduralTexture front;  // wall with a grid of framed windows (glass, blinds, curtains)
  ProceduralTexture side;   // the same wall without windows, darker: side walls read as shaded
};
// One repeat covers a few window columns x floors; window size, pitch, floor height, frames and
// wall tone vary with the seed. Rows: the bottom of the image is a floor boundary.
FacadeTextures facadeTextures(FacadeMaterial material, int size_px, std::uint64_t seed);

// Car body sides (one car length per repeat: panels, door seams, wheel arches) in a paint tone;
// the cabin's glass with pillars.
ProceduralTexture carBodyTexture(int size_px, std::uint64_t seed, double paint_grey);
ProceduralTexture carCabinTexture(int size_px, std::uint64_t seed);

// Plain, low-contrast surfaces (the sparse_texture world): soft shading, a faint grain, no corners.
ProceduralTexture plainAsphaltTexture(int size_px, std::uint64_t seed);
ProceduralTexture plainConcreteTexture(int size_px, std::uint64_t seed, double tone,
                                       const Eigen::Vector2d& tile_m);
ProceduralTexture plainGroundTexture(int size_px, std::uint64_t seed);
FacadeTextures plainWallTextures(int size_px, std::uint64_t seed, double tone);  // no windows

// Every texture the world uses, in Scene::textures order, with indices by role.
struct TextureLibrary {
  std::vector<render::Texture> textures;
  std::vector<Eigen::Vector2d> tile_m;  // per texture
  std::size_t asphalt = 0, marking = 0, paving = 0, curb = 0, ground = 0, roof = 0, foliage = 0,
              bark = 0, metal = 0, tyre = 0, cabin = 0, manhole = 0, grate = 0, sign = 0;
  std::vector<std::size_t> facade_front, facade_side;  // paired styles (brick and plaster)
  std::vector<std::size_t> car_body;                   // paint tones
};
// Throws InvalidInput unless size_px is a power of two in [64, 4096].
TextureLibrary makeTextureLibrary(std::uint64_t seed, int size_px);

}  // namespace gvio::sim
