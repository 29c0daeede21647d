// Ground-level and small-object textures, and the library the world builder uses. Sizes of painted
// details are given for 512 px and scaled with the texture size, so every size looks alike.
#include "sim/textures.hpp"

#include <cmath>
#include <numbers>

#include "odometry/error.hpp"
#include "sim/procedural.hpp"

namespace gvio::sim {
namespace {

ProceduralTexture finish(Canvas& c, double tile_u_m, double tile_v_m) {
  c.clamp(0.0, 255.0);
  return {c.toTexture(), Eigen::Vector2d(tile_u_m, tile_v_m)};
}

// Scattered small discs (stones, grass clumps): per 512 x 512 px, radius in 512-px pixels.
void scatter(Canvas& c, Rng& rng, int count_per_512, double r_lo, double r_hi, double v_lo,
             double v_hi, double alpha) {
  const double k = c.width() / 512.0;
  const int count = static_cast<int>(count_per_512 * k * k);
  for (int i = 0; i < count; ++i) {
    // Drawn one by one in the order GCC evaluated the arguments before (right to left), so the
    // textures stay the same and any compiler draws them in this order.
    const double value = rng.uniform(v_lo, v_hi);
    const double radius = k * rng.uniform(r_lo, r_hi);
    const double y = rng.uniform(0, c.height());
    const double x = rng.uniform(0, c.width());
    c.blendDisc(x, y, radius, value, alpha);
  }
}

// A crack: a random walk of short dark segments, now and then forking.
void crack(Canvas& c, Rng& rng, double x, double y, int steps, double width, double value) {
  const double k = c.width() / 512.0;
  double heading = rng.uniform(0.0, 2.0 * std::numbers::pi);
  for (int s = 0; s < steps; ++s) {
    heading += 0.6 * rng.normal();
    const double len = k * rng.uniform(3.0, 9.0);
    const double nx = x + len * std::cos(heading), ny = y + len * std::sin(heading);
    c.blendLine(x, y, nx, ny, width * rng.uniform(0.7, 1.3), value, 0.85);
    if (rng.chance(0.06)) crack(c, rng, nx, ny, steps / 3, 0.7 * width, value);
    x = nx;
    y = ny;
  }
}

// Repaired rectangles with a sharp seam: strong corners at a scale of metres.
void patches(Canvas& c, Rng& rng, int count, double delta) {
  for (int i = 0; i < count; ++i) {
    const double x = rng.uniform(0, c.width()), y = rng.uniform(0, c.height());
    const double w = c.width() * rng.uniform(0.08, 0.3), h = c.height() * rng.uniform(0.06, 0.25);
    c.addRect(x, y, x + w, y + h, rng.chance(0.5) ? delta : -delta);
    c.addRect(x, y, x + w, y + 1.5, -0.6 * delta);  // seam along one edge
  }
}

}  // namespace

ProceduralTexture asphaltTexture(int size_px, std::uint64_t seed) {
  Rng rng = Rng::derive(seed, 1);
  Canvas c(size_px, size_px, 92.0F);
  c.addFractalNoise(rng, 4, 7, 16.0);
  c.addWhiteNoise(rng, 6.0);
  scatter(c, rng, 9000, 0.4, 1.3, 120.0, 160.0, 0.45);  // light aggregate
  scatter(c, rng, 3000, 0.5, 1.5, 45.0, 65.0, 0.45);    // dark pores
  patches(c, rng, 4, 22.0);
  for (int i = 0; i < 7; ++i) {  // fine cracks, and wide ones sealed with tar (seen from afar)
    const bool sealed = i < 3;
    const int steps = rng.integer(15, 50);  // drawn in GCC's former order, as in scatter()
    const double y = rng.uniform(0, size_px);
    const double x = rng.uniform(0, size_px);
    crack(c, rng, x, y, steps, (sealed ? 4.0 : 1.4) * size_px / 512.0, sealed ? 28.0 : 35.0);
  }
  scatter(c, rng, 6, 15.0, 45.0, 55.0, 55.0, 0.3);  // oil stains
  return finish(c, 6.0, 6.0);
}

ProceduralTexture markingTexture(int size_px, std::uint64_t seed) {
  Rng rng = Rng::derive(seed, 2);
  Canvas c(size_px, size_px, 220.0F);
  c.addFractalNoise(rng, 2, 6, 14.0);
  c.addWhiteNoise(rng, 7.0);
  scatter(c, rng, 60, 2.0, 10.0, 100.0, 140.0, 0.6);  // worn spots showing the asphalt
  return finish(c, 0.15, 3.0);
}

ProceduralTexture pavingTexture(int size_px, std::uint64_t seed) {
  Rng rng = Rng::derive(seed, 3);
  constexpr int kSlabs = 8;  // per repeat of 2.4 m: 0.3 m slabs
  const double slab = static_cast<double>(size_px) / kSlabs, joint = 1.6 * size_px / 512.0;
  Canvas c(size_px, size_px, 75.0F);  // joints
  for (int row = 0; row < kSlabs; ++row) {
    const double shift = (row % 2) * 0.5 * slab + rng.uniform(-0.08, 0.08) * slab;
    for (int col = 0; col < kSlabs; ++col) {
      const double x = col * slab + shift, y = row * slab;
      const double tone = 150.0 + 14.0 * rng.normal();
      c.blendRect(x + joint / 2, y + joint / 2, x + slab - joint / 2, y + slab - joint / 2, tone);
      if (rng.chance(0.1)) {                         // broken slab
        const double x1 = x + rng.uniform(0, slab);  // GCC's former order, as in scatter()
        const double x0 = x + rng.uniform(0, slab);
        c.blendLine(x0, y, x1, y + slab, joint, 80.0, 0.8);
      }
    }
  }
  c.addFractalNoise(rng, 4, 7, 12.0);
  c.addWhiteNoise(rng, 6.0);
  scatter(c, rng, 10, 8.0, 30.0, 90.0, 110.0, 0.25);  // stains
  return finish(c, 2.4, 2.4);
}

ProceduralTexture curbTexture(int size_px, std::uint64_t seed) {
  Rng rng = Rng::derive(seed, 4);
  Canvas c(size_px, size_px, 175.0F);
  c.addFractalNoise(rng, 4, 7, 14.0);
  c.addWhiteNoise(rng, 7.0);
  for (int stone = 0; stone < 2; ++stone) {  // 1 m stones in a 2 m repeat
    const double x = (stone + rng.uniform(-0.04, 0.04)) * size_px / 2.0;
    c.blendRect(x, 0, x + 2.5 * size_px / 512.0, size_px, 70.0);
  }
  scatter(c, rng, 80, 1.0, 4.0, 90.0, 120.0, 0.6);  // chips
  return finish(c, 2.0, 0.5);
}

ProceduralTexture groundTexture(int size_px, std::uint64_t seed) {
  Rng rng = Rng::derive(seed, 5);
  Canvas c(size_px, size_px, 88.0F);
  c.addFractalNoise(rng, 3, 8, 40.0);
  scatter(c, rng, 5000, 0.8, 2.5, 40.0, 150.0, 0.5);    // grass clumps
  scatter(c, rng, 300, 1.0, 3.0, 170.0, 200.0, 0.7);    // pebbles
  scatter(c, rng, 12, 12.0, 40.0, 120.0, 140.0, 0.35);  // bare soil
  c.addWhiteNoise(rng, 10.0);
  return finish(c, 8.0, 8.0);
}

ProceduralTexture roofTexture(int size_px, std::uint64_t seed) {
  Rng rng = Rng::derive(seed, 6);
  Canvas c(size_px, size_px, 72.0F);
  c.addFractalNoise(rng, 3, 7, 14.0);
  c.addWhiteNoise(rng, 8.0);
  for (int i = 0; i < 4; ++i) {  // tar seams
    const double y = (i + rng.uniform(-0.1, 0.1)) * size_px / 4.0;
    c.blendRect(0, y, size_px, y + 2.0 * size_px / 512.0, 45.0);
  }
  return finish(c, 4.0, 4.0);
}

ProceduralTexture foliageTexture(int size_px, std::uint64_t seed) {
  Rng rng = Rng::derive(seed, 7);
  Canvas c(size_px, size_px, 45.0F);
  scatter(c, rng, 2500, 2.0, 9.0, 40.0, 150.0, 0.9);   // leaf clusters, layered
  scatter(c, rng, 900, 1.5, 5.0, 15.0, 35.0, 0.9);     // gaps into the crown
  scatter(c, rng, 1500, 0.8, 2.0, 150.0, 200.0, 0.8);  // sunlit leaves
  c.addFractalNoise(rng, 2, 4, 25.0);
  c.addWhiteNoise(rng, 8.0);
  return finish(c, 4.0, 4.0);
}

ProceduralTexture barkTexture(int size_px, std::uint64_t seed) {
  Rng rng = Rng::derive(seed, 8);
  Canvas c(size_px, size_px, 75.0F);
  c.addValueNoise(rng, 24, 3, 25.0);  // vertical furrows
  c.addValueNoise(rng, 64, 8, 12.0);
  for (int i = 0; i < 40; ++i) {
    const double x = rng.uniform(0, size_px), y = rng.uniform(0, size_px);
    const double y1 = y + rng.uniform(30, 120);  // GCC's former order, as in scatter()
    const double x1 = x + rng.uniform(-4, 4);
    c.blendLine(x, y, x1, y1, 2.0, 30.0, 0.7);
  }
  c.addWhiteNoise(rng, 9.0);
  return finish(c, 1.0, 2.0);
}

ProceduralTexture metalTexture(int size_px, std::uint64_t seed) {
  Rng rng = Rng::derive(seed, 9);
  Canvas c(size_px, size_px, 125.0F);
  c.addValueNoise(rng, 2, 12, 14.0);
  c.addWhiteNoise(rng, 5.0);
  scatter(c, rng, 25, 3.0, 12.0, 70.0, 90.0, 0.5);  // rust and stickers
  scatter(c, rng, 10, 3.0, 8.0, 200.0, 230.0, 0.8);
  return finish(c, 1.0, 2.0);
}

ProceduralTexture tyreTexture(int size_px, std::uint64_t seed) {
  Rng rng = Rng::derive(seed, 10);
  Canvas c(size_px, size_px, 28.0F);
  const double mid = 0.5 * size_px;
  c.blendDisc(mid, mid, 0.3 * size_px, 140.0);  // rim
  c.blendDisc(mid, mid, 0.12 * size_px, 70.0);  // hub
  for (int spoke = 0; spoke < 5; ++spoke) {
    const double a = spoke * 2.0 * std::numbers::pi / 5.0;
    c.blendLine(mid, mid, mid + 0.28 * size_px * std::cos(a), mid + 0.28 * size_px * std::sin(a),
                0.05 * size_px, 180.0);
  }
  c.addWhiteNoise(rng, 6.0);
  return finish(c, 1.0, 1.0);
}

ProceduralTexture manholeTexture(int size_px, std::uint64_t seed) {
  Rng rng = Rng::derive(seed, 11);
  Canvas c(size_px, size_px, 90.0F);
  const double mid = 0.5 * size_px, r = 0.48 * size_px;
  c.blendDisc(mid, mid, r, 150.0);        // frame ring
  c.blendDisc(mid, mid, 0.86 * r, 60.0);  // cover
  const double step = 0.16 * r;           // raised grid on the cover
  for (double d = -0.8 * r; d <= 0.8 * r; d += step) {
    const double half = std::sqrt(std::max(0.0, 0.7 * r * r - d * d));
    c.blendLine(mid + d, mid - half, mid + d, mid + half, 0.03 * size_px, 105.0);
    c.blendLine(mid - half, mid + d, mid + half, mid + d, 0.03 * size_px, 105.0);
  }
  c.addWhiteNoise(rng, 8.0);
  return finish(c, 1.0, 1.0);
}

ProceduralTexture grateTexture(int size_px, std::uint64_t seed) {
  Rng rng = Rng::derive(seed, 12);
  Canvas c(size_px, size_px, 140.0F);  // frame
  const double m = 0.08 * size_px;
  c.blendRect(m, m, size_px - m, size_px - m, 20.0);
  for (int bar = 1; bar < 8; ++bar) {
    const double x = m + bar * (size_px - 2 * m) / 8.0;
    c.blendRect(x - 0.02 * size_px, m, x + 0.02 * size_px, size_px - m, 95.0);
  }
  c.addWhiteNoise(rng, 8.0);
  return finish(c, 1.0, 1.0);
}

ProceduralTexture signTexture(int size_px, std::uint64_t seed) {
  Rng rng = Rng::derive(seed, 13);
  Canvas c(size_px, size_px, 150.0F);  // plate
  const double mid = 0.5 * size_px;
  c.blendDisc(mid, mid, 0.47 * size_px, 40.0);   // ring
  c.blendDisc(mid, mid, 0.36 * size_px, 225.0);  // field
  const double bar = rng.uniform(0.12, 0.3) * size_px;
  c.blendRect(mid - bar, mid - 0.06 * size_px, mid + bar, mid + 0.06 * size_px, 30.0);
  c.addWhiteNoise(rng, 6.0);
  return finish(c, 1.0, 1.0);
}

TextureLibrary makeTextureLibrary(std::uint64_t seed, int size_px) {
  if (size_px < 64 || size_px > 4096 || (size_px & (size_px - 1)) != 0) {
    throw InvalidInput("texture size must be a power of two in [64, 4096] px, got " +
                       std::to_string(size_px));
  }
  TextureLibrary lib;
  auto add = [&lib](ProceduralTexture t) {
    lib.textures.push_back(std::move(t.image));
    lib.tile_m.push_back(t.tile_m);
    return lib.textures.size() - 1;
  };
  const int small = std::max(64, size_px / 4);  // objects seen small: less memory
  lib.asphalt = add(asphaltTexture(size_px, seed));
  lib.marking = add(markingTexture(small, seed));
  lib.paving = add(pavingTexture(size_px, seed));
  lib.curb = add(curbTexture(size_px / 2, seed));
  lib.ground = add(groundTexture(size_px, seed));
  lib.roof = add(roofTexture(size_px / 2, seed));
  lib.foliage = add(foliageTexture(size_px, seed));
  lib.bark = add(barkTexture(size_px / 2, seed));
  lib.metal = add(metalTexture(small, seed));
  lib.tyre = add(tyreTexture(small, seed));
  lib.cabin = add(carCabinTexture(size_px / 2, seed));
  lib.manhole = add(manholeTexture(small, seed));
  lib.grate = add(grateTexture(small, seed));
  lib.sign = add(signTexture(small, seed));
  constexpr int kStyles = 12, kBrickStyles = 4;  // mostly plaster, as in Karlsruhe (KITTI)
  for (int style = 0; style < kStyles; ++style) {
    const auto material = style < kBrickStyles ? FacadeMaterial::kBrick : FacadeMaterial::kPlaster;
    FacadeTextures f =
        facadeTextures(material, size_px, seed * 131U + static_cast<unsigned>(style));
    lib.facade_front.push_back(add(std::move(f.front)));
    lib.facade_side.push_back(add(std::move(f.side)));
  }
  for (const double paint : {215.0, 165.0, 110.0, 55.0, 30.0})
    lib.car_body.push_back(add(carBodyTexture(size_px / 2, seed, paint)));
  return lib;
}

}  // namespace gvio::sim
