#pragma once
// `gvio render --run MAP` of a `gvio merge` folder: the merged map from above, north up, each
// drive's points in a colour of its own (where drives overlap, both show), the tile grid, the
// drives' tracks, a legend of the drives.
#include "fleet/merged_map.hpp"
#include "viz/run_views.hpp"

namespace gvio::viz {

// Throws InvalidInput for a map without a point.
ViewSpec buildMergedTopDown(const fleet::MergedMap& map, int width, int height);

// The colour of drive `point_source_id` (a qualitative palette, repeating after 10 drives).
render::Rgb driveColour(std::uint16_t point_source_id);

}  // namespace gvio::viz
