// The repetitive world: the same period (kRepetitivePeriod_m of arc length from the route's start)
// over and over on both sides: an identical building in front (same facade, size, setback), an
// identical taller one behind it, a street lamp before it and a tree in the gap between buildings;
// the surfaces repeat with the same period (world_surfaces.cpp). On a straight road the view at s
// and at s + period is the same: what a place recognition must not take for a loop.
#include <cmath>

#include "sim/world_parts.hpp"

namespace gvio::sim::detail {
namespace {

struct Layout {  // along the period [s, s + period) and across, metres
  double building_at = 6.0, lamp_at = 6.0, tree_at = 0.0;
  double front_width = 8.0, front_depth = 10.0, front_height = 13.0, front_setback = 3.0;
  double back_width = 10.0, back_depth = 12.0, back_height = 19.0, back_lateral = 24.0;
  double tree_radius = 1.5, tree_trunk = 3.0, lamp_height = 7.0;
};

}  // namespace

void addRepetitiveObjects(Street& street, std::uint64_t seed) {
  Rng rng = Rng::derive(seed, 800);
  const Layout l;
  // One facade style each for the front and the back row, every texture offset 0: identical.
  const auto style = [&] {
    BuildingSkin skin;
    skin.style = static_cast<std::size_t>(
        rng.integer(0, static_cast<int>(street.lib.facade_front.size()) - 1));
    return skin;
  };
  const BuildingSkin front_skin = style(), back_skin = style();
  const std::uint64_t tree_seed = mixSeed(seed, 801);  // every tree from the same draws
  const double w = street.options.road_half_width_m, sw = street.options.sidewalk_width_m;
  const double period = kRepetitivePeriod_m;
  const double first = street.stations.front().s, last = street.stations.back().s;
  for (double s = std::ceil(first / period) * period; s + period <= last; s += period) {
    // A later pass along a street already built adds nothing out of phase with it.
    if (revisited(street, stationAt(street.stations, s + period / 2.0))) continue;
    for (const double side : {1.0, -1.0}) {
      const Station at = stationAt(street.stations, s + l.building_at);
      const double front = w + sw + l.front_setback;
      const Footprint f =
          along(at, side, front + l.front_depth / 2.0, l.front_width / 2.0, l.front_depth / 2.0);
      if (claim(street, f.grown(0.25), sidewalkClearance(street), 0.5))
        buildingMesh(street, f, l.front_height, front_skin);
      const Footprint b = along(at, side, l.back_lateral + l.back_depth / 2.0, l.back_width / 2.0,
                                l.back_depth / 2.0);
      if (claim(street, b.grown(0.25), sidewalkClearance(street), 0.5))
        buildingMesh(street, b, l.back_height, back_skin);
      const Station lamp = stationAt(street.stations, s + l.lamp_at);
      if (claimPole(street, lamp, side)) poleMesh(street, lamp, side, true, l.lamp_height);
      const Station gap = stationAt(street.stations, s + l.tree_at);
      const Footprint crown = along(gap, side, roadClearance(street) + 1.2 * l.tree_radius + 0.6,
                                    1.2 * l.tree_radius, 1.2 * l.tree_radius);
      if (claim(street, crown, roadClearance(street), 0.1)) {
        Rng tree_rng(tree_seed);
        treeMesh(street, tree_rng, crown.c, gap.t, l.tree_radius, l.tree_trunk);
      }
    }
  }
}

}  // namespace gvio::sim::detail
