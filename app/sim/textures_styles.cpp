// Textures of the world styles other than `street`: plain, low-contrast surfaces and walls for
// sparse_texture (large uniform areas with shading but no corners), and the repetitive world's
// ground repeat fitted to its period.
#include "sim/procedural.hpp"
#include "sim/textures.hpp"
#include "sim/world_parts.hpp"

namespace gvio::sim {
namespace {

// Soft blotches (value noise of 2-8 cells per repeat) and a faint grain: shading a tracker sees
// as smooth, so Shi-Tomasi finds no corners on it.
ProceduralTexture plain(int size_px, Rng& rng, double tone, double blotch_dn, double grain_dn,
                        const Eigen::Vector2d& tile_m) {
  Canvas c(size_px, size_px, static_cast<float>(tone));
  c.addFractalNoise(rng, 2, 3, blotch_dn);
  c.addWhiteNoise(rng, grain_dn);
  c.clamp(0.0, 255.0);
  return {c.toTexture(), tile_m};
}

}  // namespace

ProceduralTexture plainAsphaltTexture(int size_px, std::uint64_t seed) {
  Rng rng = Rng::derive(seed, 51);
  return plain(size_px, rng, 95.0, 5.0, 1.0, Eigen::Vector2d(6.0, 6.0));
}

ProceduralTexture plainConcreteTexture(int size_px, std::uint64_t seed, double tone,
                                       const Eigen::Vector2d& tile_m) {
  Rng rng = Rng::derive(seed, 52 + static_cast<std::uint64_t>(tone));
  return plain(size_px, rng, tone, 4.0, 1.0, tile_m);
}

ProceduralTexture plainGroundTexture(int size_px, std::uint64_t seed) {
  Rng rng = Rng::derive(seed, 53);
  return plain(size_px, rng, 88.0, 8.0, 1.5, Eigen::Vector2d(8.0, 8.0));
}

FacadeTextures plainWallTextures(int size_px, std::uint64_t seed, double tone) {
  Rng rng = Rng::derive(seed, 54);
  const Eigen::Vector2d tile(8.0, 8.0);
  ProceduralTexture front = plain(size_px, rng, tone, 4.0, 1.0, tile);
  ProceduralTexture side = plain(size_px, rng, 0.72 * tone, 3.0, 1.0, tile);  // in the shade
  return {std::move(front), std::move(side)};
}

namespace detail {

void restyleTextures(TextureLibrary& lib, WorldStyle style, std::uint64_t seed, int size_px) {
  auto replace = [&lib](std::size_t index, ProceduralTexture t) {
    lib.textures[index] = std::move(t.image);
    lib.tile_m[index] = t.tile_m;
  };
  if (style == WorldStyle::kSparseTexture) {
    // In place: every index stays valid, the street's textures are simply not there.
    replace(lib.asphalt, plainAsphaltTexture(size_px, seed));
    replace(lib.paving, plainConcreteTexture(size_px, seed, 150.0, lib.tile_m[lib.paving]));
    replace(lib.curb, plainConcreteTexture(size_px / 2, seed, 170.0, lib.tile_m[lib.curb]));
    replace(lib.roof, plainConcreteTexture(size_px / 2, seed, 80.0, lib.tile_m[lib.roof]));
    replace(lib.ground, plainGroundTexture(size_px, seed));
    for (std::size_t k = 0; k < lib.facade_front.size(); ++k) {
      const double tone =
          115.0 + 90.0 * static_cast<double>(k) / static_cast<double>(lib.facade_front.size());
      FacadeTextures wall = plainWallTextures(size_px, seed * 131U + k, tone);
      replace(lib.facade_front[k], std::move(wall.front));
      replace(lib.facade_side[k], std::move(wall.side));
    }
  }
  if (style == WorldStyle::kRepetitive) {
    // World-mapped ground repeats every 6 m, which divides the period (the asphalt's 6 m does).
    lib.tile_m[lib.ground] = Eigen::Vector2d(6.0, 6.0);
  }
}

}  // namespace detail
}  // namespace gvio::sim
