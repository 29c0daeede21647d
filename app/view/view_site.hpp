#pragma once
// `gvio view`'s static site: the viewer page (index.html and the bundled viewer.js, built from
// app/view/web by npm + esbuild) and the data it shows, in one folder that opens from disk
// (file://) or over HTTP:
//   index.html, viewer.js      the page (copied from the built viewer)
//   data/scene.js              gvioScene({...}): view_scene.hpp's scene, plus "points" (the
//                              octree's node index: view_points.hpp) and "voxels" (a count)
//   data/points/NAME.js        one octree node's points (view_points.hpp)
//   data/keyframes/NNNNN.jpg   a keyframe's recorded image with the map drawn over it
//   data/voxels.js             gvioVoxels(N, "BASE64 float32 [x y z edge] x N", "BASE64 rgb x N")
// The folder is built beside its place and renamed into it (io::writeFolderAtomic).
#include <cstddef>
#include <filesystem>

#include "mapping/point_lod.hpp"
#include "view/view_scene.hpp"

namespace gvio::view {

struct ViewSiteSummary {
  std::size_t points = 0, nodes = 0, voxels = 0, trajectories = 0;
  int depth = 0;
  std::size_t images = 0;
};

// The built page's folder (holds index.html and viewer.js), or an empty path when this build of
// gvio has none (the viewer is built by ./setup.sh viewer or test, which install node and npm).
std::filesystem::path builtViewerPage();

// Whether `dir` holds a site this writer made (index.html and data/scene.js).
bool isViewSite(const std::filesystem::path& dir);

// The scene of a run folder or a merged map (a folder with tiles.json): view_scene.hpp.
ViewInput readViewInput(const std::filesystem::path& input);

// Writes the site of `in` into `out` (made, or replaced when it holds an earlier site; any other
// existing non-empty folder is refused), with the page from `page_dir`: the keyframes' images
// (in.keyframe_jpeg) as data/keyframes/NNNNN.jpg, listed in the scene's keyframes.images.
// Throws InputError naming the offending file.
ViewSiteSummary writeViewSite(ViewInput& in, const std::filesystem::path& out,
                              const std::filesystem::path& page_dir,
                              const mapping::PointLodConfig& lod = {});

}  // namespace gvio::view
