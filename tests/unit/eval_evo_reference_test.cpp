// gvio eval must reproduce evo 1.36.5 on the same files (figures in ../shared/data/README.md):
// KITTI_00_ORB.txt (ORB-SLAM2 stereo) against KITTI_00_gt.txt, paired by index.
#include <gtest/gtest.h>

#include "eval/evaluate.hpp"
#include "io/trajectory_io.hpp"
#include "support/fixtures.hpp"

namespace gvio::eval {
namespace {

// A published evo figure. Most are printed with 6 decimals (`decimals` = 6): they can only be
// matched to half a unit of their last digit; full-precision ones (decimals = 16) to 1e-6 relative.
struct Expected {
  double rmse, mean, median, std, min, max;
  double sse = -1.0;  // not every reference figure lists it
  int decimals = 6;
};

void expectClose(double actual, double expected, int decimals, const char* what) {
  const double tol = std::max(1e-6 * std::abs(expected), 0.5 * std::pow(10.0, -decimals));
  EXPECT_NEAR(actual, expected, tol) << what;
}

void expectStats(const Stats& s, const Expected& e) {
  expectClose(s.rmse, e.rmse, e.decimals, "rmse");
  expectClose(s.mean, e.mean, e.decimals, "mean");
  expectClose(s.median, e.median, e.decimals, "median");
  expectClose(s.std, e.std, e.decimals, "std");
  if (e.min >= 0.0) {
    expectClose(s.min, e.min, e.decimals, "min");
  }
  expectClose(s.max, e.max, e.decimals, "max");
  if (e.sse >= 0.0) {
    expectClose(s.sse, e.sse, e.decimals, "sse");
  }
}

class EvoKitti00 : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto gt = test::sharedData("kitti00/KITTI_00_gt.txt");
    const auto orb = test::sharedData("evo_kitti00/KITTI_00_ORB.txt");
    if (gt.empty() || orb.empty())
      GTEST_SKIP() << "shared data absent: ../shared/data/kitti00, evo_kitti00";
    ref_ = io::readKitti(gt);
    est_ = io::readKitti(orb);
  }
  EvalResult run(Alignment align, Relation relation,
                 std::optional<double> rpe_delta_m = std::nullopt) {
    EvalOptions opt;
    opt.align = align;
    opt.relation = relation;
    opt.rpe_delta = rpe_delta_m;
    opt.rpe_unit = DeltaUnit::kMeters;
    return evaluate(ref_, est_, opt);
  }
  Trajectory ref_, est_;
};

TEST_F(EvoKitti00, ApeTranslationUnaligned) {
  const auto r = run(Alignment::kNone, Relation::kTranslation);
  EXPECT_TRUE(r.paired_by_index);
  EXPECT_EQ(r.ape_stats.n, 4541u);
  expectStats(r.ape_stats, {7.790289, 7.01175, 6.801632, 3.394695, 0.0, 13.458509, 275586.936574});
}

TEST_F(EvoKitti00, ApeTranslationSe3) {
  expectStats(run(Alignment::kSe3, Relation::kTranslation).ape_stats,
              {1.3034497145650266, 1.1569971285389768, 1.065624769555848, 0.6002822693968323,
               0.06931322021483087, 3.587949120678954, 7715.073440292808, 16});
}

TEST_F(EvoKitti00, ApeTranslationSim3) {
  expectStats(run(Alignment::kSim3, Relation::kTranslation).ape_stats,
              {0.937709, 0.872693, 0.844691, 0.343083, 0.179515, 2.6935});
}

TEST_F(EvoKitti00, ApeAngleDegSe3) {
  expectStats(run(Alignment::kSe3, Relation::kAngleDeg).ape_stats,
              {0.756301, 0.616516, 0.527891, 0.438062, -1.0, 6.752584});
}

TEST_F(EvoKitti00, RpeTranslation10mUnaligned) {
  const auto r = run(Alignment::kNone, Relation::kTranslation, 10.0);
  ASSERT_TRUE(r.rpe);
  expectStats(r.rpe->stats, {0.226261, 0.169017, 0.138484, 0.150424, -1.0, 1.272209});
}

}  // namespace
}  // namespace gvio::eval
