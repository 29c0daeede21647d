#include "cli/consistency_images.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include <nlohmann/json.hpp>

#include "cli/config.hpp"
#include "cli/render_camera.hpp"
#include "eval/image_check_plot.hpp"
#include "io/atomic_write.hpp"
#include "io/image_loader.hpp"
#include "io/input_error.hpp"
#include "io/run_dir.hpp"
#include "odometry/error.hpp"
#include "viz/camera_view.hpp"

namespace gvio::cli {
namespace {
namespace fs = std::filesystem;

struct Checked {
  viz::CheckedView view;
  Eigen::Vector3d p_map = Eigen::Vector3d::Zero();
  bool flagged = false;
};

double seconds(std::int64_t t_ns) {
  return static_cast<double>(t_ns) * 1e-9;
}

std::string number(double v, int decimals) {
  return std::isfinite(v) ? fmt::format("{:.{}f}", v, decimals) : std::string("nan");
}

nlohmann::json finiteOrNull(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

std::string csvOf(const std::vector<Checked>& rows, std::int64_t t0_ns,
                  const mapping::FlaggedViews& flags) {
  std::string out =
      "t_s,t_from_start_s,x_m,y_m,z_m,ncc,ncc_flag_below,patches,coverage,depth_agreement,"
      "depth_flag_below,depth_pixels,source_keyframes,points_drawn,flagged,ms\n";
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const Checked& c = rows[i];
    const auto& s = c.view.score;
    out += fmt::format(
        "{:.9f},{:.3f},{:.3f},{:.3f},{:.3f},{},{},{},{:.4f},{},{},{},{},{},{},{:.1f}\n",
        seconds(c.view.t_ns), seconds(c.view.t_ns - t0_ns), c.p_map.x(), c.p_map.y(), c.p_map.z(),
        number(s.ncc, 4), number(std::max(flags.ncc.global, flags.ncc.local[i]), 4), s.patches,
        s.coverage, number(s.depth_agreement, 4),
        number(std::max(flags.depth.global, flags.depth.local[i]), 4), s.depth_pixels,
        c.view.source_keyframes, c.view.points_drawn, c.flagged ? 1 : 0, c.view.ms);
  }
  return out;
}

// Mean of the finite values; NaN when there are none.
double meanOf(const std::vector<double>& v) {
  double sum = 0.0;
  std::size_t n = 0;
  for (const double x : v) {
    if (!std::isfinite(x)) continue;
    sum += x;
    ++n;
  }
  return n > 0 ? sum / static_cast<double>(n) : std::numeric_limits<double>::quiet_NaN();
}

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(std::floor(q * static_cast<double>(v.size() - 1)))];
}

// Worst first: flagged before unflagged, then by ZNCC (unscored last), then by depth agreement.
std::vector<std::size_t> worstOrder(const std::vector<Checked>& rows) {
  std::vector<std::size_t> order(rows.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  const auto key = [&](std::size_t i) {
    const auto& s = rows[i].view.score;
    return std::make_tuple(rows[i].flagged ? 0 : 1, s.hasNcc() ? s.ncc : 2.0,
                           s.hasDepth() ? s.depth_agreement : 2.0);
  };
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return key(a) < key(b); });
  return order;
}

std::vector<std::size_t> keyframesToCheck(const viz::ImageCheck& check,
                                          const ImageConsistencyRequest& r, std::int64_t t0_ns) {
  if (r.at_s) {
    return {check.keyframeNearest(t0_ns + static_cast<std::int64_t>(std::llround(*r.at_s * 1e9)))};
  }
  const auto inside = [&](std::int64_t t_ns) {
    const double t = seconds(t_ns - t0_ns);
    return (!r.from_s || t >= *r.from_s) && (!r.to_s || t <= *r.to_s);
  };
  std::vector<std::size_t> in_range;
  for (std::size_t k = 0; k < check.keyframes().size(); ++k) {
    if (inside(check.keyframes()[k].t_ns)) in_range.push_back(k);
  }
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < in_range.size(); i += r.every) out.push_back(in_range[i]);
  if (out.empty()) throw InvalidInput("--from/--to: no map keyframe in that time range");
  return out;
}

}  // namespace

