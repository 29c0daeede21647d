#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <random>

#include "eval/evaluate.hpp"
#include "io/text.hpp"
#include "odometry/error.hpp"

namespace gvio::eval {
namespace {
using testing::HasSubstr;

// A curvy 3-D trajectory with timestamps every 0.1 s.
Trajectory wiggle(std::size_t n) {
  Trajectory t;
  for (std::size_t i = 0; i < n; ++i) {
    const double s = 0.1 * static_cast<double>(i);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() =
        Eigen::Vector3d(10 * std::cos(0.3 * s), 8 * std::sin(0.2 * s), 0.5 * std::sin(s));
    T.linear() = Eigen::AngleAxisd(0.3 * s, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    t.poses.push_back(T);
    t.t_ns.push_back(1'000'000'000LL + static_cast<std::int64_t>(i) * 100'000'000LL);
  }
  return t;
}

Trajectory transformed(const Trajectory& in, const Eigen::Isometry3d& T, double scale) {
  Trajectory out = in;
  for (auto& P : out.poses) {
    P.translation() *= scale;
    P = T * P;
  }
  return out;
}

const Eigen::Isometry3d kT = [] {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())).toRotationMatrix();
  T.translation() = Eigen::Vector3d(100, -50, 7);
  return T;
}();

TEST(EvalAlign, Se3RecoversKnownTransform) {
  const Trajectory ref = wiggle(300);
  const Trajectory est = transformed(ref, kT.inverse(), 1.0);  // est = T^-1 ref
  EvalOptions opt;
  opt.align = Alignment::kSe3;
  const auto r = evaluate(ref, est, opt);
  EXPECT_NEAR((r.alignment.R - kT.linear()).norm(), 0.0, 1e-9);
  EXPECT_NEAR((r.alignment.t - kT.translation()).norm(), 0.0, 1e-9);
  EXPECT_LT(r.ape_stats.max, 1e-9);
  opt.relation = Relation::kFull;
  EXPECT_LT(evaluate(ref, est, opt).ape_stats.max, 1e-9);
}

TEST(EvalAlign, Sim3RecoversScale) {
  const Trajectory ref = wiggle(300);
  // est = (s T)^-1 ref: ref = s R est + t with s = 2.5
  Trajectory est = ref;
  for (auto& P : est.poses) {
    P = kT.inverse() * P;
    P.translation() /= 2.5;
  }
  EvalOptions opt;
  opt.align = Alignment::kSim3;
  const auto r = evaluate(ref, est, opt);
  EXPECT_NEAR(r.alignment.s, 2.5, 1e-9);
  EXPECT_NEAR((r.alignment.R - kT.linear()).norm(), 0.0, 1e-9);
  EXPECT_LT(r.ape_stats.max, 1e-9);
  opt.align = Alignment::kSe3;  // without scale the error stays
  EXPECT_GT(evaluate(ref, est, opt).ape_stats.rmse, 1.0);
}

TEST(EvalAlign, OriginAlignsFirstPoses) {
  const Trajectory ref = wiggle(50);
  const Trajectory est = transformed(ref, kT, 1.0);
  EvalOptions opt;
  opt.align = Alignment::kOrigin;
  const auto r = evaluate(ref, est, opt);
  EXPECT_LT(r.ape_stats.max, 1e-9);
  EXPECT_NEAR((r.est.front() - r.ref.front()).norm(), 0.0, 1e-12);
}

TEST(EvalAssociate, JitterOffsetAndMissingStamps) {
  const Trajectory ref = wiggle(200);
  Trajectory est;
  std::mt19937 rng(7);
  std::uniform_int_distribution<std::int64_t> jitter(-4'000'000, 4'000'000);  // +-4 ms
  for (std::size_t i = 0; i < ref.size(); ++i) {
    if (i % 7 == 3) continue;  // dropped poses
    est.poses.push_back(ref.poses[i]);
    est.t_ns.push_back(ref.t_ns[i] - 250'000'000 + jitter(rng));  // est clock 0.25 s behind
  }
  EvalOptions opt;
  EXPECT_THROW(evaluate(ref, est, opt), InvalidInput);  // no offset: nothing within 10 ms
  opt.t_offset_ns = 250'000'000;
  const auto r = evaluate(ref, est, opt);
  EXPECT_EQ(r.ref.size(), est.size());
  EXPECT_LT(r.ape_stats.max, 1e-12);  // every pose found its true partner
}

TEST(EvalAssociate, NearestWithinMaxDiff) {
  const std::vector<std::int64_t> ref = {0, 100, 200, 300};
  const std::vector<std::int64_t> est = {49, 151, 1000};
  const auto a = associateByTime(ref, est, 60, 0);
  EXPECT_EQ(a.est, (std::vector<std::size_t>{0, 1}));
  EXPECT_EQ(a.ref, (std::vector<std::size_t>{0, 2}));                  // 49->0, 151->200
  const auto b = associateByTime(ref, {0, 100, 200, 300, 400}, 0, 0);  // longer estimate
  EXPECT_EQ(b.ref, (std::vector<std::size_t>{0, 1, 2, 3}));
}

// A stamp as evo holds it: the double numpy parses from the decimal text.
double evoSeconds(std::int64_t t_ns) {
  return std::strtod(io::formatSeconds(t_ns).c_str(), nullptr);
}

// evo's association, ported literally (sync.associate_trajectories + matching_time_indices):
// the shorter trajectory (the second on equal lengths) against the longer, numpy argmin over
// float64 differences of the seconds.
Association evoAssociate(const std::vector<std::int64_t>& ref, const std::vector<std::int64_t>& est,
                         std::int64_t max_diff) {
  const bool est_longer = est.size() > ref.size();
  const auto& shorter = est_longer ? ref : est;
  const auto& longer = est_longer ? est : ref;
  std::vector<std::size_t> is, il;
  for (std::size_t i = 0; i < shorter.size(); ++i) {
    const double a = evoSeconds(shorter[i]);
    std::size_t best = 0;
    for (std::size_t j = 1; j < longer.size(); ++j) {
      if (std::abs(evoSeconds(longer[j]) - a) < std::abs(evoSeconds(longer[best]) - a)) best = j;
    }
    if (std::abs(evoSeconds(longer[best]) - a) <= static_cast<double>(max_diff) / 1e9) {
      is.push_back(i);
      il.push_back(best);
    }
  }
  Association a;
  a.ref = est_longer ? is : il;
  a.est = est_longer ? il : is;
  return a;
}

// A 10 Hz estimate halfway between a 5 Hz reference's stamps (GPS time in seconds): exact
// nanoseconds tie, and evo's float64 seconds decide, not always for the earlier stamp.
TEST(EvalAssociate, TiesAreDecidedAsEvoDoesInFloat64) {
  std::vector<std::int64_t> ref, est;
  const std::int64_t t0 = 1'689'055'532'000'000'000;
  for (int i = 0; i < 200; ++i) ref.push_back(t0 + i * 200'000'000LL);
  for (int i = 0; i < 199; ++i) est.push_back(t0 + 100'000'000LL + i * 200'000'000LL);
  const Association a = associateByTime(ref, est, 100'000'000, 0);
  const Association b = evoAssociate(ref, est, 100'000'000);
  EXPECT_EQ(a.ref, b.ref);
  EXPECT_EQ(a.est, b.est);
  int later = 0;
  for (std::size_t k = 0; k < a.est.size(); ++k) later += a.ref[k] == a.est[k] + 1 ? 1 : 0;
  EXPECT_GT(later, 0);                               // exact arithmetic: none
  EXPECT_LT(later, static_cast<int>(a.est.size()));  // nor always the later one
}

TEST(EvalAssociate, RepeatedAndUnsortedStampsAsEvoDoes) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> step(0, 3);  // 0: a repeated stamp
  for (int trial = 0; trial < 40; ++trial) {
    std::vector<std::int64_t> ref, est;
    std::int64_t t = 0;
    for (int i = 0; i < 60; ++i) ref.push_back(t += step(rng) * 4'000'000);
    t = 2'000'000;
    for (int i = 0; i < 55 + trial % 10; ++i) est.push_back(t += step(rng) * 5'000'000);
    if (trial % 2 == 1) std::shuffle(est.begin(), est.end(), rng);  // steps back too
    const Association a = associateByTime(ref, est, 3'000'000, 0);
    const Association b = evoAssociate(ref, est, 3'000'000);
    EXPECT_EQ(a.ref, b.ref) << "trial " << trial;
    EXPECT_EQ(a.est, b.est) << "trial " << trial;
    EXPECT_FALSE(a.ref.empty());
  }
}

TEST(EvalStats, PopulationStdAndMedian) {
  const Stats s = computeStats({1, 2, 3, 4});
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.median, 2.5);
  EXPECT_DOUBLE_EQ(s.std, std::sqrt(1.25));
  EXPECT_DOUBLE_EQ(s.sse, 30.0);
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(7.5));
  EXPECT_EQ(computeStats({5, 1, 3}).median, 3.0);
  EXPECT_THROW(computeStats({}), InvalidInput);
}

