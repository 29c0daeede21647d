// gvio view: a run folder or a merged map as a web page (app/view/view_site.hpp), optionally
// served on localhost.
#include <spdlog/spdlog.h>

#include <chrono>

#include "cli/app.hpp"
#include "cli/interrupt.hpp"
#include "cli/view_images.hpp"
#include "fleet/merged_map.hpp"
#include "io/run_dir.hpp"
#include "odometry/error.hpp"
#include "view/static_server.hpp"
#include "view/view_site.hpp"

namespace gvio::cli {
namespace {

struct ViewCliOptions {
  std::string run;
  std::optional<std::string> out;
  ViewImagesRequest images;
  bool serve = false;
  int port = 8000;
};

int runView(const ViewCliOptions& o) {
  const std::filesystem::path page = view::builtViewerPage();
  if (page.empty()) {
    throw InvalidInput(
        "this gvio was built without the viewer's page (it needs node and npm): build it with "
        "./setup.sh viewer");
  }
  const std::filesystem::path out =
      o.out ? std::filesystem::path(*o.out) : std::filesystem::path(o.run) / "viewer";
  if (const auto warning = io::incompleteRunWarning(o.run)) spdlog::warn("{}", *warning);
  const auto t0 = std::chrono::steady_clock::now();
  view::ViewInput in;
  if (fleet::isMergedMap(o.run)) {
    in = view::readMergedForView(o.run);
  } else {
    // Read once: the scene, and the map the keyframe images draw.
    io::RunFiles run = io::readRunDir(o.run);
    in = view::readRunForView(run);
    run.occupancy.reset();
    if (const auto why = addKeyframeImages(std::move(run), in, o.images)) {
      spdlog::info("view: no keyframe images ({})", *why);
    }
  }
  const auto t1 = std::chrono::steady_clock::now();
  const view::ViewSiteSummary s = view::writeViewSite(in, out, page);
  const double write_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  spdlog::info(
      "wrote {}: {} points in {} octree nodes ({} levels), {} trajectories, {} voxels, {} "
      "keyframe images",
      (out / "index.html").string(), s.points, s.nodes, s.nodes > 0 ? s.depth + 1 : 0,
      s.trajectories, s.voxels, s.images);
  // The octree's cost per million points (issue 62's target: 0.2 s), apart from reading the
  // input and drawing the keyframe images.
  spdlog::info("view: read in {:.2f} s, site written in {:.2f} s ({:.3f} s per million points)",
               std::chrono::duration<double>(t1 - t0).count(), write_s,
               s.points > 0 ? write_s / (static_cast<double>(s.points) * 1e-6) : 0.0);
  if (!o.serve) return 0;
  const InterruptGuard guard;
  view::serveFolder(
      out, o.port,
      [](int port) { spdlog::info("serving on http://127.0.0.1:{}/ (Ctrl-C stops)", port); },
      [] { return InterruptGuard::pending() != 0; });
  return 0;
}

}  // namespace

Command addViewCommand(CLI::App& app) {
  auto o = std::make_shared<ViewCliOptions>();
  CLI::App* sub = app.add_subcommand(
      "view", "Write a web page to look around a run or a merged map (3-D, level of detail)");
  sub->add_option("--run", o->run, "Run folder (gvio run --out) or merged map (gvio merge --out)")
      ->required();
  sub->add_option("--out", o->out, "Site folder (default: RUN/viewer)");
  sub->add_option("--images", o->images.max_images,
                  "Keyframes shown with their image and the map over it (0: none)")
      ->check(CLI::Range(0, 100000));
  sub->add_option("--dataset", o->images.dataset,
                  "The run's recordings, where report.json's sources have moved");
  sub->add_flag("--serve", o->serve, "Serve the site on 127.0.0.1 until Ctrl-C");
  sub->add_option("--port", o->port, "Port for --serve (0: any free one)")
      ->check(CLI::Range(0, 65535));
  return {sub, [o] { return runView(*o); }};
}

}  // namespace gvio::cli
