#include "eval/eval_inputs.hpp"

#include <spdlog/spdlog.h>

#include "io/reader_config.hpp"
#include "io/text.hpp"
#include "io/trajectory_io.hpp"
#include "odometry/error.hpp"

namespace gvio::eval {
namespace {

bool isGeodetic(const EvalSideRequest& side) {
  if (side.format == "gnss") return true;
  return side.format == "auto" && !io::geoTrackFormat(side.file).empty();
}

Trajectory loadLocal(const EvalSideRequest& side) {
  const io::TrajectoryFormat f = side.format == "auto" ? io::detectTrajectoryFormat(side.file)
                                                       : *io::parseTrajectoryFormat(side.format);
  std::optional<std::filesystem::path> times_path;
  if (side.times) times_path = *side.times;
  // Stamps as evo takes them: real benchmark files repeat one now and then (TUM RGB-D fr2/desk's
  // ground truth does), and evo associates them regardless (each pose of the shorter trajectory
  // to the nearest stamp of the other, the first of equals). Said once, with a count.
  Trajectory traj = io::readTrajectory(side.file, f, times_path, io::StampOrder::kAsGiven);
  const io::StampOrderSummary order = io::summarizeStampOrder(traj.t_ns);
  if (order.repeated + order.steps_back > 0) {
    spdlog::warn(
        "{}: {} repeated timestamps and {} steps back (the first at pose {}, t = {} s): "
        "associated as evo does, each pose of the shorter trajectory with the nearest stamp of "
        "the other (the first of equal stamps)",
        side.file, order.repeated, order.steps_back, order.first_index + 1,
        io::formatSeconds(traj.t_ns[order.first_index]));
  }
  return traj;
}

io::GeoTrack loadGeodetic(const EvalSideRequest& side, const char* option,
                          const io::ReaderConfig& reader) {
  if (side.times) {
    throw InvalidInput(
        fmt::format("{}: a times file is for KITTI poses, not a GNSS track", option));
  }
  io::GeoTrack track = io::readGeoTrack(side.file, reader);
  for (const std::string& w : track.warnings) spdlog::warn("{}", w);
  return track;
}

}  // namespace

EvalInputs loadEvalInputs(const EvalSideRequest& ref, const EvalSideRequest& est,
                          const std::optional<std::string>& origin,
                          const io::ReaderConfig& reader) {
  EvalInputs in;
  if (isGeodetic(ref)) in.ref.geo = loadGeodetic(ref, "--ref-times", reader);
  if (isGeodetic(est)) in.est.geo = loadGeodetic(est, "--est-times", reader);
  if (!in.ref.geo) in.ref.trajectory = loadLocal(ref);
  if (!in.est.geo) in.est.trajectory = loadLocal(est);
  std::optional<fusion::Lla> given;
  if (origin) {
    given = fusion::parseLla(*origin);
    if (!given)
      throw InvalidInput("--origin '" + *origin + "': expected lat,lon,h (degrees, metres)");
  }
  if (!in.ref.geo && !in.est.geo) {
    if (given) spdlog::warn("--origin: unused, neither trajectory is a GNSS track");
    return in;
  }
  if (!given && (!in.ref.geo || !in.est.geo)) {
    const std::string& local = in.ref.geo ? est.file : ref.file;
    throw InvalidInput(fmt::format(
        "{} is in a local frame and the other side is a GNSS track: give that frame's ENU origin "
        "with --origin lat,lon,h (a run's georef.json enu_origin, a simulation's sim.yaml "
        "origin_*)",
        local));
  }
  in.enu_origin = given ? *given : in.ref.geo->lla.front();
  const fusion::EnuFrame enu(*in.enu_origin);
  if (in.ref.geo) in.ref.trajectory = io::geoTrackPositions(*in.ref.geo, enu);
  if (in.est.geo) in.est.trajectory = io::geoTrackPositions(*in.est.geo, enu);
  return in;
}

}  // namespace gvio::eval