int runImageConsistency(const ImageConsistencyRequest& r) {
  if (r.every < 1) throw InvalidInput("--every must be >= 1");
  if (r.at_s && (!std::isfinite(*r.at_s) || *r.at_s < 0.0)) {
    throw InvalidInput("--at must be >= 0 s");
  }
  if ((r.from_s && !std::isfinite(*r.from_s)) || (r.to_s && !std::isfinite(*r.to_s)) ||
      (r.from_s && r.to_s && *r.to_s < *r.from_s)) {
    throw InvalidInput("--from/--to: expected a time range with from <= to (s)");
  }
  if (r.at_s && (r.from_s || r.to_s)) throw InvalidInput("--at excludes --from/--to");
  r.check.validate();
  const fs::path out = r.out.value_or(r.run / "consistency_images");
  if (!fs::is_directory(fs::absolute(out).parent_path())) {
    throw io::InputError(out, 0, "output folder's parent does not exist");
  }
  if (const auto warning = io::incompleteRunWarning(r.run)) spdlog::warn("{}", *warning);
  io::RunReadOptions read;
  read.cloud = read.occupancy = read.gnss_fixes = read.outages = read.loops = false;
  const io::RunFiles run = io::readRunDir(r.run, read);
  const Trajectory& traj = viz::mapTrajectory(run);
  if (!traj.hasTimestamps()) throw io::InputError(r.run, 0, "the trajectory has no timestamps");
  std::string mode;
  const io::Dataset ds = reopenRunDataset(r.run, r.dataset, mode);
  ConfigSources config;
  if (fs::exists(r.run / "config.yaml")) config.file = r.run / "config.yaml";
  const AppConfig app = loadConfig(config);
  viz::ImageCheck check(run, ds, app.map.map.dense, r.check);
  const std::int64_t t0_ns = traj.t_ns.front();
  const std::vector<std::size_t> todo = keyframesToCheck(check, r, t0_ns);
  spdlog::info("checking {} of {} map keyframes against their images ({} s left out around each)",
               todo.size(), check.keyframes().size(), r.check.exclude_s);

  std::vector<Checked> rows;
  Progress progress("image check", todo.size(), "keyframes", r.progress);
  for (const std::size_t k : todo) {
    Checked c;
    c.view = check.check(k);
    c.p_map = check.keyframes()[k].T_map_c.translation();
    rows.push_back(c);
    progress.update(rows.size());
  }
  progress.finish();
  std::vector<mapping::ViewScore> scores;
  for (const Checked& c : rows) scores.push_back(c.view.score);
  std::vector<double> t_s;
  for (const Checked& c : rows) t_s.push_back(seconds(c.view.t_ns - t0_ns));
  const mapping::FlaggedViews flags = mapping::flagOutliers(scores, t_s, r.check.score);
  for (std::size_t i = 0; i < rows.size(); ++i) rows[i].flagged = flags.flagged[i];
  const auto stretches = mapping::flaggedStretches(flags.flagged);

  fs::create_directories(out);
  // A previous check's side-by-side images would mix with this one's.
  for (const auto& entry : fs::directory_iterator(out)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("worst_", 0) == 0 && entry.path().extension() == ".png")
      fs::remove(entry.path());
  }
  io::writeTextAtomic(out / "keyframes.csv", csvOf(rows, t0_ns, flags));

  eval::ImageCheckPlotData plot;
  plot.title = fmt::format("Map against the recorded images: {} ({} keyframes, {} s left out)",
                           r.run.filename().string(), rows.size(), r.check.exclude_s);
  std::vector<double> ms;
  for (const Checked& c : rows) {
    plot.t_s.push_back(seconds(c.view.t_ns - t0_ns));
    plot.ncc.push_back(c.view.score.ncc);
    plot.depth.push_back(c.view.score.depth_agreement);
    plot.flagged.push_back(c.flagged);
    ms.push_back(c.view.ms);
  }
  nlohmann::json jstretches = nlohmann::json::array();
  for (const auto& s : stretches) {
    plot.stretches_s.emplace_back(plot.t_s[s.first], plot.t_s[s.last]);
    jstretches.push_back({{"from_s", plot.t_s[s.first]},
                          {"to_s", plot.t_s[s.last]},
                          {"keyframes", s.last - s.first + 1}});
  }
  for (std::size_t i = 0; i < rows.size(); ++i) {
    plot.ncc_threshold.push_back(std::max(flags.ncc.global, flags.ncc.local[i]));
    plot.depth_threshold.push_back(std::max(flags.depth.global, flags.depth.local[i]));
  }
  if (rows.size() >= 2) eval::writeImageCheckPlot(plot, (out / "scores").string());

  nlohmann::json worst = nlohmann::json::array();
  const std::vector<std::size_t> order = worstOrder(rows);
  for (std::size_t n = 0; n < std::min(r.worst_images, order.size()); ++n) {
    const Checked& c = rows[order[n]];
    viz::CheckImages images;
    (void)check.check(c.view.keyframe, &images);
    const fs::path file = out / fmt::format("worst_{}_{:.1f}s.png", n + 1, plot.t_s[order[n]]);
    io::writePng(file, viz::sideBySide(images));
    worst.push_back({{"t_from_start_s", plot.t_s[order[n]]},
                     {"ncc", finiteOrNull(c.view.score.ncc)},
                     {"depth_agreement", finiteOrNull(c.view.score.depth_agreement)},
                     {"flagged", c.flagged},
                     {"image", file.filename().string()}});
  }
  std::size_t flagged = 0;
  for (const Checked& c : rows) flagged += c.flagged ? 1 : 0;
  nlohmann::json j;
  j["run"] = r.run.string();
  j["keyframes"] = {
      {"map", check.keyframes().size()},
      {"checked", rows.size()},
      {"flagged", flagged},
      {"ncc_scored", std::count_if(rows.begin(), rows.end(),
                                   [](const Checked& c) { return c.view.score.hasNcc(); })},
      {"depth_scored", std::count_if(rows.begin(), rows.end(),
                                     [](const Checked& c) { return c.view.score.hasDepth(); })}};
  j["ncc"] = {{"mean", finiteOrNull(meanOf(plot.ncc))},
              {"median", finiteOrNull(flags.ncc.median)},
              {"flag_threshold", finiteOrNull(flags.ncc.global)}};
  j["depth_agreement"] = {{"mean", finiteOrNull(meanOf(plot.depth))},
                          {"median", finiteOrNull(flags.depth.median)},
                          {"flag_threshold", finiteOrNull(flags.depth.global)}};
  j["flagged_stretches"] = jstretches;
  j["worst"] = worst;
  j["ms_per_keyframe"] = {{"mean", finiteOrNull(meanOf(ms))},
                          {"median", finiteOrNull(quantile(ms, 0.5))},
                          {"p90", finiteOrNull(quantile(ms, 0.9))}};
  j["options"] = {{"exclude_s", r.check.exclude_s},
                  {"neighbour_radius_m", r.check.neighbour_radius_m},
                  {"max_depth_m", r.check.max_depth_m},
                  {"patch_px", r.check.score.patch_px},
                  {"flag_sigmas", r.check.score.flag_sigmas},
                  {"every", r.every}};
  const std::string summary = j.dump(2) + "\n";
  io::writeTextAtomic(out / "summary.json", summary);
  if (r.json) io::writeTextAtomic(*r.json, summary);
  spdlog::info(
      "ZNCC mean {} (median {}), depth agreement mean {} (median {}); {} of {} keyframes "
      "flagged in {} stretches; {:.0f} ms per keyframe; wrote {}",
      number(meanOf(plot.ncc), 3), number(flags.ncc.median, 3), number(meanOf(plot.depth), 3),
      number(flags.depth.median, 3), flagged, rows.size(), stretches.size(), meanOf(ms),
      out.string());
  return 0;
}

}  // namespace gvio::cli
