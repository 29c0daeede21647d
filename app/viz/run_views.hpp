#pragma once
// The images `gvio render` draws of a run: which primitives, camera and 2-D annotations each
// view uses. Pure scene building; the CLI owns the EGL context and the file output.
#include <string>

#include "io/run_dir.hpp"
#include "render/annotate.hpp"
#include "render/camera.hpp"
#include "render/scene.hpp"

namespace gvio::viz {

enum class RunView { kTopDown, kPerspective, kError };
RunView parseRunView(const std::string& name);  // topdown|perspective|error; InvalidInput else

struct ViewSpec {
  render::Scene scene;
  render::RenderCamera camera;
  render::Annotations annotations;
};

// Throws InvalidInput when the view cannot be drawn from the run (error view without truth).
ViewSpec buildRunView(const io::RunFiles& run, RunView view, int width, int height);

}  // namespace gvio::viz