TEST(EvalRotation, AngleMatchesAxisAngle) {
  for (const double angle : {0.0, 1e-9, 1e-4, 0.3, 2.0, 3.1, M_PI}) {
    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(angle, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
    EXPECT_NEAR(rotationAngleRad(R), angle, 1e-12) << angle;
  }
}

TEST(EvalRpe, PairsByFramesAndPath) {
  std::vector<Eigen::Matrix4d> poses(10, Eigen::Matrix4d::Identity());
  for (int i = 0; i < 10; ++i) poses[i](0, 3) = 1.5 * i;  // 1.5 m steps
  const auto by_frames = rpePairs(poses, 3, DeltaUnit::kFrames);
  EXPECT_EQ(by_frames.size(), 3u);  // ids 0,3,6,9
  EXPECT_EQ(by_frames.back(), (std::pair<std::size_t, std::size_t>{6, 9}));
  // evo: path accumulates from pose 0; an id is taken where the path reaches 4 m: 3 (4.5), 6, 9
  const auto by_path = rpePairs(poses, 4.0, DeltaUnit::kMeters);
  ASSERT_EQ(by_path.size(), 2u);
  EXPECT_EQ(by_path.front(), (std::pair<std::size_t, std::size_t>{3, 6}));
  EXPECT_THROW(rpePairs(poses, 100.0, DeltaUnit::kMeters), InvalidInput);
  EXPECT_THROW(rpePairs(poses, 2.5, DeltaUnit::kFrames), InvalidInput);
}

TEST(EvalRpe, ConstantDriftGivesConstantError) {
  const Trajectory ref = wiggle(100);
  Trajectory est = ref;  // est drifts 1 cm per pose along world x
  for (std::size_t i = 0; i < est.size(); ++i) est.poses[i].translation().x() += 0.01 * i;
  EvalOptions opt;
  opt.rpe_delta = 1;
  const auto r = evaluate(ref, est, opt);
  ASSERT_TRUE(r.rpe);
  EXPECT_NEAR(r.rpe->stats.min, 0.01, 1e-9);
  EXPECT_NEAR(r.rpe->stats.max, 0.01, 1e-9);
}

TEST(EvalBadInput, Errors) {
  Trajectory a = wiggle(10), b = wiggle(9);
  a.t_ns.clear();
  b.t_ns.clear();
  try {
    evaluate(a, b, {});
    ADD_FAILURE();
  } catch (const InvalidInput& e) {
    EXPECT_THAT(e.what(), HasSubstr("10 poses and estimate 9"));
  }
  EXPECT_THROW(evaluate(wiggle(2), wiggle(2), {}), InvalidInput);  // fewer than 3
  Trajectory line = wiggle(20);                                    // collinear positions
  for (std::size_t i = 0; i < line.size(); ++i)
    line.poses[i].translation() = Eigen::Vector3d(i, 2.0 * i, 0);
  EvalOptions opt;
  opt.align = Alignment::kSe3;
  try {
    evaluate(line, line, opt);
    ADD_FAILURE();
  } catch (const InvalidInput& e) {
    EXPECT_THAT(e.what(), HasSubstr("collinear"));
  }
  EXPECT_THROW(parseAlignment("se2"), InvalidInput);
}

}  // namespace
}  // namespace gvio::eval
