// Map builder: landmarks follow corrected keyframe poses exactly, the sparse filters, skipped
// keyframes, the dense cloud's voxel grid, and occupancy from a wall seen from one origin.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <tuple>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "mapping/map_builder.hpp"
#include "mapping/occupancy_builder.hpp"
#include "odometry/error.hpp"
#include "support/kitti_camera.hpp"

namespace gvio::mapping {
namespace {

using odometry::LandmarkEstimate;

CameraModel camera() {
  CameraModel c = test::kittiRectifiedCamera();
  // KITTI-like: camera x right, y down, z forward; body x forward, y left, z up; 0.3 m ahead.
  Eigen::Matrix3d R_b_c;
  R_b_c << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  c.T_b_c.linear() = R_b_c;
  c.T_b_c.translation() = Eigen::Vector3d(0.3, 0.1, 0.5);
  return c;
}

Eigen::Isometry3d pose(double yaw, const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
               Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitX()).toRotationMatrix();
  T.translation() = t;
  return T;
}

LandmarkEstimate landmark(std::uint64_t id, const Eigen::Vector3d& p_w, int obs, double px) {
  LandmarkEstimate lm;
  lm.id = id;
  lm.p_w = p_w;
  lm.observations = obs;
  lm.mean_reprojection_px = px;
  return lm;
}

MapConfig sparseOnly() {
  MapConfig config;
  config.dense.enabled = false;
  return config;
}

std::map<std::uint32_t, Eigen::Vector3d> byObservations(const MapCloud& cloud) {
  std::map<std::uint32_t, Eigen::Vector3d> out;
  for (const auto& p : cloud) out[p.observations] = p.getVector3fMap().cast<double>();
  return out;
}

TEST(MappingBuilder, LandmarksFollowTheCorrectedKeyframePose) {
  MapBuilder builder(sparseOnly(), camera(), 0.0);
  const Eigen::Isometry3d T_w_b1 = pose(0.3, {10.0, -4.0, 1.0});
  const Eigen::Isometry3d T_w_b2 = pose(0.35, {12.0, -3.0, 1.1});
  const Eigen::Vector3d a_w(20.0, 2.0, 1.5), b_w(25.0, -1.0, 3.0), b2_w(25.2, -1.1, 3.05);
  builder.addKeyframe(1000, T_w_b1, cv::Mat(), cv::Mat(),
                      {landmark(1, a_w, 5, 0.5), landmark(2, b_w, 6, 0.5)});
  // Landmark 2 is re-estimated in keyframe 2: its latest estimate and count win.
  builder.addKeyframe(2000, T_w_b2, cv::Mat(), cv::Mat(), {landmark(2, b2_w, 7, 0.4)});

  const MapBuildResult vio = builder.build(builder.vioPoses());
  ASSERT_EQ(vio.sparse.size(), 2u);
  auto points = byObservations(vio.sparse);
  EXPECT_LT((points.at(5) - a_w).norm(), 1e-5);
  EXPECT_LT((points.at(7) - b2_w).norm(), 1e-5);
  for (const auto& p : vio.sparse) EXPECT_EQ(p.source, 0);

  // Fusion corrects each keyframe differently: every landmark moves with its own keyframe.
  const Eigen::Isometry3d C1 = pose(0.02, {1.5, -0.7, 0.2});
  const Eigen::Isometry3d C2 = pose(-0.01, {-2.0, 0.4, -0.3});
  const PoseLookup corrected = [&](std::int64_t t_ns) -> std::optional<Eigen::Isometry3d> {
    return t_ns == 1000 ? C1 * T_w_b1 : C2 * T_w_b2;
  };
  const MapBuildResult fused = builder.build(corrected);
  points = byObservations(fused.sparse);
  EXPECT_LT((points.at(5) - C1 * a_w).norm(), 1e-5);
  EXPECT_LT((points.at(7) - C2 * b2_w).norm(), 1e-5);
  EXPECT_EQ(fused.counts.keyframes_used, 2u);
  EXPECT_EQ(fused.counts.keyframes_skipped, 0u);
}

TEST(MappingBuilder, LandmarkKeepsItsBestSupportedEstimate) {
  // As frames leave the window a landmark loses observations: the estimate that rested on the
  // most observations stays, with its keyframe; more observations later replace it.
  MapBuilder builder(sparseOnly(), camera(), 0.0);
  const Eigen::Isometry3d T1 = pose(0.1, {0.0, 0.0, 0.0}), T2 = pose(0.2, {5.0, 0.0, 0.0});
  const Eigen::Vector3d best_w(20.0, 2.0, 1.5), late_w(20.4, 2.3, 1.4);
  builder.addKeyframe(1000, T1, cv::Mat(), cv::Mat(), {landmark(1, best_w, 8, 0.6)});
  builder.addKeyframe(2000, T2, cv::Mat(), cv::Mat(),
                      {landmark(1, late_w, 2, 0.2), landmark(2, late_w, 3, 0.3)});
  builder.addKeyframe(3000, T2, cv::Mat(), cv::Mat(), {landmark(2, best_w, 5, 0.4)});
  const auto& lms = builder.store().landmarks();
  EXPECT_EQ(lms.at(1).keyframe, 0u);
  EXPECT_EQ(lms.at(1).observations, 8);
  EXPECT_DOUBLE_EQ(lms.at(1).mean_reprojection_px, 0.6);
  EXPECT_EQ(lms.at(2).keyframe, 2u);
  EXPECT_EQ(lms.at(2).observations, 5);
  const MapBuildResult map = builder.build(builder.vioPoses());
  ASSERT_EQ(map.sparse.size(), 2u);
  const auto points = byObservations(map.sparse);
  EXPECT_LT((points.at(8) - best_w).norm(), 1e-5);
  EXPECT_LT((points.at(5) - best_w).norm(), 1e-5);
}

TEST(MappingBuilder, SparseFiltersOnObservationsAndReprojection) {
  MapConfig config = sparseOnly();  // defaults: >= 4 observations, <= 1.5 px
  MapBuilder builder(config, camera(), 0.0);
  const Eigen::Isometry3d T_w_b = pose(0.0, {0, 0, 0});
  builder.addKeyframe(1, T_w_b, cv::Mat(), cv::Mat(),
                      {landmark(1, {10, 0, 0}, 3, 0.5), landmark(2, {10, 1, 0}, 4, 1.5),
                       landmark(3, {10, 2, 0}, 9, 1.6), landmark(4, {10, 3, 0}, 12, 0.1)});
  const MapBuildResult map = builder.build(builder.vioPoses());
  std::set<std::uint32_t> kept;
  for (const auto& p : map.sparse) kept.insert(p.observations);
  EXPECT_EQ(kept, (std::set<std::uint32_t>{4, 12}));
  EXPECT_EQ(map.counts.landmarks_stored, 4u);
  EXPECT_EQ(map.counts.landmarks_rejected, 2u);
  EXPECT_EQ(map.counts.sparse_points, 2u);
}

TEST(MappingBuilder, SparseLeavesOutLandmarksBeyondItsRange) {
  // The VIO keeps far landmarks for their rotation information; the map takes them up to
  // sparse.max_landmark_range_m (80 m) from their keyframe only.
  MapConfig config = sparseOnly();
  MapBuilder builder(config, camera(), 0.0);
  const Eigen::Isometry3d T_w_b = pose(0.0, {100, 0, 0});
  builder.addKeyframe(1, T_w_b, cv::Mat(), cv::Mat(),
                      {landmark(1, {179, 0, 0}, 5, 0.5), landmark(2, {181, 0, 0}, 6, 0.5),
                       landmark(3, {400, 0, 0}, 7, 0.5)});
  const MapBuildResult map = builder.build(builder.vioPoses());
  ASSERT_EQ(map.sparse.size(), 1u);
  EXPECT_EQ(map.sparse[0].observations, 5u);
  EXPECT_EQ(map.counts.landmarks_rejected, 2u);
  config.sparse.max_landmark_range_m = 500.0;
  MapBuilder wide(config, camera(), 0.0);
  wide.addKeyframe(1, T_w_b, cv::Mat(), cv::Mat(),
                   {landmark(1, {179, 0, 0}, 5, 0.5), landmark(2, {181, 0, 0}, 6, 0.5),
                    landmark(3, {400, 0, 0}, 7, 0.5)});
  EXPECT_EQ(wide.build(wide.vioPoses()).sparse.size(), 3u);
}

TEST(MappingOccupancy, PointsAllBeyondTheRangeClearSpaceAndColourNothing) {
  // OctoMap 1.9's ColorOcTree::updateInnerOccupancy does not check for an empty tree: a map
  // whose points all lie beyond occupancy.max_range_m (30 m) crashed there.
  OccupancyBuilder builder(OccupancyConfig{});
  CameraCloud far;
  pcl::PointXYZI p;
  p.x = 100.0F;
  p.y = 0.0F;
  p.z = 0.0F;
  p.intensity = 50.0F;
  far.push_back(p);
  builder.insert(far, Eigen::Vector3d::Zero());
  const OccupancyBuilder::Trees trees = builder.finish();
  EXPECT_EQ(trees.color->getNumLeafNodes(), 0u);
  EXPECT_GT(trees.occupancy->getNumLeafNodes(), 0u);  // the ray's first 30 m, free
  const OccupancyBuilder::Trees none = OccupancyBuilder(OccupancyConfig{}).finish();
  EXPECT_EQ(none.occupancy->getNumLeafNodes(), 0u);
  EXPECT_EQ(none.color->getNumLeafNodes(), 0u);
}

TEST(MappingBuilder, LandmarkIntensityIsSampledWhereItProjects) {
  MapBuilder builder(sparseOnly(), camera(), 0.0);
  const CameraModel cam = camera();
  // Grey = column / 5: bilinear sampling at u gives u / 5.
  cv::Mat left(cam.height_px, cam.width_px, CV_8UC1);
  for (int v = 0; v < left.rows; ++v) {
    for (int u = 0; u < left.cols; ++u) left.at<uchar>(v, u) = static_cast<uchar>(u / 5);
  }
  const Eigen::Isometry3d T_w_b = pose(0.2, {3, 4, 0});
  // 8 m ahead, projecting to u = 619.6 (between grey 123 and 124), v = cy.
  const double u = 619.6;
  const Eigen::Vector3d p_c((u - cam.cx) * 8.0 / cam.fx, 0.0, 8.0);
  const Eigen::Vector3d p_w = T_w_b * cam.T_b_c * p_c;
  builder.addKeyframe(1, T_w_b, left, cv::Mat(), {landmark(9, p_w, 5, 0.5)});
  const MapBuildResult map = builder.build(builder.vioPoses());
  ASSERT_EQ(map.sparse.size(), 1u);
  const int u0 = static_cast<int>(u);
  const double a = u - u0;
  EXPECT_NEAR(map.sparse[0].intensity, (1.0 - a) * (u0 / 5) + a * ((u0 + 1) / 5), 1e-3);
}

TEST(MappingBuilder, KeyframesWithoutPoseAreSkippedAndCounted) {
  MapBuilder builder(sparseOnly(), camera(), 0.0);
  builder.addKeyframe(1, pose(0, {0, 0, 0}), cv::Mat(), cv::Mat(),
                      {landmark(1, {10, 0, 0}, 5, 0.5)});
  builder.addKeyframe(2, pose(0, {1, 0, 0}), cv::Mat(), cv::Mat(),
                      {landmark(2, {10, 1, 0}, 5, 0.5)});
  builder.addKeyframe(3, pose(0, {2, 0, 0}), cv::Mat(), cv::Mat(),
                      {landmark(3, {10, 2, 0}, 5, 0.5)});
  const PoseLookup vio = builder.vioPoses();
  const MapBuildResult map =
      builder.build([&](std::int64_t t_ns) { return t_ns == 2 ? std::nullopt : vio(t_ns); });
  EXPECT_EQ(map.counts.keyframes, 3u);
  EXPECT_EQ(map.counts.keyframes_used, 2u);
  EXPECT_EQ(map.counts.keyframes_skipped, 1u);
  EXPECT_EQ(map.counts.landmarks_unplaced, 1u);
  ASSERT_EQ(map.sparse.size(), 2u);
  for (const auto& p : map.sparse) EXPECT_NE(p.y, 1.0f);
  EXPECT_EQ(map.ms_octomap_per_keyframe.size(), 2u);
  // Keyframe times must increase.
  EXPECT_THROW(builder.addKeyframe(3, pose(0, {0, 0, 0}), cv::Mat(), cv::Mat(), {}), InvalidInput);
}

// A textured plane 9.7 m in front of the camera (disparity 40 px), as a rectified pair.
std::pair<cv::Mat, cv::Mat> planePair(const CameraModel& c) {
  cv::Mat noise(c.height_px, c.width_px + 40, CV_8UC1);
  cv::RNG(5).fill(noise, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(noise, noise, cv::Size(0, 0), 1.2);
  cv::normalize(noise, noise, 0, 255, cv::NORM_MINMAX);
  return {noise.colRange(0, c.width_px).clone(), noise.colRange(40, c.width_px + 40).clone()};
}

TEST(MappingBuilder, DenseCloudIsVoxelDownsampledAndFollowsPoses) {
  MapConfig config;
  config.dense.sor_stddev_mul = 3.0;
  config.dense.min_spacing_m = 0.0;  // depth at every keyframe, even one that did not move
  config.dense.min_rotation_deg = 0.0;
  const CameraModel cam = camera();
  MapBuilder builder(config, cam, 0.54);
  const auto [left, right] = planePair(cam);
  const Eigen::Isometry3d T_w_b = pose(0.4, {5, 6, 0});
  // The same view twice: the global VoxelGrid merges the two keyframes' points.
  const KeyframeTimings t1 = builder.addKeyframe(1, T_w_b, left, right, {});
  const KeyframeTimings t2 = builder.addKeyframe(2, T_w_b, left, right, {});
  EXPECT_GT(t1.ms_dense, 0.0);
  EXPECT_GT(t1.dense_points, 10000u);
  EXPECT_EQ(t1.dense_points, t2.dense_points);

  const MapBuildResult map = builder.build(builder.vioPoses());
  EXPECT_EQ(map.counts.dense_points_raw, 2 * t1.dense_points);
  // The duplicate keyframe adds no voxel: the map equals that of the single keyframe.
  MapBuilder single(config, cam, 0.54);
  single.addKeyframe(1, T_w_b, left, right, {});
  const MapBuildResult single_map = single.build(single.vioPoses());
  EXPECT_EQ(single_map.counts.dense_points_raw, t1.dense_points);
  EXPECT_EQ(map.counts.dense_points_voxel, single_map.counts.dense_points_voxel);
  // The world-aligned grid re-bins the keyframe's camera-aligned voxels: fewer, not more.
  EXPECT_LT(map.counts.dense_points_voxel, t1.dense_points);
  EXPECT_GT(map.counts.dense_points_voxel, t1.dense_points / 2);
  EXPECT_LE(map.dense.size(), map.counts.dense_points_voxel);
  EXPECT_GT(map.dense.size(), map.counts.dense_points_voxel * 9 / 10);
  // One point per 0.1 m voxel (pcl::VoxelGrid's float cell formula), all on the plane.
  const float inv = 1.0f / 0.1f;
  std::set<std::tuple<long, long, long>> voxels;
  const Eigen::Isometry3d T_c_w = (T_w_b * cam.T_b_c).inverse();
  for (const auto& p : map.dense) {
    voxels.insert({static_cast<long>(std::floor(p.x * inv)),
                   static_cast<long>(std::floor(p.y * inv)),
                   static_cast<long>(std::floor(p.z * inv))});
    EXPECT_NEAR((T_c_w * p.getVector3fMap().cast<double>()).z(), cam.fx * 0.54 / 40.0, 0.3);
    EXPECT_EQ(p.source, 1);
    EXPECT_EQ(p.observations, 0u);
  }
  EXPECT_GE(static_cast<double>(voxels.size()), 0.999 * static_cast<double>(map.dense.size()));

  // Raw keyframe points move exactly with a corrected pose.
  const Eigen::Isometry3d C = pose(0.1, {-3.0, 2.0, 0.5});
  const MapCloud raw = builder.keyframePoints(1, 1, builder.vioPoses());
  const MapCloud moved = builder.keyframePoints(
      1, 1, [&](std::int64_t) { return std::optional<Eigen::Isometry3d>(C * T_w_b); });
  ASSERT_EQ(raw.size(), t1.dense_points);
  ASSERT_EQ(moved.size(), raw.size());
  for (std::size_t i = 0; i < raw.size(); i += 97) {
    const Eigen::Vector3d expected = C * raw[i].getVector3fMap().cast<double>();
    EXPECT_LT((moved[i].getVector3fMap().cast<double>() - expected).norm(), 1e-4);
  }
  // Occupancy from dense keyframes: the plane is occupied.
  EXPECT_GT(map.counts.occupied_leaves, 1000u);

  // Built in two stages, freeing the stored points: the same map, no dense point left. The
  // clouds come without trees; the occupancy stage adds them.
  MapBuildResult staged = builder.buildClouds(builder.vioPoses());
  EXPECT_FALSE(staged.occupancy || staged.occupancy_color);
  EXPECT_EQ(staged.dense.size(), map.dense.size());
  EXPECT_EQ(staged.counts.dense_points_raw, map.counts.dense_points_raw);
  EXPECT_EQ(staged.counts.keyframes_used, 2u);
  builder.buildOccupancyReleasing(builder.vioPoses(), staged);
  ASSERT_TRUE(staged.occupancy && staged.occupancy_color);
  EXPECT_EQ(staged.occupancy->getNumLeafNodes(), map.occupancy->getNumLeafNodes());
  EXPECT_EQ(staged.counts.occupied_leaves, map.counts.occupied_leaves);
  EXPECT_EQ(staged.counts.keyframes_used, 2u);
  EXPECT_EQ(staged.ms_octomap_per_keyframe.size(), 2u);
  EXPECT_EQ(builder.store().densePointCount(), 0u);
  EXPECT_TRUE(builder.keyframePoints(1, 2, builder.vioPoses()).empty());
}

TEST(MappingBuilder, EveryNthKeyframeGetsDepth) {
  MapConfig config;
  config.dense.every_n_keyframes = 2;
  config.dense.min_spacing_m = 0.0;
  config.dense.min_rotation_deg = 0.0;
  const CameraModel cam = camera();
  MapBuilder builder(config, cam, 0.54);
  const auto [left, right] = planePair(cam);
  EXPECT_GT(builder.addKeyframe(1, pose(0, {0, 0, 0}), left, right, {}).dense_points, 0u);
  EXPECT_EQ(builder.addKeyframe(2, pose(0, {0, 0, 0}), left, right, {}).dense_points, 0u);
  EXPECT_GT(builder.addKeyframe(3, pose(0, {0, 0, 0}), left, right, {}).dense_points, 0u);
  EXPECT_FALSE(builder.store().keyframes()[1].has_dense);
  // Mono builder never computes depth.
  MapBuilder mono(MapConfig{}, cam, 0.0);
  EXPECT_EQ(mono.addKeyframe(1, pose(0, {0, 0, 0}), left, right, {}).dense_points, 0u);
}

TEST(MappingBuilder, DepthOnlyOnceTheCameraMovedOrTurnedEnough) {
  MapConfig config;  // the defaults: 1.5 m or 10 deg since the last keyframe with depth
  const CameraModel cam = camera();
  MapBuilder builder(config, cam, 0.54);
  const auto pair = planePair(cam);  // not a structured binding: clang 14 cannot capture one
  const auto depth = [&](std::int64_t t, const Eigen::Isometry3d& T_w_b) {
    return builder.addKeyframe(t, T_w_b, pair.first, pair.second, {}).dense_points > 0;
  };
  EXPECT_TRUE(depth(1, pose(0, {0, 0, 0})));        // the first keyframe
  EXPECT_FALSE(depth(2, pose(0, {0.8, 0, 0})));     // 0.8 m
  EXPECT_FALSE(depth(3, pose(0, {1.4, 0.3, 0})));   // 1.43 m from the first
  EXPECT_TRUE(depth(4, pose(0, {1.6, 0, 0})));      // 1.6 m: the new reference
  EXPECT_FALSE(depth(5, pose(0.15, {2.0, 0, 0})));  // 0.4 m and 8.6 deg from it
  EXPECT_TRUE(depth(6, pose(0.18, {2.0, 0, 0})));   // 10.3 deg
  EXPECT_FALSE(depth(7, pose(0.18, {2.0, 0, 0})));  // standing still
  std::size_t with_depth = 0;
  for (const auto& kf : builder.store().keyframes()) with_depth += kf.has_dense ? 1 : 0;
  EXPECT_EQ(with_depth, 3U);
  // Both rules at 0: every keyframe, standing still or not.
  config.dense.min_spacing_m = 0.0;
  config.dense.min_rotation_deg = 0.0;
  MapBuilder every(config, cam, 0.54);
  for (std::int64_t t = 1; t <= 3; ++t) {
    EXPECT_GT(every.addKeyframe(t, pose(0, {0, 0, 0}), pair.first, pair.second, {}).dense_points,
              0u);
  }
  config.dense.min_spacing_m = -1.0;
  EXPECT_THROW(config.validate(), InvalidInput);
}

TEST(MappingBuilder, WallIsOccupiedAndTheSpaceBeforeItFree) {
  // Camera = body = world; a 4 x 4 m wall of landmarks 6 m ahead (camera z), seen from two
  // keyframes.
  CameraModel cam = camera();
  cam.T_b_c = Eigen::Isometry3d::Identity();
  MapBuilder builder(sparseOnly(), cam, 0.0);
  std::vector<LandmarkEstimate> wall;
  std::uint64_t id = 0;
  for (double x = -2.0; x <= 2.0; x += 0.05) {
    for (double y = -2.0; y <= 2.0; y += 0.05) wall.push_back(landmark(++id, {x, y, 6.03}, 5, 0.5));
  }
  // The lower half (y < 0) from the origin, the upper half from a second keyframe.
  std::stable_partition(wall.begin(), wall.end(),
                        [](const LandmarkEstimate& lm) { return lm.p_w.y() < 0.0; });
  const auto half = static_cast<std::size_t>(
      std::count_if(wall.begin(), wall.end(), [](const auto& lm) { return lm.p_w.y() < 0.0; }));
  const Eigen::Isometry3d second(Eigen::Translation3d(0.5, 0.0, 1.0));
  builder.addKeyframe(1, Eigen::Isometry3d::Identity(), cv::Mat(), cv::Mat(),
                      {wall.begin(), wall.begin() + static_cast<std::ptrdiff_t>(half)});
  builder.addKeyframe(2, second, cv::Mat(), cv::Mat(),
                      {wall.begin() + static_cast<std::ptrdiff_t>(half), wall.end()});
  const MapBuildResult map = builder.build(builder.vioPoses());
  ASSERT_TRUE(map.occupancy);
  ASSERT_TRUE(map.occupancy_color);
  const octomap::OcTree& tree = *map.occupancy;
  EXPECT_DOUBLE_EQ(tree.getResolution(), 0.2);

  const auto occupied = [](const auto& t, double x, double y, double z) -> std::optional<bool> {
    const auto* node = t.search(x, y, z);
    if (!node) return std::nullopt;
    return t.isNodeOccupied(node);
  };
  for (double x : {-1.5, 0.0, 1.1}) {
    for (double y : {-1.3, -0.4, 0.4, 1.7}) {
      EXPECT_EQ(occupied(tree, x, y, 6.03), std::optional<bool>(true)) << x << " " << y;
      EXPECT_EQ(occupied(*map.occupancy_color, x, y, 6.03), std::optional<bool>(true));
      // Free along the ray from the keyframe that saw this part of the wall.
      const Eigen::Vector3d origin =
          y < 0.0 ? Eigen::Vector3d::Zero().eval() : Eigen::Vector3d(second.translation());
      for (double s : {0.1, 0.4, 0.7, 0.9}) {
        const Eigen::Vector3d q = origin + s * (Eigen::Vector3d(x, y, 6.03) - origin);
        EXPECT_EQ(occupied(tree, q.x(), q.y(), q.z()), std::optional<bool>(false)) << q.transpose();
      }
      // Behind the wall nothing is known.
      EXPECT_EQ(occupied(tree, x, y, 7.5), std::nullopt);
    }
  }
  // The wall covers ~ (4 / 0.2)^2 voxels, one layer thick.
  EXPECT_GE(map.counts.occupied_leaves, 400u);
  EXPECT_LE(map.counts.occupied_leaves, 21u * 21u);
  // The colour tree carries the landmarks' (default 0) grey.
  const auto* node = map.occupancy_color->search(0.0, 0.0, 6.03);
  ASSERT_NE(node, nullptr);
  EXPECT_TRUE(node->isColorSet());

  // Every coloured voxel has the OcTree's classification.
  std::size_t coloured = 0;
  for (auto it = map.occupancy_color->begin_leafs(); it != map.occupancy_color->end_leafs();
       ++it, ++coloured) {
    const auto* mine = tree.search(it.getKey());
    ASSERT_NE(mine, nullptr);
    EXPECT_EQ(tree.isNodeOccupied(mine), map.occupancy_color->isNodeOccupied(*it));
  }
  EXPECT_GE(coloured, 400u);

  // The OcTree has the same classification as one filled by OctoMap's own insertion of the same
  // scans.
  octomap::OcTree direct(0.2);
  const auto scan = [&](std::size_t begin, std::size_t end) {
    octomap::Pointcloud pc;
    for (std::size_t i = begin; i < end; ++i) {
      pc.push_back(static_cast<float>(wall[i].p_w.x()), static_cast<float>(wall[i].p_w.y()),
                   static_cast<float>(wall[i].p_w.z()));
    }
    return pc;
  };
  direct.insertPointCloud(scan(0, half), octomap::point3d(0, 0, 0), 30.0, true, true);
  direct.insertPointCloud(scan(half, wall.size()), octomap::point3d(0.5f, 0.0f, 1.0f), 30.0, true,
                          true);
  direct.updateInnerOccupancy();
  std::size_t leaves = 0;
  for (auto it = direct.begin_leafs(); it != direct.end_leafs(); ++it, ++leaves) {
    const auto* mine = tree.search(it.getKey());
    ASSERT_NE(mine, nullptr);
    EXPECT_EQ(tree.isNodeOccupied(mine), direct.isNodeOccupied(*it));
  }
  EXPECT_GT(leaves, 2000u);
  std::size_t direct_occupied = 0;
  for (auto it = direct.begin_leafs(); it != direct.end_leafs(); ++it) {
    if (direct.isNodeOccupied(*it)) ++direct_occupied;
  }
  EXPECT_EQ(map.counts.occupied_leaves, direct_occupied);
}

TEST(MappingConfig, DefaultsValidateAndBadValuesThrow) {
  EXPECT_NO_THROW(MapConfig{}.validate());
  MapConfig c;
  c.dense.stereo.num_disparities = 50;
  EXPECT_THROW(c.validate(), InvalidInput);
  c = MapConfig{};
  c.dense.stereo.max_range_m = 40.0;
  EXPECT_THROW(c.validate(), InvalidInput);
  c = MapConfig{};
  c.occupancy.resolution_m = 0.0;
  EXPECT_THROW(c.validate(), InvalidInput);
  c = MapConfig{};
  c.sparse.min_landmark_observations = 1;
  EXPECT_THROW(c.validate(), InvalidInput);
  c = MapConfig{};
  c.sparse.max_landmark_range_m = 0.0;
  EXPECT_THROW(c.validate(), InvalidInput);
  c = MapConfig{};
  c.dense.voxel_size_m = 0.01;
  EXPECT_THROW(MapBuilder(c, camera(), 0.54), InvalidInput);
}

}  // namespace
}  // namespace gvio::mapping
