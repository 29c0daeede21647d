// gvio eval: APE / RPE of an estimate against a reference, with evo's definitions and numbers,
// a readable table, JSON, the aligned estimate and plots.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <iostream>
#include <nlohmann/json.hpp>

#include "cli/app.hpp"
#include "eval/evaluate.hpp"
#include "eval/plots.hpp"
#include "io/atomic_write.hpp"
#include "io/intervals.hpp"
#include "io/text.hpp"
#include "io/trajectory_io.hpp"
#include "odometry/error.hpp"

namespace gvio::cli {
namespace {

struct EvalCliOptions {
  std::string ref, est, ref_format = "auto", est_format = "auto";
  std::optional<std::string> ref_times, est_times, json, plot, est_aligned, outages;
  std::string align = "none", relation = "trans", rpe_unit = "frames", plot_plane = "auto";
  std::optional<double> rpe_delta;
  double t_max_diff_s = 0.01, t_offset_s = 0.0;
};

Trajectory load(const std::string& file, const std::string& format,
                const std::optional<std::string>& times) {
  const io::TrajectoryFormat f =
      format == "auto" ? io::detectTrajectoryFormat(file) : *io::parseTrajectoryFormat(format);
  std::optional<std::filesystem::path> times_path;
  if (times) times_path = *times;
  return io::readTrajectory(file, f, times_path);
}

std::string alignmentName(eval::Alignment a) {
  switch (a) {
    case eval::Alignment::kNone:
      return "none";
    case eval::Alignment::kSe3:
      return "SE(3) Umeyama";
    case eval::Alignment::kSim3:
      return "Sim(3) Umeyama";
    case eval::Alignment::kOrigin:
      return "origin (first poses)";
  }
  return "";
}

nlohmann::json statsJson(const eval::Stats& s) {
  return {{"rmse", s.rmse}, {"mean", s.mean}, {"median", s.median}, {"std", s.std},
          {"min", s.min},   {"max", s.max},   {"sse", s.sse},       {"n", s.n}};
}

std::string statsTable(const std::string& title, const eval::Stats& s) {
  std::string out = title + "\n";
  const std::pair<const char*, double> rows[] = {
      {"max", s.max},   {"mean", s.mean}, {"median", s.median}, {"min", s.min},
      {"rmse", s.rmse}, {"sse", s.sse},   {"std", s.std}};
  for (const auto& [name, value] : rows) out += fmt::format("{:>10}  {:.6f}\n", name, value);
  return out + fmt::format("{:>10}  {}\n", "n", s.n);
}

nlohmann::json resultJson(const eval::EvalResult& r, const EvalCliOptions& o) {
  nlohmann::json j;
  j["ape"] = statsJson(r.ape_stats);
  if (r.rpe) j["rpe"] = statsJson(r.rpe->stats);
  const auto& a = r.alignment;
  j["alignment"] = {{"mode", o.align},
                    {"rotation",
                     {a.R(0, 0), a.R(0, 1), a.R(0, 2), a.R(1, 0), a.R(1, 1), a.R(1, 2), a.R(2, 0),
                      a.R(2, 1), a.R(2, 2)}},
                    {"translation", {a.t.x(), a.t.y(), a.t.z()}},
                    {"scale", a.s}};
  j["relation"] = o.relation;
  j["poses"] = {{"reference", r.ref_poses},
                {"estimate", r.est_poses},
                {"associated", r.ref.size()},
                {"paired_by_index", r.paired_by_index}};
  return j;
}

void writeAligned(const std::string& file, const eval::EvalResult& r) {
  Trajectory out;
  for (std::size_t i = 0; i < r.est.size(); ++i) {
    // Stamps of the reference poses they were associated with; pose index without stamps.
    out.t_ns.push_back(r.t_ns.empty() ? static_cast<std::int64_t>(i) * 1'000'000'000LL : r.t_ns[i]);
    Eigen::Isometry3d T;
    T.matrix() = r.est[i];
    T.linear() = Eigen::Quaterniond(r.est[i].topLeftCorner<3, 3>()).normalized().toRotationMatrix();
    out.poses.push_back(T);
  }
  io::writeTum(file, out);
}

std::array<int, 2> planeAxes(const std::string& plane, const std::vector<Eigen::Vector3d>& ref) {
  if (plane == "xy") return {0, 1};
  if (plane == "xz") return {0, 2};
  if (plane == "yz") return {1, 2};
  return eval::choosePlane(ref);
}

std::vector<std::string> plot(const eval::EvalResult& r, const EvalCliOptions& o) {
  eval::PlotData d;
  d.title =
      fmt::format("APE w.r.t. {}, alignment: {}", eval::describe(eval::parseRelation(o.relation)),
                  alignmentName(eval::parseAlignment(o.align)));
  d.error_label =
      o.relation == "angle_deg" ? "APE (deg)" : (o.relation == "full" ? "APE" : "APE (m)");
  const std::int64_t t0 = r.t_ns.empty() ? 0 : r.t_ns.front();
  if (r.t_ns.empty()) d.time_label = "pose index";
  for (std::size_t i = 0; i < r.ref.size(); ++i) {
    d.t_s.push_back(r.t_ns.empty() ? static_cast<double>(i)
                                   : 1e-9 * static_cast<double>(r.t_ns[i] - t0));
    d.p_ref.emplace_back(r.ref[i].topRightCorner<3, 1>());
    d.p_est.emplace_back(r.est[i].topRightCorner<3, 1>());
  }
  d.error = r.ape;
  d.stats = r.ape_stats;
  if (o.outages) {
    for (const auto& [a, b] : io::readIntervals(*o.outages)) {
      d.outages_s.emplace_back(1e-9 * static_cast<double>(a - t0),
                               1e-9 * static_cast<double>(b - t0));
    }
  }
  d.plane = planeAxes(o.plot_plane, d.p_ref);
  std::string prefix = *o.plot;
  for (const char* ext : {".png", ".svg"}) {
    if (prefix.ends_with(ext)) prefix.resize(prefix.size() - 4);
  }
  return eval::writePlots(d, prefix);
}

std::int64_t secondsToNsOption(double s) {
  return static_cast<std::int64_t>(std::llround(s * 1e9));
}

int runEval(const EvalCliOptions& o) {
  eval::EvalOptions opt;
  opt.align = eval::parseAlignment(o.align);
  opt.relation = eval::parseRelation(o.relation);
  opt.t_max_diff_ns = secondsToNsOption(o.t_max_diff_s);
  opt.t_offset_ns = secondsToNsOption(o.t_offset_s);
  opt.rpe_delta = o.rpe_delta;
  opt.rpe_unit = eval::parseDeltaUnit(o.rpe_unit);
  if (o.plot_plane != "auto" && o.plot_plane != "xy" && o.plot_plane != "xz" &&
      o.plot_plane != "yz") {
    throw gvio::InvalidInput("--plot-plane: expected auto, xy, xz or yz");
  }
  const Trajectory ref = load(o.ref, o.ref_format, o.ref_times);
  const Trajectory est = load(o.est, o.est_format, o.est_times);
  const eval::EvalResult r = eval::evaluate(ref, est, opt);

  std::string report = fmt::format("{} of {} reference / {} estimate poses {}\nalignment: {}",
                                   r.ref.size(), r.ref_poses, r.est_poses,
                                   r.paired_by_index ? "paired by index" : "associated by time",
                                   alignmentName(opt.align));
  if (opt.align == eval::Alignment::kSim3) report += fmt::format(" (scale {:.6f})", r.alignment.s);
  report += "\n\n" + statsTable("APE w.r.t. " + eval::describe(opt.relation), r.ape_stats);
  if (r.rpe) {
    report += "\n" + statsTable(fmt::format("RPE w.r.t. {} for delta = {} ({}), consecutive pairs",
                                            eval::describe(opt.relation), *o.rpe_delta, o.rpe_unit),
                                r.rpe->stats);
  }
  std::cout << report;
  if (o.json) io::writeTextAtomic(*o.json, resultJson(r, o).dump(2) + "\n");
  if (o.est_aligned) writeAligned(*o.est_aligned, r);
  if (o.plot) {
    for (const auto& file : plot(r, o)) spdlog::info("wrote {}", file);
  }
  return 0;
}

}  // namespace

Command addEvalCommand(CLI::App& app) {
  auto o = std::make_shared<EvalCliOptions>();
  CLI::App* sub = app.add_subcommand(
      "eval", "APE / RPE of an estimate against a reference, as evo computes them");
  const auto formats = CLI::IsMember({"auto", "tum", "kitti", "euroc"});
  sub->add_option("--ref", o->ref, "Reference trajectory file")->required();
  sub->add_option("--est", o->est, "Estimated trajectory file")->required();
  sub->add_option("--ref-format", o->ref_format, "auto guesses from the first line")
      ->check(formats);
  sub->add_option("--est-format", o->est_format, "auto guesses from the first line")
      ->check(formats);
  sub->add_option("--ref-times", o->ref_times,
                  "Times file for a KITTI reference (seconds per line)");
  sub->add_option("--est-times", o->est_times, "Times file for a KITTI estimate");
  sub->add_option("--align", o->align, "Umeyama alignment of est onto ref, or first-pose alignment")
      ->check(CLI::IsMember({"none", "se3", "sim3", "origin"}));
  sub->add_option("--relation", o->relation, "Pose relation of the error")
      ->check(CLI::IsMember({"trans", "full", "angle_deg"}));
  sub->add_option("--rpe-delta", o->rpe_delta, "Also compute RPE for this delta");
  sub->add_option("--rpe-unit", o->rpe_unit, "Unit of --rpe-delta")
      ->check(CLI::IsMember({"frames", "m"}));
  sub->add_option("--t-max-diff", o->t_max_diff_s, "Max. stamp difference for association (s)")
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--t-offset", o->t_offset_s, "Added to the estimate's stamps (s)");
  sub->add_option("--json", o->json,
                  "Write {\"ape\": {...}, \"rpe\": {...}} statistics to this file");
  sub->add_option("--est-aligned", o->est_aligned, "Write the aligned, associated estimate (TUM)");
  sub->add_option("--plot", o->plot, "Write PREFIX_{trajectory,error,axes}.{png,svg}");
  sub->add_option("--plot-plane", o->plot_plane, "Top-down plane of the trajectory plot")
      ->check(CLI::IsMember({"auto", "xy", "xz", "yz"}));
  sub->add_option("--outages", o->outages,
                  "Intervals 't0 t1' (s, trajectory time base) shaded in plots");
  return {sub, [o] { return runEval(*o); }};
}

}  // namespace gvio::cli
