// gvio eval: APE / RPE of an estimate against a reference, with evo's definitions and numbers,
// a readable table, JSON, the aligned estimate and plots.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <charconv>
#include <cmath>
#include <iostream>
#include <limits>
#include <nlohmann/json.hpp>

#include "cli/app.hpp"
#include "eval/eval_inputs.hpp"
#include "eval/evaluate.hpp"
#include "eval/plots.hpp"
#include "eval/position_report.hpp"
#include "eval/revisits.hpp"
#include "eval/revisits_plot.hpp"
#include "eval/stats_text.hpp"
#include "io/atomic_write.hpp"
#include "io/intervals.hpp"
#include "io/trajectory_io.hpp"
#include "odometry/error.hpp"

namespace gvio::cli {
namespace {

struct EvalCliOptions {
  std::string ref, est, ref_format = "auto", est_format = "auto";
  std::optional<std::string> ref_times, est_times, json, plot, est_aligned, outages, origin,
      errors_csv;
  // Taken as text and parsed here, so a bad value is a one-line InvalidInput like other input.
  std::optional<std::string> revisits_radius, revisits_min_separation;
  std::string align = "none", relation = "trans", rpe_unit = "frames", plot_plane = "auto";
  std::optional<double> rpe_delta;
  double t_max_diff_s = 0.01, t_offset_s = 0.0;
  ConfigOptions config;  // its dataset.* keys read GNSS files as gvio run reads them
};

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

// Divided, not multiplied by 1e-9, so that whole seconds print whole (30, not 30.000000000000004).
double separationS(std::int64_t t_ns) {
  return static_cast<double>(t_ns) / 1e9;
}

// "reference poses within 5 m and at least 30 s apart"
std::string revisitsScope(const eval::RevisitOptions& o) {
  return fmt::format("reference poses within {} m and at least {} s apart", o.radius_m,
                     separationS(o.min_separation_ns));
}

std::string revisitsTable(const eval::RevisitResult& v) {
  if (!v.stats) return fmt::format("revisits: no pair of {}\n", revisitsScope(v.options));
  return eval::statsTable(
      fmt::format("revisit consistency |(p_est_j - p_est_i) - (p_ref_j - p_ref_i)| "
                  "(m) over pairs of {}",
                  revisitsScope(v.options)),
      v.stats->stats, v.stats->p95, "pairs");
}

// The statistics are null when no pair qualifies, so the keys are always there.
nlohmann::json revisitsJson(const eval::RevisitResult& v) {
  nlohmann::json j = {{"radius_m", v.options.radius_m},
                      {"min_separation_s", separationS(v.options.min_separation_ns)},
                      {"pairs", v.pairs.size()}};
  if (v.stats) {
    j.update(eval::statsJson(v.stats->stats));
    j["p95"] = v.stats->p95;
  } else {
    for (const char* key : {"rmse", "mean", "median", "std", "min", "max", "sse", "p95"}) {
      j[key] = nullptr;
    }
    j["n"] = 0;
  }
  return j;
}

nlohmann::json resultJson(const eval::EvalResult& r,
                          const std::optional<eval::RevisitResult>& revisits,
                          const EvalCliOptions& o) {
  nlohmann::json j;
  j["ape"] = eval::statsJson(r.ape_stats);
  if (r.rpe) j["rpe"] = eval::statsJson(r.rpe->stats);
  if (revisits) j["revisits"] = revisitsJson(*revisits);
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

std::string plotPrefix(const EvalCliOptions& o) {
  std::string prefix = *o.plot;
  for (const char* ext : {".png", ".svg"}) {
    if (prefix.ends_with(ext)) prefix.resize(prefix.size() - 4);
  }
  return prefix;
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
  return eval::writePlots(d, plotPrefix(o));
}

std::vector<std::string> plotRevisits(const eval::EvalResult& r, const eval::RevisitResult& v,
                                      const EvalCliOptions& o) {
  eval::RevisitPlotData d;
  d.title = fmt::format("Revisit consistency (pairs within {} m, >= {} s apart), alignment: {}",
                        v.options.radius_m, separationS(v.options.min_separation_ns),
                        alignmentName(eval::parseAlignment(o.align)));
  for (std::size_t i = 0; i < r.ref.size(); ++i) {
    d.p_ref.emplace_back(r.ref[i].topRightCorner<3, 1>());
    d.p_est.emplace_back(r.est[i].topRightCorner<3, 1>());
  }
  d.plane = planeAxes(o.plot_plane, d.p_ref);
  return eval::writeRevisitsPlot(d, v, plotPrefix(o));
}

std::int64_t secondsToNsOption(double s) {
  return static_cast<std::int64_t>(std::llround(s * 1e9));
}

// The whole text must be a finite number accepted by `ok`, else a one-line error naming the option.
double parseNumberOption(const char* option, const std::string& text, bool (*ok)(double),
                         const char* expected) {
  double value = 0.0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (ec != std::errc() || ptr != end || !std::isfinite(value) || !ok(value)) {
    throw gvio::InvalidInput(fmt::format("{} '{}': expected {}", option, text, expected));
  }
  return value;
}

// Revisit options from --revisits R and --revisits-min-separation S; none without --revisits.
std::optional<eval::RevisitOptions> revisitOptions(const EvalCliOptions& o) {
  if (!o.revisits_radius) {
    if (o.revisits_min_separation) {
      throw gvio::InvalidInput("--revisits-min-separation: only used with --revisits R");
    }
    return std::nullopt;
  }
  eval::RevisitOptions v;
  v.radius_m = parseNumberOption(
      "--revisits", *o.revisits_radius, [](double r) { return r > 0.0; },
      "a finite radius > 0 (metres)");
  if (o.revisits_min_separation) {
    const double s = parseNumberOption(
        "--revisits-min-separation", *o.revisits_min_separation, [](double x) { return x >= 0.0; },
        "a finite number of seconds >= 0");
    // Saturates: a separation beyond int64 nanoseconds (292 years) simply admits no pair.
    v.min_separation_ns =
        s * 1e9 >= 9.2e18 ? std::numeric_limits<std::int64_t>::max() : secondsToNsOption(s);
  }
  return v;
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
  const std::optional<eval::RevisitOptions> revisit_options = revisitOptions(o);
  const AppConfig config = o.config.load();
  const eval::EvalInputs in =
      eval::loadEvalInputs({o.ref, o.ref_format, o.ref_times}, {o.est, o.est_format, o.est_times},
                           o.origin, config.dataset);
  if (in.enu_origin && opt.relation != eval::Relation::kTranslation) {
    throw gvio::InvalidInput("--relation " + o.relation +
                             ": a GNSS track has positions only; use --relation trans");
  }
  const eval::EvalResult r = eval::evaluate(in.ref.trajectory, in.est.trajectory, opt);
  std::optional<eval::RevisitResult> revisits;
  if (revisit_options) revisits = eval::computeRevisits(r.ref, r.est, r.t_ns, *revisit_options);

  std::string report = fmt::format("{} of {} reference / {} estimate poses {}\nalignment: {}",
                                   r.ref.size(), r.ref_poses, r.est_poses,
                                   r.paired_by_index ? "paired by index" : "associated by time",
                                   alignmentName(opt.align));
  if (opt.align == eval::Alignment::kSim3) report += fmt::format(" (scale {:.6f})", r.alignment.s);
  report += "\n\n" + eval::statsTable("APE w.r.t. " + eval::describe(opt.relation), r.ape_stats);
  if (r.rpe) {
    report +=
        "\n" + eval::statsTable(fmt::format("RPE w.r.t. {} for delta = {} ({}), consecutive pairs",
                                            eval::describe(opt.relation), *o.rpe_delta, o.rpe_unit),
                                r.rpe->stats);
  }
  if (revisits) report += "\n" + revisitsTable(*revisits);
  nlohmann::json json = resultJson(r, revisits, o);
  if (in.enu_origin) report += "\n" + eval::positionReport(r, in, json);
  std::cout << report;
  if (o.json) io::writeTextAtomic(*o.json, json.dump(2) + "\n");
  if (o.est_aligned) writeAligned(*o.est_aligned, r);
  if (o.errors_csv) {
    eval::writeErrorsCsv(*o.errors_csv, r, in.est.geo ? in.est.geo->quality : std::vector<int>{});
  }
  if (o.plot) {
    for (const auto& file : plot(r, o)) spdlog::info("wrote {}", file);
    if (revisits) {
      for (const auto& file : plotRevisits(r, *revisits, o)) spdlog::info("wrote {}", file);
    }
  }
  return 0;
}

}  // namespace

Command addEvalCommand(CLI::App& app) {
  auto o = std::make_shared<EvalCliOptions>();
  CLI::App* sub = app.add_subcommand(
      "eval", "APE / RPE of an estimate against a reference, as evo computes them");
  const auto formats = CLI::IsMember({"auto", "tum", "kitti", "euroc", "gnss"});
  sub->add_option("--ref", o->ref,
                  "Reference: a trajectory (TUM, KITTI, EuRoC) or a GNSS track (RTKLIB .pos, "
                  "NMEA, GNSS CSV, a GNSS/INS reference CSV)")
      ->required();
  sub->add_option("--est", o->est, "Estimate: the same kinds of file")->required();
  sub->add_option("--ref-format", o->ref_format,
                  "auto guesses from the first line; gnss: a GNSS track")
      ->check(formats);
  sub->add_option("--est-format", o->est_format,
                  "auto guesses from the first line; gnss: a GNSS track")
      ->check(formats);
  sub->add_option("--origin", o->origin,
                  "lat,lon,h: the ENU origin of the local trajectory compared with a GNSS track "
                  "(a run's georef.json enu_origin); with two GNSS tracks, the frame's origin "
                  "(default: the reference's first position)");
  o->config.addTo(*sub, "YAML configuration: its dataset.* keys read GNSS files as gvio run does",
                  "Override one config key: --set dataset.nmea_checksum=warn (repeatable)");
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
  sub->add_option("--errors-csv", o->errors_csv,
                  "Write each associated pose's time, APE and position error est - ref (x, y, z; "
                  "east, north, up with a GNSS track) as CSV");
  sub->add_option("--plot", o->plot,
                  "Write PREFIX_{trajectory,error,axes}.{png,svg} (and PREFIX_revisits.{png,svg} "
                  "with --revisits)");
  sub->add_option("--plot-plane", o->plot_plane, "Top-down plane of the trajectory plot")
      ->check(CLI::IsMember({"auto", "xy", "xz", "yz"}));
  sub->add_option("--revisits", o->revisits_radius,
                  "Revisit consistency: error of the estimated relative position of every pair "
                  "of reference poses within R m of each other (R > 0)");
  sub->add_option("--revisits-min-separation", o->revisits_min_separation,
                  "Least time between the two poses of a revisit pair (s, default 30)");
  sub->add_option("--outages", o->outages,
                  "Intervals 't0 t1' (s, trajectory time base) shaded in plots");
  return {sub, [o] { return runEval(*o); }};
}

}  // namespace gvio::cli
