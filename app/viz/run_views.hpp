#pragma once
// The images `gvio render` draws of a run: which primitives, camera and 2-D annotations each
// view uses. Pure scene building; the CLI owns the EGL context and the file output.
//  - topdown:     orthographic ENU map, north up: the cloud coloured by height (when map.pcd
//                 exists), trajectories, GNSS fixes (used / rejected / skipped), outages and
//                 accepted loop closures (loops.csv) on top.
//  - perspective: the dense cloud from behind and above the start of the drive, with the
//                 trajectory (without map.pcd: an orbit view of the trajectories, as before maps).
//  - octomap:     the OctoMap's occupied voxels as shaded cubes, same viewpoint.
//  - error:       the estimate coloured by its APE against the truth.
#include <filesystem>
#include <optional>
#include <string>

#include "io/run_dir.hpp"
#include "render/annotate.hpp"
#include "render/camera.hpp"
#include "render/scene.hpp"

namespace gvio::viz {

enum class RunView { kTopDown, kPerspective, kOctomap, kError };
// topdown|perspective|octomap|error; InvalidInput else.
RunView parseRunView(const std::string& name);

// The run files a view draws (the map files are large: read only what is drawn).
io::RunReadOptions readOptionsFor(RunView view,
                                  const std::optional<std::filesystem::path>& reference);

struct ViewSpec {
  render::Scene scene;
  render::RenderCamera camera;
  render::Annotations annotations;
};

// Throws InvalidInput when the view cannot be drawn from the run (error view without truth,
// octomap view without map.ot / map.bt or without occupied voxels).
ViewSpec buildRunView(const io::RunFiles& run, RunView view, int width, int height);

// The top-down view without its lines (trajectories, GNSS outages, loop closures) and their legend
// entries, plus a legend entry for the path a video draws as it grows: the map for
// `gvio render --video --view topdown`.
ViewSpec buildTopDownMapOnly(io::RunFiles run, int width, int height);

// A top-down camera fitted to `box`, keeping it clear of the compass, colour bar and title.
render::RenderCamera topDownClearOfOverlays(const Eigen::AlignedBox3d& box, int width, int height);

// Metres one pixel spans at `p_w` (perspective: at its depth; orthographic: everywhere).
double metresPerPixelAt(const render::RenderCamera& camera, const Eigen::Vector3d& p_w);

}  // namespace gvio::viz
