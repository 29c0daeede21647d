// Facade and car textures: drawn in metres on a canvas that covers one repeat, z up from the
// bottom edge (a floor boundary), so geometry can align floors with the street.
#include <algorithm>
#include <cmath>
#include <vector>

#include "sim/procedural.hpp"
#include "sim/textures.hpp"

namespace gvio::sim {
namespace {

// Canvas addressed in metres: x right, z up from the bottom edge.
class MetricCanvas {
 public:
  MetricCanvas(Canvas& canvas, double width_m, double height_m)
      : c_(canvas), sx_(canvas.width() / width_m), sz_(canvas.height() / height_m) {}

  void rect(double x0, double z0, double x1, double z1, double value, double alpha = 1.0) {
    c_.blendRect(x0 * sx_, c_.height() - z1 * sz_, x1 * sx_, c_.height() - z0 * sz_, value, alpha);
  }
  void addRect(double x0, double z0, double x1, double z1, double delta) {
    c_.addRect(x0 * sx_, c_.height() - z1 * sz_, x1 * sx_, c_.height() - z0 * sz_, delta);
  }
  [[nodiscard]] double pxPerMetreZ() const { return sz_; }

 private:
  Canvas& c_;
  double sx_, sz_;
};

struct FacadeStyle {
  int columns = 4, floors = 4;
  double pitch = 2.5, floor_h = 3.2;              // window spacing, floor height (m)
  double win_w = 1.2, win_h = 1.5, sill_z = 0.9;  // window size, sill above the floor
  double wall = 120.0, frame = 210.0;             // tones
  int mullions = 1;                               // 0 none, 1 vertical, 2 cross
};

FacadeStyle randomStyle(FacadeMaterial material, Rng& rng) {
  FacadeStyle s;
  s.columns = rng.integer(3, 5);
  s.floors = rng.integer(3, 4);
  s.pitch = rng.uniform(2.2, 3.0);
  s.floor_h = rng.uniform(2.9, 3.6);
  s.win_w = std::min(rng.uniform(0.9, 1.5), s.pitch - 0.8);
  s.win_h = std::min(rng.uniform(1.2, 1.8), s.floor_h - 1.2);
  s.sill_z = rng.uniform(0.8, 1.0);
  s.wall =
      material == FacadeMaterial::kBrick ? rng.uniform(80.0, 135.0) : rng.uniform(150.0, 210.0);
  s.frame = rng.chance(0.6) ? rng.uniform(195.0, 235.0) : rng.uniform(40.0, 70.0);
  s.mullions = rng.integer(0, 2);
  return s;
}

// Bricks in courses with a tone per brick over slightly lighter mortar. Joints are jittered
// along each course and the mortar contrast is low, so the random brick tones (corners), not the
// regular courses, dominate: a perfectly periodic pattern would let KLT lock onto the wrong brick.
void paintBricks(Canvas& c, Rng& rng, double width_m, double height_m, double tone) {
  MetricCanvas m(c, width_m, height_m);
  const int courses = std::max(1, static_cast<int>(std::lround(height_m / 0.075)));
  const int per_course = std::max(1, static_cast<int>(std::lround(width_m / 0.25)));
  const double ch = height_m / courses, bl = width_m / per_course, mortar = 0.012;
  m.rect(0, 0, width_m, height_m, tone + 15.0);
  for (int row = 0; row < courses; ++row) {
    const double shift = (row % 2) * 0.5 * bl + rng.uniform(-0.2, 0.2) * bl;
    std::vector<double> joints;
    for (int b = 0; b < per_course; ++b)
      joints.push_back(shift + (b + rng.uniform(-0.15, 0.15)) * bl);
    joints.push_back(joints.front() + width_m);
    for (int b = 0; b < per_course; ++b) {
      double brick = tone + 8.0 * rng.normal();
      if (rng.chance(0.05)) brick -= 40.0;  // burnt bricks
      const double z = row * ch;
      const auto bi = static_cast<std::size_t>(b);
      m.rect(joints[bi] + mortar, z + mortar, joints[bi + 1], z + ch, brick);  // canvas wraps
    }
  }
}

void paintPlaster(Canvas& c, Rng& rng, const FacadeStyle& s, double width_m, double height_m) {
  MetricCanvas m(c, width_m, height_m);
  m.rect(0, 0, width_m, height_m, s.wall);
  c.addFractalNoise(rng, 2, 7, 14.0);
  for (int f = 0; f < s.floors; ++f) {  // string courses between floors
    m.addRect(0, f * s.floor_h, width_m, f * s.floor_h + 0.18, rng.chance(0.5) ? 22.0 : -22.0);
  }
}

// What walls carry besides windows: patched and stained areas, a drain pipe, vents, and scrawls
// at street level. Side walls (no windows) need this to give the tracker something.
void paintWallDetails(Canvas& c, Rng& rng, double width_m, double height_m, double tone) {
  MetricCanvas m(c, width_m, height_m);
  for (int i = 0; i < 5; ++i) {  // repairs and stains
    const double x = rng.uniform(0.0, width_m), z = rng.uniform(0.0, height_m);
    // Drawn in the order GCC evaluated the arguments before (right to left): the same facades.
    const double delta = rng.uniform(-25.0, 20.0);
    const double z1 = z + rng.uniform(0.5, 2.5);
    const double x1 = x + rng.uniform(0.5, 3.0);
    m.addRect(x, z, x1, z1, delta);
  }
  const double pipe = rng.uniform(0.0, width_m);
  m.rect(pipe, 0.0, pipe + 0.1, height_m, std::clamp(tone + rng.uniform(-60.0, 60.0), 30.0, 230.0));
  for (int f = 0; f < 3; ++f) {  // pipe brackets
    const double z = rng.uniform(0.0, height_m);
    m.rect(pipe - 0.03, z, pipe + 0.13, z + 0.05, 40.0);
  }
  for (int i = 0; i < 3; ++i) {  // vents and boxes
    const double x = rng.uniform(0.0, width_m), z = rng.uniform(0.5, height_m);
    const double a = rng.uniform(0.2, 0.5), b = rng.uniform(0.2, 0.5);
    m.rect(x, z, x + a, z + b, rng.chance(0.5) ? 45.0 : 200.0);
    m.rect(x + 0.04, z + 0.04, x + a - 0.04, z + b - 0.04, rng.uniform(60.0, 160.0));
  }
  Canvas& raw = c;  // scrawls up to 2 m: random walks in pixels
  const double px_per_m = raw.height() / height_m;
  for (int i = 0; i < 2; ++i) {
    double x = rng.uniform(0.0, raw.width()), y = raw.height() - rng.uniform(0.3, 2.0) * px_per_m;
    const double value = rng.chance(0.5) ? 60.0 : 200.0;
    for (int k = 0; k < 12; ++k) {
      const double nx = x + rng.uniform(-6.0, 6.0), ny = y + rng.uniform(-6.0, 6.0);
      raw.blendLine(x, y, nx, ny, 1.5, value, 0.8);
      x = nx;
      y = ny;
    }
  }
}

// Glass with a reflection, optional blinds or curtains, frame, mullions and sill.
void paintWindow(MetricCanvas& m, Rng& rng, const FacadeStyle& s, double x, double z) {
  const double w = s.win_w, h = s.win_h, f = 0.07;
  m.rect(x - 0.12, z - 0.1, x + w + 0.12, z + h + 0.12, s.wall - 25.0, 0.6);  // reveal shadow
  const double glass = rng.uniform(20.0, 75.0);
  m.rect(x, z, x + w, z + h, glass);
  const double reflection = glass + rng.uniform(15.0, 45.0);  // GCC's former order (right to left)
  m.rect(x, z + h * rng.uniform(0.3, 0.7), x + w, z + h, reflection, 0.5);
  if (rng.chance(0.35)) {  // blinds down to some height, with slats
    const double bottom = z + h * rng.uniform(0.0, 0.8), tone = rng.uniform(135.0, 205.0);
    m.rect(x, bottom, x + w, z + h, tone);
    for (double sz = bottom + 0.06; sz < z + h; sz += 0.06 + rng.uniform(-0.004, 0.004))
      m.rect(x, sz, x + w, sz + 0.012, tone - 20.0, 0.7);
  } else if (rng.chance(0.3)) {  // curtains at the sides
    const double tone = rng.uniform(110.0, 190.0), cw = w * rng.uniform(0.15, 0.35);
    m.rect(x, z, x + cw, z + h, tone);
    m.rect(x + w - cw, z, x + w, z + h, tone);
  }
  m.rect(x - f, z - f, x + w + f, z, s.frame);
  m.rect(x - f, z + h, x + w + f, z + h + f, s.frame);
  m.rect(x - f, z, x, z + h, s.frame);
  m.rect(x + w, z, x + w + f, z + h, s.frame);
  if (s.mullions >= 1) m.rect(x + w / 2 - f / 2, z, x + w / 2 + f / 2, z + h, s.frame);
  if (s.mullions == 2) m.rect(x, z + 0.7 * h, x + w, z + 0.7 * h + f, s.frame);
  m.rect(x - 0.1, z - f - 0.07, x + w + 0.1, z - f, std::min(235.0, s.wall + 60.0));  // sill
}

}  // namespace

FacadeTextures facadeTextures(FacadeMaterial material, int size_px, std::uint64_t seed) {
  Rng rng = Rng::derive(seed, 20);
  const FacadeStyle s = randomStyle(material, rng);
  const double width_m = s.columns * s.pitch, height_m = s.floors * s.floor_h;
  Canvas wall(size_px, size_px, 0.0F);
  if (material == FacadeMaterial::kBrick) {
    paintBricks(wall, rng, width_m, height_m, s.wall);
    wall.addFractalNoise(rng, 2, 5, 16.0);  // weathering
  } else {
    paintPlaster(wall, rng, s, width_m, height_m);
  }
  paintWallDetails(wall, rng, width_m, height_m, s.wall);
  wall.addWhiteNoise(rng, 5.0);
  Canvas front = wall;
  MetricCanvas m(front, width_m, height_m);
  for (int floor = 0; floor < s.floors; ++floor) {
    for (int col = 0; col < s.columns; ++col) {
      const double x = (col + 0.5) * s.pitch - s.win_w / 2 + rng.uniform(-0.04, 0.04);
      const double z = floor * s.floor_h + s.sill_z + rng.uniform(-0.03, 0.03);
      m.addRect(x + 0.1, z - 1.2, x + s.win_w - 0.1, z - 0.1, -10.0);  // rain streaks below
      paintWindow(m, rng, s, x, z);
    }
  }
  wall.scale(0.72);  // side walls face away from the light
  front.clamp(0.0, 255.0);
  wall.clamp(0.0, 255.0);
  const Eigen::Vector2d tile(width_m, height_m);
  return {{front.toTexture(), tile}, {wall.toTexture(), tile}};
}

ProceduralTexture carBodyTexture(int size_px, std::uint64_t seed, double paint_grey) {
  Rng rng = Rng::derive(seed, 30 + static_cast<std::uint64_t>(paint_grey));
  constexpr double kLength = 4.2, kHeight = 0.75;
  Canvas c(size_px, size_px, static_cast<float>(paint_grey));
  MetricCanvas m(c, kLength, kHeight);
  c.addValueNoise(rng, 1, 6, 10.0);
  m.addRect(0, 0.55, kLength, kHeight, 18.0);  // upper body catches the sky
  m.rect(0, 0, kLength, 0.18, 35.0);           // sills and bumpers
  for (const double door : {1.45, 2.6}) m.rect(door, 0.12, door + 0.015, 0.7, paint_grey * 0.5);
  for (const double handle : {1.7, 2.85}) m.rect(handle, 0.5, handle + 0.18, 0.54, 40.0);
  const double r = 0.36;  // wheel arches: dark half discs over the wheels
  for (const double cx : {0.8, 3.4}) {
    for (double z = 0.0; z < r; z += 0.5 / m.pxPerMetreZ()) {
      const double half = std::sqrt(r * r - z * z);
      m.rect(cx - half, z, cx + half, z + 0.5 / m.pxPerMetreZ(), 18.0);
    }
  }
  m.rect(0.02, 0.45, 0.2, 0.62, 225.0);                      // head light
  m.rect(kLength - 0.18, 0.45, kLength - 0.02, 0.62, 70.0);  // tail light
  c.addWhiteNoise(rng, 4.0);
  c.clamp(0.0, 255.0);
  return {c.toTexture(), Eigen::Vector2d(kLength, kHeight)};
}

ProceduralTexture carCabinTexture(int size_px, std::uint64_t seed) {
  Rng rng = Rng::derive(seed, 40);
  Canvas c(size_px, size_px, 45.0F);  // glass
  MetricCanvas m(c, 1.0, 1.0);
  c.addValueNoise(rng, 3, 2, 18.0);
  m.rect(0.1, 0.45, 0.9, 0.9, 110.0, 0.35);                                       // sky reflection
  for (const double x : {0.0, 0.47, 0.94}) m.rect(x, 0.0, x + 0.06, 1.0, 120.0);  // pillars
  m.rect(0.0, 0.88, 1.0, 1.0, 120.0);                                             // roof edge
  c.addWhiteNoise(rng, 5.0);
  c.clamp(0.0, 255.0);
  return {c.toTexture(), Eigen::Vector2d(1.0, 1.0)};
}

}  // namespace gvio::sim
