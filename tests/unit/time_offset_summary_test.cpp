// What gvio run says of the camera-IMU time offset (app/run/time_offset_summary.hpp): an estimate
// with the spread of its late free solves, "not observed" when the drive held it in most solves
// or solved it freely only a few times, "not estimated" when switched off.
#include <gtest/gtest.h>

#include <vector>

#include "run/time_offset_summary.hpp"

namespace gvio::run {
namespace {

TEST(TimeOffsetSummary, EstimatedByTheMedianAndSpreadOfItsLateFreeSolves) {
  // 100 free solves: a wandering first half, then 20 ms +- 0.5 ms (alternating), the last one
  // wandered off to 17 ms.
  std::vector<double> free;
  for (int i = 0; i < 50; ++i) free.push_back(-0.01 + 0.0006 * i);
  for (int i = 0; i < 49; ++i) free.push_back(i % 2 == 0 ? 0.0205 : 0.0195);
  free.push_back(0.017);
  const TimeOffsetSummary s = summarizeTimeOffset(true, 0.017, free, 20);
  EXPECT_EQ(s.status, "estimated");
  EXPECT_NEAR(s.t_d_s, 0.020, 1e-12);  // neither the first half nor the last value
  EXPECT_EQ(s.final_t_d_s, 0.017);
  EXPECT_NEAR(s.sigma_s, 1.4826 * 0.0005, 1e-9);  // the first half's wander is left out
  EXPECT_NEAR(s.observed_fraction, 100.0 / 120.0, 1e-12);
  EXPECT_EQ(timeOffsetText(s), "camera-IMU time offset 20.0 +- 0.7 ms");
  const nlohmann::json j = timeOffsetSummaryJson(s);
  EXPECT_EQ(j["status"], "estimated");
  EXPECT_NEAR(j["t_d_s"].get<double>(), 0.020, 1e-12);
  EXPECT_EQ(j["t_d_final_s"].get<double>(), 0.017);
}

TEST(TimeOffsetSummary, HeldInMostSolvesIsNotObserved) {
  const std::vector<double> free(40, 0.004);
  const TimeOffsetSummary s = summarizeTimeOffset(true, 0.004, free, 400);
  EXPECT_EQ(s.status, "not observed");
  EXPECT_EQ(s.t_d_s, 0.004);  // the value the estimator held
  EXPECT_EQ(timeOffsetText(s), "camera-IMU time offset not observed (held in 91 % of 440 solves)");
  EXPECT_TRUE(timeOffsetSummaryJson(s)["sigma_s"].is_null());
  // Free in every solve, but only a few of them: not observed either.
  EXPECT_EQ(
      summarizeTimeOffset(true, 0.0, std::vector<double>(kTimeOffsetMinFreeSolves - 1, 0.0), 0)
          .status,
      "not observed");
}

TEST(TimeOffsetSummary, SwitchedOffIsNotEstimated) {
  const TimeOffsetSummary s = summarizeTimeOffset(false, 0.0, {}, 0);
  EXPECT_EQ(s.status, "not estimated");
  EXPECT_EQ(timeOffsetText(s), "");
}

}  // namespace
}  // namespace gvio::run
