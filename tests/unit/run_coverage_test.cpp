// A run that covers only part of its input says so (issue 58): the Husky bag's GNSS/INS
// initialised after 390 of 395 s and reported "complete".
#include <gtest/gtest.h>

#include "run/coverage.hpp"

namespace gvio::run {
namespace {

constexpr std::int64_t kS = 1'000'000'000;

std::vector<std::int64_t> span(std::int64_t from_s, std::int64_t to_s) {
  std::vector<std::int64_t> t;
  for (std::int64_t s = from_s; s <= to_s; ++s) t.push_back(s * kS);
  return t;
}

TEST(RunCoverage, PartialBelowHalfTheInputsSpanAndMoreThanFiveSecondsMissing) {
  const Coverage late = coverageOf(span(0, 395), span(390, 395));
  EXPECT_DOUBLE_EQ(late.input_s, 395.0);
  EXPECT_DOUBLE_EQ(late.output_s, 5.0);
  EXPECT_TRUE(late.partial());
  EXPECT_EQ(runStatus(late), "partial");
  EXPECT_EQ(partialNote(late),
            ", partial: the trajectory covers 5.0 s of the input's 395.0 s (1.3 %)");
  EXPECT_DOUBLE_EQ(coverageJson(late)["fraction"].get<double>(), 5.0 / 395.0);

  const Coverage usual = coverageOf(span(0, 100), span(2, 100));  // a VIO's initialisation
  EXPECT_FALSE(usual.partial());
  EXPECT_FALSE(coverageOf(span(0, 8), span(4, 8)).partial());      // short: 4 s missing
  EXPECT_TRUE(coverageOf(span(0, 100), span(51, 100)).partial());  // half missing
  EXPECT_FALSE(coverageOf(span(0, 100), span(49, 100)).partial());
  EXPECT_EQ(runStatus(usual), "complete");
  EXPECT_EQ(partialNote(usual), "");

  EXPECT_TRUE(coverageOf(span(0, 100), {}).partial());  // nothing written
  EXPECT_FALSE(coverageOf({}, {}).partial());           // nothing to cover
}

}  // namespace
}  // namespace gvio::run
