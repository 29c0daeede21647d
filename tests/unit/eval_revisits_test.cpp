// Revisit consistency (eval/revisits): pair selection against a brute-force search, errors on
// constructed drives, statistics and validation.
#include "eval/revisits.hpp"

#include <gtest/gtest.h>

#include <cstdio>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include "odometry/error.hpp"

namespace gvio::eval {
namespace {

using PairList = std::vector<std::pair<std::size_t, std::size_t>>;
constexpr std::int64_t kSecond = 1'000'000'000LL;

// The definition, written out: every pair i < j, O(n^2).
PairList bruteForcePairs(const std::vector<Eigen::Vector3d>& p, const std::vector<std::int64_t>& t,
                         double radius_m, std::int64_t min_separation_ns) {
  PairList out;
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (std::size_t j = i + 1; j < p.size(); ++j) {
      if (std::abs(t[j] - t[i]) >= min_separation_ns && (p[j] - p[i]).norm() <= radius_m) {
        out.emplace_back(i, j);
      }
    }
  }
  return out;
}

struct Drive {
  std::vector<Eigen::Matrix4d> poses;
  std::vector<std::int64_t> t_ns;
  [[nodiscard]] std::vector<Eigen::Vector3d> positions() const {
    std::vector<Eigen::Vector3d> p;
    for (const auto& T : poses) p.emplace_back(T.topRightCorner<3, 1>());
    return p;
  }
};

// Constant speed along straight legs between waypoints (z = 0), one pose every 0.1 s (1 m).
Drive alongWaypoints(const std::vector<Eigen::Vector2d>& waypoints) {
  Drive d;
  auto add = [&](const Eigen::Vector2d& xy) {
    Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
    T.topRightCorner<3, 1>() = Eigen::Vector3d(xy.x(), xy.y(), 0.0);
    d.t_ns.push_back(static_cast<std::int64_t>(d.poses.size()) * kSecond / 10);
    d.poses.push_back(T);
  };
  add(waypoints.front());
  for (std::size_t w = 1; w < waypoints.size(); ++w) {
    const Eigen::Vector2d a = waypoints[w - 1], b = waypoints[w];
    const auto steps = static_cast<int>(std::lround((b - a).norm()));
    for (int k = 1; k <= steps; ++k) add(a + (b - a) * k / steps);
  }
  return d;
}

// Pass 1 along y = 0 from x = 0 to 100 (0-10 s), away round a 100 m square, pass 2 along y = 0
// again from x = 0 to 60 (40-46 s). Within 2 m, only pass 1 meets the later drive (the end of the
// way back and pass 2), always 39.7-40.2 s later.
Drive twoPasses() {
  return alongWaypoints({{0, 0}, {100, 0}, {100, 100}, {0, 100}, {0, 0}, {60, 0}});
}
constexpr std::size_t kPass1End = 100;  // index of (100, 0)

TEST(EvalRevisits, ExactEstimateGivesZeroForEveryPair) {
  const Drive ref = twoPasses();
  const RevisitResult r = computeRevisits(ref.poses, ref.poses, ref.t_ns, {2.0, 30 * kSecond});
  ASSERT_FALSE(r.pairs.empty());
  for (const RevisitPair& p : r.pairs) EXPECT_EQ(p.error_m, 0.0) << p.i << " " << p.j;
  ASSERT_TRUE(r.stats);
  EXPECT_EQ(r.stats->stats.max, 0.0);
  EXPECT_EQ(r.stats->p95, 0.0);
  EXPECT_EQ(r.stats->stats.n, r.pairs.size());
}

TEST(EvalRevisits, SecondPassOffsetGivesItsLengthForEveryPair) {
  const Drive ref = twoPasses();
  Drive est = ref;
  const Eigen::Vector3d offset(0.3, -0.4, 0.0);  // 0.5 m
  for (std::size_t k = kPass1End + 1; k < est.poses.size(); ++k) {
    est.poses[k].topRightCorner<3, 1>() += offset;
  }
  const RevisitResult r = computeRevisits(ref.poses, est.poses, ref.t_ns, {2.0, 30 * kSecond});
  // Pass 1 (x = 0..60 within reach of pass 2, x = 0..2 of the way back) meets ~5 later poses each.
  ASSERT_GT(r.pairs.size(), 200U);
  for (const RevisitPair& p : r.pairs) {
    EXPECT_LE(p.i, kPass1End);
    EXPECT_GT(p.j, kPass1End);
    EXPECT_NEAR(p.error_m, 0.5, 1e-12) << p.i << " " << p.j;
    EXPECT_LE(p.ref_distance_m, 2.0);
    EXPECT_EQ(p.t_i_ns, ref.t_ns[p.i]);
    EXPECT_EQ(p.t_j_ns, ref.t_ns[p.j]);
  }
  ASSERT_TRUE(r.stats);
  EXPECT_NEAR(r.stats->stats.rmse, 0.5, 1e-12);
  EXPECT_NEAR(r.stats->stats.median, 0.5, 1e-12);
  EXPECT_NEAR(r.stats->p95, 0.5, 1e-12);
  EXPECT_NEAR(r.stats->stats.std, 0.0, 1e-12);
}

TEST(EvalRevisits, PairsCloserThanTheSeparationAreExcluded) {
  const Drive ref = twoPasses();
  const std::vector<Eigen::Vector3d> p = ref.positions();
  // Without a separation, neighbours along the drive pair up (1 m apart, 0.1 s).
  const PairList all = revisitPairs(p, ref.t_ns, 2.0, 0);
  EXPECT_NE(std::find(all.begin(), all.end(), std::make_pair<std::size_t, std::size_t>(0, 1)),
            all.end());
  // Every revisit is 39.7-40.2 s later: 39 s keeps them all, 41 s none, 40 s a part.
  const PairList at39 = revisitPairs(p, ref.t_ns, 2.0, 39 * kSecond);
  const PairList at40 = revisitPairs(p, ref.t_ns, 2.0, 40 * kSecond);
  EXPECT_EQ(at39, revisitPairs(p, ref.t_ns, 2.0, 30 * kSecond));
  EXPECT_TRUE(revisitPairs(p, ref.t_ns, 2.0, 41 * kSecond).empty());
  EXPECT_GT(at40.size(), 0U);
  EXPECT_LT(at40.size(), at39.size());
  for (const auto& [i, j] : at40) EXPECT_GE(ref.t_ns[j] - ref.t_ns[i], 40 * kSecond);
  EXPECT_EQ(at40, bruteForcePairs(p, ref.t_ns, 2.0, 40 * kSecond));
}

TEST(EvalRevisits, StraightDriveHasNoPairs) {
  const Drive ref = alongWaypoints({{0, 0}, {500, 0}});
  const RevisitResult r = computeRevisits(ref.poses, ref.poses, ref.t_ns, {5.0, 30 * kSecond});
  EXPECT_TRUE(r.pairs.empty());
  EXPECT_FALSE(r.stats);
}

// A random walk in a 20 m x 20 m x 2 m box (plenty of revisits) with jittered stamps.
std::pair<std::vector<Eigen::Vector3d>, std::vector<std::int64_t>> randomWalk(std::size_t n,
                                                                              unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> step(0.0, 0.7);
  std::uniform_int_distribution<std::int64_t> dt_ns(50'000'000, 150'000'000);
  std::vector<Eigen::Vector3d> p = {Eigen::Vector3d::Zero()};
  std::vector<std::int64_t> t = {0};
  while (p.size() < n) {
    Eigen::Vector3d next = p.back() + Eigen::Vector3d{step(rng), step(rng), 0.1 * step(rng)};
    next = next.cwiseMax(Eigen::Vector3d(-10, -10, -1)).cwiseMin(Eigen::Vector3d(10, 10, 1));
    p.push_back(next);
    t.push_back(t.back() + dt_ns(rng));
  }
  return {p, t};
}

TEST(EvalRevisits, GridSearchEqualsBruteForce) {
  for (const unsigned seed : {1U, 2U, 3U}) {
    const auto [p, t] = randomWalk(1500, seed);
    for (const double radius_m : {0.3, 1.5, 4.0}) {
      const PairList expected = bruteForcePairs(p, t, radius_m, 5 * kSecond);
      ASSERT_GT(expected.size(), 10U) << seed << " " << radius_m;
      EXPECT_EQ(revisitPairs(p, t, radius_m, 5 * kSecond), expected) << seed << " " << radius_m;
    }
  }
}

TEST(EvalRevisits, GridSearchEqualsBruteForceWithUnsortedStamps) {
  auto [p, t] = randomWalk(1200, 7);
  std::mt19937 rng(8);
  std::shuffle(t.begin(), t.end(), rng);  // pairs then count |t_j - t_i|
  const PairList expected = bruteForcePairs(p, t, 1.0, 20 * kSecond);
  ASSERT_GT(expected.size(), 10U);
  EXPECT_EQ(revisitPairs(p, t, 1.0, 20 * kSecond), expected);
}

TEST(EvalRevisits, DistanceExactlyTheRadiusCountsAcrossCellBorders) {
  // Two layers of an integer lattice around the origin with radius 1: neighbours sit exactly on
  // the radius and on cell borders, on both sides of zero.
  std::vector<Eigen::Vector3d> p;
  std::vector<std::int64_t> t;
  for (int z = -1; z <= 0; ++z) {
    for (int x = -3; x <= 3; ++x) {
      for (int y = -3; y <= 3; ++y) {
        p.emplace_back(x, y, z);
        t.push_back(static_cast<std::int64_t>(t.size()) * kSecond);
      }
    }
  }
  const PairList expected = bruteForcePairs(p, t, 1.0, 0);
  ASSERT_EQ(expected.size(), 2U * 2U * 7U * 6U + 49U);  // edges in x and y per layer, and in z
  EXPECT_EQ(revisitPairs(p, t, 1.0, 0), expected);
}

TEST(EvalRevisits, P95InterpolatesLinearlyBetweenOrderStatistics) {
  // Pass 2 offset growing along x: pair errors spread over a range.
  const Drive ref = twoPasses();
  Drive est = ref;
  for (std::size_t k = kPass1End + 1; k < est.poses.size(); ++k) {
    est.poses[k](1, 3) += 0.01 * est.poses[k](0, 3);
  }
  const RevisitResult r = computeRevisits(ref.poses, est.poses, ref.t_ns, {2.0, 30 * kSecond});
  ASSERT_TRUE(r.stats);
  std::vector<double> e;
  for (const RevisitPair& p : r.pairs) e.push_back(p.error_m);
  std::sort(e.begin(), e.end());
  const double rank = 0.95 * static_cast<double>(e.size() - 1);
  const auto lo = static_cast<std::size_t>(rank);
  const double expected = e[lo] + (rank - static_cast<double>(lo)) * (e[lo + 1] - e[lo]);
  EXPECT_DOUBLE_EQ(r.stats->p95, expected);
  EXPECT_GT(r.stats->p95, r.stats->stats.median);
  EXPECT_LT(r.stats->p95, r.stats->stats.max);
}

TEST(EvalRevisits, PairsAreSortedAndUnique) {
  const auto [p, t] = randomWalk(800, 11);
  const PairList pairs = revisitPairs(p, t, 2.0, 3 * kSecond);
  ASSERT_FALSE(pairs.empty());
  EXPECT_TRUE(std::is_sorted(pairs.begin(), pairs.end()));
  EXPECT_EQ(std::adjacent_find(pairs.begin(), pairs.end()), pairs.end());
  for (const auto& [i, j] : pairs) EXPECT_LT(i, j);
}

TEST(EvalRevisits, AnHourAt100HzIsNotQuadratic) {
  // 360 k poses round a 36 km circle (10 m/s): only the start and the end meet. A quadratic
  // search would make 6.5e10 distance tests; the grid makes a few million.
  constexpr std::size_t kPoses = 360'000;
  constexpr double kRadius = 36'000.0 / (2.0 * std::numbers::pi);
  std::vector<Eigen::Vector3d> p;
  std::vector<std::int64_t> t;
  for (std::size_t k = 0; k < kPoses; ++k) {
    const double phi = 2.0 * std::numbers::pi * static_cast<double>(k) / (kPoses - 1);
    p.emplace_back(kRadius * std::cos(phi), kRadius * std::sin(phi), 0.0);
    t.push_back(static_cast<std::int64_t>(k) * 10'000'000);
  }
  const auto start = std::chrono::steady_clock::now();
  const PairList pairs = revisitPairs(p, t, 2.0, 30 * kSecond);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("an hour at 100 Hz, start and end meeting: %.2f s\n", seconds);
  EXPECT_LT(seconds, 20.0);
  // First and last 2 m (20 poses each side at 0.1 m) pair up when within 2 m of each other.
  ASSERT_FALSE(pairs.empty());
  for (const auto& [i, j] : pairs) {
    EXPECT_LT(i, 21U);
    EXPECT_GT(j, kPoses - 22);
  }
}

TEST(EvalRevisits, BadInputThrows) {
  const Drive ref = twoPasses();
  const std::vector<Eigen::Vector3d> p = ref.positions();
  for (const double bad : {0.0, -1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    EXPECT_THROW(revisitPairs(p, ref.t_ns, bad, 0), InvalidInput) << bad;
  }
  EXPECT_THROW(revisitPairs(p, ref.t_ns, 1.0, -1), InvalidInput);
  EXPECT_THROW(revisitPairs(p, {}, 1.0, 0), InvalidInput);  // no stamps (KITTI without times)
  std::vector<Eigen::Vector3d> far = p;
  far[3].x() = 1e300;  // 1e300 / 1e-3 cells from the origin
  EXPECT_THROW(revisitPairs(far, ref.t_ns, 1e-3, 0), InvalidInput);
  std::vector<Eigen::Matrix4d> fewer = ref.poses;
  fewer.pop_back();
  EXPECT_THROW(computeRevisits(ref.poses, fewer, ref.t_ns, {1.0, 0}), InvalidInput);
}

}  // namespace
}  // namespace gvio::eval
