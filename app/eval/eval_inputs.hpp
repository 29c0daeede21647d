#pragma once
// The two trajectories `gvio eval` compares, read as evo reads them (TUM, KITTI, EuRoC) or as
// geodetic position tracks (GNSS solutions, a GNSS/INS reference CSV: io/geo_track.hpp). Where a
// side is geodetic both are compared in one local ENU frame: a local side's own (its origin given
// as lat,lon,h: a run's georef.json enu_origin, a simulation's sim.origin_*), or, with two
// geodetic sides and no origin given, the reference's first position.
#include <optional>
#include <string>

#include "fusion/geodesy.hpp"
#include "io/geo_track.hpp"
#include "io/reader_config.hpp"
#include "odometry/trajectory.hpp"

namespace gvio::eval {

struct EvalSideRequest {
  std::string file;
  std::string format = "auto";  // auto | tum | kitti | euroc | gnss
  std::optional<std::string> times;
};

struct EvalSide {
  Trajectory trajectory;            // in the local frame (ENU when geodetic)
  std::optional<io::GeoTrack> geo;  // when the file is a geodetic track
};

struct EvalInputs {
  EvalSide ref, est;
  std::optional<fusion::Lla> enu_origin;  // set when either side is geodetic
};

// `origin`: "lat,lon,h" of the local sides' ENU frame, or none. `reader`: how GNSS files are read
// (dataset.*: NMEA checksums, UERE, ellipses), as gvio run reads them. Throws InvalidInput /
// InputError naming the file for bad input, and InvalidInput when a local side meets a geodetic
// one without an origin.
EvalInputs loadEvalInputs(const EvalSideRequest& ref, const EvalSideRequest& est,
                          const std::optional<std::string>& origin,
                          const io::ReaderConfig& reader = {});

}  // namespace gvio::eval
