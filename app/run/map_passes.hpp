#pragma once
// gvio run --two-pass: how well two passes over the same place agree in the map (issue 8: "two
// passes over the same place agree within 0.5 m median"). Each pass is a span of keyframes; their
// points (mapping::MapBuilder::keyframePoints: dense stereo where the keyframe has it, else its
// landmarks, placed with the map's final poses, before the global filters) are compared with
// mapping::twoPassAgreement. The points are not in the map files (their global VoxelGrid merges
// the passes), so this runs inside gvio run, where the keyframes are.
#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "mapping/map_builder.hpp"
#include "run/map_run.hpp"

namespace gvio::run {

// The bound on the median, and the radius within which a pass-2 point counts as seeing
// what pass 1 saw (above the bound, so a map that disagrees by more than it can fail).
inline constexpr double kTwoPassTargetMedianM = 0.5;
inline constexpr double kTwoPassOverlapRadiusM = 1.0;

struct TimeSpanS {  // seconds since the dataset's first camera frame
  double t0_s = 0.0, t1_s = 0.0;
};

struct TwoPassSpans {
  TimeSpanS pass1, pass2;
};

// "T0:T1,T2:T3" (seconds since the first frame, T0 < T1, T2 < T3, all >= 0). Throws InvalidInput
// naming the option.
TwoPassSpans parseTwoPass(const std::string& text);

// report.json's map "two_pass": both spans (relative and on the dataset clock), keyframes and
// points per pass, and the agreement (overlap, median, mean, p90) against the target. `pose_of`:
// the poses the map was built with (mapPoses); `t_first_ns`: the dataset's first frame.
nlohmann::json twoPassReport(const MapRecorder& recorder, const mapping::PoseLookup& pose_of,
                             const TwoPassSpans& spans, std::int64_t t_first_ns);

// The map at revisits, found by itself (issue 15: "for the places passed twice, >= 95 % of the
// second pass's dense points within 0.2 m of the first pass's"). A keyframe is a second pass of
// every keyframe at least kRevisitMinSeparationS older whose final position lies within
// kRevisitRadiusM and whose heading agrees within kRevisitMaxHeadingDeg (the cameras saw the same
// scene). Runs of consecutive second-pass keyframes are compared, each against the points of its
// first-pass keyframes (outside the run), with the same overlap rule as --two-pass; the report
// gives the share of overlapping second-pass points within kRevisitWithinM of the first pass.
inline constexpr double kRevisitRadiusM = 5.0;
inline constexpr double kRevisitMinSeparationS = 30.0;
inline constexpr double kRevisitMaxHeadingDeg = 45.0;
inline constexpr double kRevisitWithinM = 0.2;
inline constexpr double kRevisitTargetFraction = 0.95;

// report.json's map "revisits"; `pose_of`: the poses the map is built with.
nlohmann::json revisitReport(const MapRecorder& recorder, const mapping::PoseLookup& pose_of);

}  // namespace gvio::run
