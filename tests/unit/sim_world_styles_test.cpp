// sim/world styles: `street` (the default) is the world it always was, bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <iostream>

#include "sim/world.hpp"
#include "sim_world_fixture.hpp"

namespace gvio::sim {
namespace {

using namespace world_fixture;  // NOLINT(google-build-using-namespace): test helpers

// FNV-1a over the meshes (texture, indices, vertices to 0.1 mm, uv to 1e-5) and texture texels.
std::uint64_t checksum(const World& world) {
  std::uint64_t h = 14695981039346656037ULL;
  auto mix = [&h](std::int64_t v) {
    for (int b = 0; b < 8; ++b) {
      h ^= static_cast<std::uint64_t>(v >> (8 * b)) & 0xFFU;
      h *= 1099511628211ULL;
    }
  };
  for (const auto& m : world.scene.meshes) {
    mix(static_cast<std::int64_t>(m.texture));
    for (const auto i : m.indices) mix(i);
    for (const auto& v : m.vertices) {
      for (int k = 0; k < 3; ++k) mix(std::llround(v[k] * 1e4));
    }
    for (const auto& uv : m.uv) {
      for (int k = 0; k < 2; ++k) mix(std::llround(static_cast<double>(uv[k]) * 1e5));
    }
  }
  for (const auto& t : world.scene.textures) {
    for (const auto texel : t.data) mix(texel);
  }
  return h;
}

// The figures were taken from the world builder before world styles existed (commit b50ebfc).
TEST(SimWorldStyles, StreetIsTheWorldItAlwaysWas) {
  WorldOptions o;
  o.texture_size_px = 64;
  const World world = buildWorld(twoTurns(), o);
  const std::uint64_t sum = checksum(world);
  std::cout << "[ street ] " << world.triangles << " triangles, checksum " << std::hex << sum
            << std::dec << "\n";
  EXPECT_EQ(world.triangles, 26838U);
  EXPECT_EQ(sum, 0x3c87fd57122e876cULL);
}

}  // namespace
}  // namespace gvio::sim
