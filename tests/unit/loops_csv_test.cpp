// loops.csv (io::writeLoopsCsv / readLoopsCsv): exact stamps, "nan" for what was not measured,
// and a strict reader whose every complaint is one line naming the file and line.
#include "io/loops_csv.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "io/input_error.hpp"
#include "support/fixtures.hpp"

namespace gvio::test {
namespace {
using io::LoopCsvRow;
using testing::HasSubstr;
namespace fs = std::filesystem;

LoopCsvRow row(std::int64_t query, std::int64_t candidate, bool accepted, std::string reason) {
  LoopCsvRow r;
  r.query_t_ns = query;
  r.candidate_t_ns = candidate;
  r.accepted = accepted;
  r.reason = std::move(reason);
  return r;
}

std::vector<LoopCsvRow> sampleRows() {
  LoopCsvRow verified = row(1317384506123456789LL, 1317384406000000001LL, true, "ok");
  verified.distance_m = 3.25;
  verified.search_radius_m = 15.0;
  verified.matches = 412;
  verified.inliers = 187;
  verified.reprojection_px = 0.734512;
  verified.correction_m = 2.125;
  verified.correction_deg = 1.5;
  LoopCsvRow few_matches = row(1317384507999999999LL, 1317384400000000000LL, false, "few_matches");
  few_matches.distance_m = 9.5;
  few_matches.search_radius_m = 15.0;
  few_matches.matches = 12;  // PnP not run: inliers 0, the rest NaN
  LoopCsvRow outlier = row(5, 1, false, "graph_outlier");
  outlier.distance_m = 0.000001;
  outlier.search_radius_m = 7.75;
  outlier.matches = 90;
  outlier.inliers = 41;
  outlier.reprojection_px = 1.0;
  outlier.correction_m = 40.0;
  outlier.correction_deg = 170.0;
  return {verified, few_matches, outlier};
}

// NaN compares unequal to itself: both NaN, or within the file's 6 decimals.
void expectSameQuantity(double got, double want, const char* what) {
  if (std::isnan(want)) {
    EXPECT_TRUE(std::isnan(got)) << what << " " << got;
  } else {
    EXPECT_NEAR(got, want, 5e-7) << what;
  }
}

class LoopsCsv : public ::testing::Test {
 protected:
  // The one-line message readLoopsCsv throws for `text`.
  std::string failure(const std::string& text) {
    writeText(file_, text);
    try {
      io::readLoopsCsv(file_);
    } catch (const io::InputError& e) {
      return e.what();
    }
    return "(no error)";
  }
  TempDir dir_{"loopscsv"};
  fs::path file_ = dir_.path() / "loops.csv";
};

TEST_F(LoopsCsv, RoundTripsEveryFieldAndStampsExactly) {
  const auto rows = sampleRows();
  io::writeLoopsCsv(file_, rows);
  const auto back = io::readLoopsCsv(file_);
  ASSERT_EQ(back.size(), rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const LoopCsvRow &a = rows[i], &b = back[i];
    EXPECT_EQ(b.query_t_ns, a.query_t_ns) << i;
    EXPECT_EQ(b.candidate_t_ns, a.candidate_t_ns) << i;
    expectSameQuantity(b.distance_m, a.distance_m, "distance_m");
    expectSameQuantity(b.search_radius_m, a.search_radius_m, "search_radius_m");
    EXPECT_EQ(b.matches, a.matches) << i;
    EXPECT_EQ(b.inliers, a.inliers) << i;
    expectSameQuantity(b.reprojection_px, a.reprojection_px, "reprojection_px");
    expectSameQuantity(b.correction_m, a.correction_m, "correction_m");
    expectSameQuantity(b.correction_deg, a.correction_deg, "correction_deg");
    EXPECT_EQ(b.accepted, a.accepted) << i;
    EXPECT_EQ(b.reason, a.reason) << i;
  }
  // The text itself: header, 9-decimal stamps (no detour through double, which would round the
  // 19-digit stamp), "nan" as pandas and Python read it.
  const std::string text = readText(file_);
  EXPECT_EQ(text.substr(0, text.find('\n')), io::kLoopsCsvHeader);
  EXPECT_THAT(text, HasSubstr("\n1317384506.123456789,1317384406.000000001,3.250000,15.000000,412,"
                              "187,0.734512,2.125000,1.500000,accepted,ok\n"));
  EXPECT_THAT(text, HasSubstr("\n1317384507.999999999,1317384400.000000000,9.500000,15.000000,12,"
                              "0,nan,nan,nan,rejected,few_matches\n"));
  EXPECT_THAT(text, HasSubstr("\n0.000000005,0.000000001,"));
}

TEST_F(LoopsCsv, HeaderOnlyFileHoldsNoRowsAndOtherSpellingsOfNanAreRead) {
  io::writeLoopsCsv(file_, {});
  EXPECT_EQ(readText(file_), std::string(io::kLoopsCsvHeader) + "\n");
  EXPECT_TRUE(io::readLoopsCsv(file_).empty());
  writeText(file_, std::string(io::kLoopsCsvHeader) +
                       "\r\n2.5,1.0,NaN,-nan,0,0,nan,nan,nan,rejected,few_matches\r\n\n");
  const auto rows = io::readLoopsCsv(file_);
  ASSERT_EQ(rows.size(), 1U);
  EXPECT_EQ(rows[0].query_t_ns, 2'500'000'000LL);
  EXPECT_TRUE(std::isnan(rows[0].distance_m));
  EXPECT_TRUE(std::isnan(rows[0].search_radius_m));
}

TEST_F(LoopsCsv, MalformedFilesNameFileAndLineInOneLine) {
  const std::string h = std::string(io::kLoopsCsvHeader) + "\n";
  const std::string good = "2.0,1.0,3.0,15.0,100,50,0.8,0.5,1.0,accepted,ok\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"", "loops.csv: empty file, expected the header query_t_s,"},
      {"query_t_s,candidate_t_s\n", "loops.csv:1: header 'query_t_s,candidate_t_s': expected"},
      {h + good + "2.0,1.0,3.0,15.0,100,50,0.8,0.5,accepted,ok\n",
       "loops.csv:3: expected 11 fields, got 10"},
      {h + "2.0,1.0,3.0,15.0,100,50,0.8,0.5,1.0,accepted,ok,extra\n",
       "loops.csv:2: expected 11 fields, got 12"},
      {h + "two,1.0,3.0,15.0,100,50,0.8,0.5,1.0,accepted,ok\n", "loops.csv:2: malformed query_t_s"},
      {h + "2.0,1.0,3.0,15.0,100,50,0.8,abc,1.0,accepted,ok\n",
       "loops.csv:2: malformed correction_m 'abc'"},
      {h + "2.0,1.0,inf,15.0,100,50,0.8,0.5,1.0,accepted,ok\n",
       "loops.csv:2: non-finite distance_m"},
      {h + "2.0,1.0,3.0,15.0,,50,0.8,0.5,1.0,accepted,ok\n", "loops.csv:2: malformed matches ''"},
      {h + "2.0,1.0,3.0,15.0,100,-1,0.8,0.5,1.0,accepted,ok\n",
       "loops.csv:2: negative inliers '-1'"},
      {h + "2.0,1.0,3.0,15.0,1.5,50,0.8,0.5,1.0,accepted,ok\n", "loops.csv:2: malformed matches"},
      {h + "2.0,1.0,3.0,15.0,100,50,0.8,0.5,1.0,maybe,ok\n",
       "loops.csv:2: verdict 'maybe': expected accepted or rejected"},
      {h + "2.0,1.0,3.0,15.0,100,50,0.8,0.5,1.0,rejected,\n", "loops.csv:2: reason ''"},
      {h + "2.0,1.0,3.0,15.0,100,50,0.8,0.5,1.0,rejected,Few-Inliers\n",
       "loops.csv:2: reason 'Few-Inliers': expected a token of a-z and _"},
      {h + "2.0,1.0,3.0,15.0,100,50,0.8,0.5,1.0,accepted,few_inliers\n",
       "loops.csv:2: accepted loop with reason 'few_inliers'"},
      {h + "2.0,1.0,3.0,15.0,100,50,0.8,0.5,1.0,rejected,ok\n",
       "loops.csv:2: rejected loop with reason 'ok'"},
  };
  for (const auto& [text, needle] : cases) {
    const std::string msg = failure(text);
    EXPECT_THAT(msg, HasSubstr(needle)) << text;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
  EXPECT_EQ(failure(h + good), "(no error)");
}

TEST_F(LoopsCsv, WriterRefusesRowsTheReaderWouldReject) {
  for (const LoopCsvRow& bad : {row(2, 1, true, "few_inliers"), row(2, 1, false, "ok"),
                                row(2, 1, false, ""), row(2, 1, false, "two words")}) {
    EXPECT_THROW(io::writeLoopsCsv(file_, {bad}), std::invalid_argument) << bad.reason;
  }
  LoopCsvRow negative = row(2, 1, false, "few_matches");
  negative.matches = -3;
  EXPECT_THROW(io::writeLoopsCsv(file_, {negative}), std::invalid_argument);
  EXPECT_FALSE(fs::exists(file_));  // nothing written
  LoopCsvRow infinite = row(2, 1, false, "implausible");
  infinite.correction_m = std::numeric_limits<double>::infinity();
  io::writeLoopsCsv(file_, {infinite});
  EXPECT_TRUE(std::isnan(io::readLoopsCsv(file_).at(0).correction_m));  // "not measured"
}

}  // namespace
}  // namespace gvio::test
