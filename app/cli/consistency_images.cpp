#include "cli/consistency_images.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include <nlohmann/json.hpp>

#include "cli/config.hpp"
#include "eval/image_check_plot.hpp"
#include "eval/image_check_report.hpp"
#include "io/atomic_write.hpp"
#include "io/image_loader.hpp"
#include "io/input_error.hpp"
#include "io/run_map.hpp"
#include "odometry/error.hpp"
#include "viz/camera_view.hpp"

namespace gvio::cli {
namespace {
namespace fs = std::filesystem;

double seconds(std::int64_t t_ns) {
  return static_cast<double>(t_ns) * 1e-9;
}

// Worst first: flagged before unflagged, then by ZNCC (unscored last), then by depth agreement.
std::vector<std::size_t> worstOrder(const std::vector<eval::ImageCheckRow>& rows) {
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

eval::ImageCheckResult checkAll(viz::ImageCheck& check, const std::vector<std::size_t>& todo,
                                std::int64_t t0_ns, const ImageConsistencyRequest& r) {
  eval::ImageCheckResult out;
  Progress progress("image check", todo.size(), "keyframes", r.progress);
  for (const std::size_t k : todo) {
    eval::ImageCheckRow c;
    c.view = check.check(k);
    c.p_map = check.keyframes()[k].T_map_c.translation();
    out.rows.push_back(c);
    out.t_s.push_back(seconds(c.view.t_ns - t0_ns));
    progress.update(out.rows.size());
  }
  progress.finish();
  // The self-check on keyframes spread over those checked.
  std::vector<mapping::ViewScore> self;
  const std::size_t n = std::min(r.check.self_check_keyframes, todo.size());
  for (std::size_t i = 0; i < n; ++i) self.push_back(check.selfCheck(todo[i * todo.size() / n]));
  eval::applySelfCheck(out, self, r.check.min_self_depth_agreement);
  if (!out.self_check.depth_valid) {
    spdlog::warn(
        "{}: a keyframe's own points drawn from its own pose agree with its stereo depth on only "
        "{:.0f} % of the pixels (median of {} keyframes): the drawn and stereo depths are not "
        "comparable on this dataset, so the depth agreement is left out",
        r.run.string(), 100.0 * out.self_check.depth_median, n);
  }
  eval::flagImageCheck(out, r.check.score);
  return out;
}

eval::ImageCheckPlotData plotData(const eval::ImageCheckResult& c,
                                  const ImageConsistencyRequest& r) {
  eval::ImageCheckPlotData plot;
  plot.title = fmt::format("Map against the recorded images: {} ({} keyframes, {} s left out)",
                           r.run.filename().string(), c.rows.size(), r.check.exclude_s);
  plot.t_s = c.t_s;
  for (std::size_t i = 0; i < c.rows.size(); ++i) {
    plot.ncc.push_back(c.rows[i].view.score.ncc);
    plot.depth.push_back(c.rows[i].view.score.depth_agreement);
    plot.flagged.push_back(c.rows[i].flagged);
    plot.ncc_threshold.push_back(c.flags.ncc.below[i]);
    plot.depth_threshold.push_back(c.flags.depth.below[i]);
  }
  for (const auto& s : c.stretches) plot.stretches_s.emplace_back(c.t_s[s.first], c.t_s[s.last]);
  return plot;
}

// A previous check's side-by-side images would mix with this one's.
void removeOldImages(const fs::path& out) {
  for (const auto& entry : fs::directory_iterator(out)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("worst_", 0) == 0 && entry.path().extension() == ".png") {
      fs::remove(entry.path());
    }
  }
}

// recorded | drawn | difference for the worst keyframes (checked again for their images).
nlohmann::json writeWorstImages(viz::ImageCheck& check, const eval::ImageCheckResult& c,
                                const fs::path& out, std::size_t count) {
  nlohmann::json worst = nlohmann::json::array();
  const std::vector<std::size_t> order = worstOrder(c.rows);
  for (std::size_t n = 0; n < std::min(count, order.size()); ++n) {
    const eval::ImageCheckRow& row = c.rows[order[n]];
    viz::CheckImages images;
    (void)check.check(row.view.keyframe, &images);
    const fs::path file = out / fmt::format("worst_{}_{:.1f}s.png", n + 1, c.t_s[order[n]]);
    io::writePng(file, viz::sideBySide(images));
    worst.push_back({{"t_from_start_s", c.t_s[order[n]]},
                     {"ncc", eval::jsonNumber(row.view.score.ncc)},
                     {"depth_agreement", eval::jsonNumber(row.view.score.depth_agreement)},
                     {"flagged", row.flagged},
                     {"image", file.filename().string()}});
  }
  return worst;
}

void validateRequest(const ImageConsistencyRequest& r) {
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
}

}  // namespace

int runImageConsistency(const ImageConsistencyRequest& request) {
  ImageConsistencyRequest r = request;
  if (r.no_revisits) r.check.revisits = false;
  validateRequest(r);
  const fs::path out = r.out.value_or(r.run / "consistency_images");
  if (!fs::is_directory(fs::absolute(out).parent_path())) {
    throw io::InputError(out, 0, "output folder's parent does not exist");
  }
  // The check rebuilds the map: map.pcd is not read.
  const io::RunFiles run = io::readMapRun(r.run, /*with_cloud=*/false);
  const Trajectory& traj = io::mapTrajectory(run);
  const AppConfig app = loadRunConfig(r.run);
  std::string mode;
  const io::Dataset ds = io::reopenRunDataset(r.run, r.dataset, app.dataset, mode);
  viz::ImageCheck check(run, ds, app.map.map.dense, r.check);
  const std::int64_t t0_ns = traj.t_ns.front();
  const std::vector<std::size_t> todo = keyframesToCheck(check, r, t0_ns);
  spdlog::info("checking {} of {} map keyframes against their images ({} s left out around each)",
               todo.size(), check.keyframes().size(), r.check.exclude_s);
  const eval::ImageCheckResult result = checkAll(check, todo, t0_ns, r);

  fs::create_directories(out);
  removeOldImages(out);
  io::writeTextAtomic(out / "keyframes.csv", eval::imageCheckCsv(result));
  if (result.rows.size() >= 2) {
    eval::writeImageCheckPlot(plotData(result, r), (out / "scores").string());
  }
  nlohmann::json j =
      eval::imageCheckSummary(result, check.keyframes().size(), r.run, r.check, r.every);
  j["worst"] = writeWorstImages(check, result, out, r.worst_images);
  const std::string summary = j.dump(2) + "\n";
  io::writeTextAtomic(out / "summary.json", summary);
  if (r.json) io::writeTextAtomic(*r.json, summary);
  spdlog::info("{}; wrote {}", eval::imageCheckSummaryLine(result), out.string());
  return 0;
}

}  // namespace gvio::cli
