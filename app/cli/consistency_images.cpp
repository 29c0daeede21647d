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
#include "io/atomic_write.hpp"
#include "io/image_loader.hpp"
#include "io/input_error.hpp"
#include "io/run_map.hpp"
#include "mapping/consistency.hpp"
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

// The stamp as the dataset gives it (integer nanoseconds), not through a double.
std::string stamp(std::int64_t t_ns) {
  const std::int64_t s = t_ns / 1'000'000'000, ns = t_ns % 1'000'000'000;
  return t_ns < 0 ? fmt::format("{:.9f}", static_cast<double>(t_ns) * 1e-9)
                  : fmt::format("{}.{:09d}", s, ns);
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

// Every requested keyframe checked, then flagged against the others.
struct CheckResult {
  std::vector<Checked> rows;
  std::vector<double> t_s;  // of each row, from the start of the trajectory
  mapping::FlaggedViews flags;
  std::vector<mapping::ViewStretch> stretches;
};

CheckResult checkAll(viz::ImageCheck& check, const std::vector<std::size_t>& todo,
                     std::int64_t t0_ns, const ImageConsistencyRequest& r) {
  CheckResult out;
  Progress progress("image check", todo.size(), "keyframes", r.progress);
  for (const std::size_t k : todo) {
    Checked c;
    c.view = check.check(k);
    c.p_map = check.keyframes()[k].T_map_c.translation();
    out.rows.push_back(c);
    out.t_s.push_back(seconds(c.view.t_ns - t0_ns));
    progress.update(out.rows.size());
  }
  progress.finish();
  std::vector<mapping::ViewScore> scores;
  for (const Checked& c : out.rows) scores.push_back(c.view.score);
  out.flags = mapping::flagOutliers(scores, out.t_s, r.check.score);
  for (std::size_t i = 0; i < out.rows.size(); ++i) out.rows[i].flagged = out.flags.flagged[i];
  out.stretches = mapping::flaggedStretches(out.flags.flagged);
  return out;
}

// What a keyframe is flagged below (the larger of the drive's and its neighbours' threshold).
double flagBelow(const mapping::ScoreThresholds& th, std::size_t i) {
  return std::max(th.global, th.local[i]);
}

std::string csvOf(const CheckResult& c, std::int64_t t0_ns) {
  std::string out =
      "t_s,t_from_start_s,x_m,y_m,z_m,ncc,ncc_flag_below,patches,coverage,depth_agreement,"
      "depth_flag_below,depth_pixels,source_keyframes,points_drawn,flagged,ms\n";
  for (std::size_t i = 0; i < c.rows.size(); ++i) {
    const Checked& row = c.rows[i];
    const auto& s = row.view.score;
    out += fmt::format("{},{:.3f},{:.3f},{:.3f},{:.3f},{},{},{},{:.4f},{},{},{},{},{},{},{:.1f}\n",
                       stamp(row.view.t_ns), seconds(row.view.t_ns - t0_ns), row.p_map.x(),
                       row.p_map.y(), row.p_map.z(), number(s.ncc, 4),
                       number(flagBelow(c.flags.ncc, i), 4), s.patches, s.coverage,
                       number(s.depth_agreement, 4), number(flagBelow(c.flags.depth, i), 4),
                       s.depth_pixels, row.view.source_keyframes, row.view.points_drawn,
                       row.flagged ? 1 : 0, row.view.ms);
  }
  return out;
}

eval::ImageCheckPlotData plotData(const CheckResult& c, const ImageConsistencyRequest& r) {
  eval::ImageCheckPlotData plot;
  plot.title = fmt::format("Map against the recorded images: {} ({} keyframes, {} s left out)",
                           r.run.filename().string(), c.rows.size(), r.check.exclude_s);
  plot.t_s = c.t_s;
  for (std::size_t i = 0; i < c.rows.size(); ++i) {
    plot.ncc.push_back(c.rows[i].view.score.ncc);
    plot.depth.push_back(c.rows[i].view.score.depth_agreement);
    plot.flagged.push_back(c.rows[i].flagged);
    plot.ncc_threshold.push_back(flagBelow(c.flags.ncc, i));
    plot.depth_threshold.push_back(flagBelow(c.flags.depth, i));
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
nlohmann::json writeWorstImages(viz::ImageCheck& check, const CheckResult& c, const fs::path& out,
                                std::size_t count) {
  nlohmann::json worst = nlohmann::json::array();
  const std::vector<std::size_t> order = worstOrder(c.rows);
  for (std::size_t n = 0; n < std::min(count, order.size()); ++n) {
    const Checked& row = c.rows[order[n]];
    viz::CheckImages images;
    (void)check.check(row.view.keyframe, &images);
    const fs::path file = out / fmt::format("worst_{}_{:.1f}s.png", n + 1, c.t_s[order[n]]);
    io::writePng(file, viz::sideBySide(images));
    worst.push_back({{"t_from_start_s", c.t_s[order[n]]},
                     {"ncc", finiteOrNull(row.view.score.ncc)},
                     {"depth_agreement", finiteOrNull(row.view.score.depth_agreement)},
                     {"flagged", row.flagged},
                     {"image", file.filename().string()}});
  }
  return worst;
}

std::size_t flaggedCount(const CheckResult& c) {
  return static_cast<std::size_t>(
      std::count_if(c.rows.begin(), c.rows.end(), [](const Checked& r) { return r.flagged; }));
}

std::vector<double> scoresOf(const CheckResult& c, bool ncc) {
  std::vector<double> v;
  for (const Checked& r : c.rows)
    v.push_back(ncc ? r.view.score.ncc : r.view.score.depth_agreement);
  return v;
}

double msMean(const CheckResult& c) {
  std::vector<double> ms;
  for (const Checked& row : c.rows) ms.push_back(row.view.ms);
  return meanOf(ms);
}

nlohmann::json summaryJson(const CheckResult& c, std::size_t map_keyframes,
                           const ImageConsistencyRequest& r) {
  std::vector<double> ms;
  for (const Checked& row : c.rows) ms.push_back(row.view.ms);
  nlohmann::json stretches = nlohmann::json::array();
  for (const auto& s : c.stretches) {
    stretches.push_back(
        {{"from_s", c.t_s[s.first]}, {"to_s", c.t_s[s.last]}, {"keyframes", s.last - s.first + 1}});
  }
  const auto scored = [&](bool ncc) {
    const std::vector<double> v = scoresOf(c, ncc);
    return std::count_if(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
  };
  nlohmann::json j;
  j["run"] = r.run.string();
  j["keyframes"] = {{"map", map_keyframes},
                    {"checked", c.rows.size()},
                    {"flagged", flaggedCount(c)},
                    {"ncc_scored", scored(true)},
                    {"depth_scored", scored(false)}};
  j["ncc"] = {{"mean", finiteOrNull(meanOf(scoresOf(c, true)))},
              {"median", finiteOrNull(c.flags.ncc.median)},
              {"flag_threshold", finiteOrNull(c.flags.ncc.global)}};
  j["depth_agreement"] = {{"mean", finiteOrNull(meanOf(scoresOf(c, false)))},
                          {"median", finiteOrNull(c.flags.depth.median)},
                          {"flag_threshold", finiteOrNull(c.flags.depth.global)}};
  j["flagged_stretches"] = stretches;
  j["ms_per_keyframe"] = {{"mean", finiteOrNull(meanOf(ms))},
                          {"median", mapping::percentile(ms, 0.5)},
                          {"p90", mapping::percentile(ms, 0.9)}};
  j["options"] = {{"exclude_s", r.check.exclude_s},
                  {"neighbour_radius_m", r.check.neighbour_radius_m},
                  {"max_view_angle_deg", r.check.max_view_angle_deg},
                  {"max_depth_m", r.check.max_depth_m},
                  {"patch_px", r.check.score.patch_px},
                  {"flag_sigmas", r.check.score.flag_sigmas},
                  {"every", r.every}};
  return j;
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

int runImageConsistency(const ImageConsistencyRequest& r) {
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
  const CheckResult result = checkAll(check, todo, t0_ns, r);

  fs::create_directories(out);
  removeOldImages(out);
  io::writeTextAtomic(out / "keyframes.csv", csvOf(result, t0_ns));
  if (result.rows.size() >= 2) {
    eval::writeImageCheckPlot(plotData(result, r), (out / "scores").string());
  }
  nlohmann::json j = summaryJson(result, check.keyframes().size(), r);
  j["worst"] = writeWorstImages(check, result, out, r.worst_images);
  const std::string summary = j.dump(2) + "\n";
  io::writeTextAtomic(out / "summary.json", summary);
  if (r.json) io::writeTextAtomic(*r.json, summary);
  spdlog::info(
      "ZNCC mean {} (median {}), depth agreement mean {} (median {}); {} of {} keyframes "
      "flagged in {} stretches; {} ms per keyframe; wrote {}",
      number(meanOf(scoresOf(result, true)), 3), number(result.flags.ncc.median, 3),
      number(meanOf(scoresOf(result, false)), 3), number(result.flags.depth.median, 3),
      flaggedCount(result), result.rows.size(), result.stretches.size(), number(msMean(result), 0),
      out.string());
  return 0;
}

}  // namespace gvio::cli
