// The stated GNSS error ellipse (fusion/gnss_covariance.hpp): its shape normalised and kept from
// degenerating, NMEA GST's axes and orientation both ways, and the whitening the factors apply.
#include <gtest/gtest.h>

#include <cmath>

#include "fusion/gnss_covariance.hpp"

namespace gvio::fusion {
namespace {

TEST(GnssCovariance, ShapeHasTraceTwoAndKeepsTheCorrelation) {
  Eigen::Matrix2d cov;
  cov << 4.0 * 4.0, 0.6 * 4.0 * 3.0, 0.6 * 4.0 * 3.0, 3.0 * 3.0;  // sde 4, sdn 3, rho 0.6
  const Eigen::Matrix2d s = horizontalShape(cov);
  EXPECT_NEAR(s.trace(), 2.0, 1e-12);
  EXPECT_NEAR(s(0, 1) / std::sqrt(s(0, 0) * s(1, 1)), 0.6, 1e-12);
  EXPECT_NEAR(s(0, 0) / s(1, 1), 16.0 / 9.0, 1e-12);
  EXPECT_EQ(s(0, 1), s(1, 0));
  // sigma_h^2 S gives the stated covariance back, sigma_h = sqrt(trace / 2).
  const double sigma_h = std::sqrt(cov.trace() / 2.0);
  EXPECT_LT((sigma_h * sigma_h * s - cov).norm(), 1e-12);
}

TEST(GnssCovariance, ACircleAndWhatIsNotACovarianceGiveTheIdentity) {
  EXPECT_EQ(horizontalShape(2.5 * Eigen::Matrix2d::Identity()), Eigen::Matrix2d::Identity());
  EXPECT_EQ(horizontalShape(Eigen::Matrix2d::Zero()), Eigen::Matrix2d::Identity());
  Eigen::Matrix2d indefinite;
  indefinite << 1.0, 2.0, 2.0, 1.0;
  EXPECT_EQ(horizontalShape(indefinite), Eigen::Matrix2d::Identity());
  Eigen::Matrix2d nan = Eigen::Matrix2d::Identity();
  nan(0, 1) = nan(1, 0) = std::nan("");
  EXPECT_EQ(horizontalShape(nan), Eigen::Matrix2d::Identity());
  Eigen::Matrix2d asymmetric;
  asymmetric << 2.0, 0.5, -0.5, 1.0;
  EXPECT_EQ(horizontalShape(asymmetric), Eigen::Matrix2d::Identity());
}

// A correlation of 0.9999 would let a fix pin one direction to a millimetre: the minor axis is
// raised to a tenth of the major one, the orientation kept.
TEST(GnssCovariance, ANearlyDegenerateEllipseIsWidened) {
  const Eigen::Matrix2d thin = ellipseCovariance(5.0, 0.001, 30.0);
  const Eigen::Matrix2d s = horizontalShape(thin);
  const Ellipse e = ellipseOf(s);
  EXPECT_NEAR(e.minor_m / e.major_m, kMinEllipseAxisRatio, 1e-9);
  EXPECT_NEAR(e.orientation_deg, 30.0, 1e-6);
  EXPECT_NEAR(s.trace(), 2.0, 1e-12);
  // A mild ellipse is left as it is (up to the normalisation).
  const Eigen::Matrix2d mild = ellipseCovariance(2.0, 1.0, 100.0);
  EXPECT_LT((horizontalShape(mild) - 2.0 * mild / mild.trace()).norm(), 1e-12);
}

// A receiver's formal sigma below its quality's floor (an RTK fix's millimetres): raised to the
// floor by a circle, so the ellipse rounds off; one above the floor keeps its shape exactly.
TEST(GnssCovariance, AFloorAddsACircle) {
  const Eigen::Matrix2d tiny = ellipseCovariance(0.005, 0.001, 30.0);
  const HorizontalError floored = flooredHorizontal(tiny, 0.02);
  EXPECT_DOUBLE_EQ(floored.sigma_m, 0.02);
  const Ellipse e = ellipseOf(floored.shape_en);
  EXPECT_GT(e.minor_m / e.major_m, 0.95);  // nearly a circle
  EXPECT_NEAR(e.orientation_deg, 30.0, 1e-6);
  // Nothing stated: a circle of the floor, exactly.
  const HorizontalError none = flooredHorizontal(Eigen::Matrix2d::Zero(), 1.5);
  EXPECT_EQ(none.sigma_m, 1.5);
  EXPECT_EQ(none.shape_en, Eigen::Matrix2d::Identity());
  const Eigen::Matrix2d big = ellipseCovariance(3.0, 1.0, 30.0);
  const HorizontalError kept = flooredHorizontal(big, 1.5);
  EXPECT_DOUBLE_EQ(kept.sigma_m, std::sqrt(5.0));
  EXPECT_LT((kept.shape_en - horizontalShape(big)).norm(), 1e-12);
}

// NMEA GST: the orientation of the semi-major axis in degrees clockwise from true north.
TEST(GnssCovariance, EllipseAxesAndOrientationBothWays) {
  // Major axis pointing east (90 deg): east variance = major^2.
  const Eigen::Matrix2d east = ellipseCovariance(3.0, 1.0, 90.0);
  EXPECT_NEAR(east(0, 0), 9.0, 1e-12);
  EXPECT_NEAR(east(1, 1), 1.0, 1e-12);
  EXPECT_NEAR(east(0, 1), 0.0, 1e-12);
  // 45 deg (north-east): east and north errors positively correlated.
  const Eigen::Matrix2d ne = ellipseCovariance(3.0, 1.0, 45.0);
  EXPECT_NEAR(ne(0, 1), (9.0 - 1.0) / 2.0, 1e-12);
  for (const double orientation : {0.0, 17.0, 45.0, 90.0, 123.0, 179.0}) {
    const Ellipse e = ellipseOf(ellipseCovariance(2.5, 0.7, orientation));
    EXPECT_NEAR(e.major_m, 2.5, 1e-12) << orientation;
    EXPECT_NEAR(e.minor_m, 0.7, 1e-12) << orientation;
    EXPECT_NEAR(e.orientation_deg, orientation, 1e-9) << orientation;
  }
  // 200 deg is the same axis as 20 deg.
  EXPECT_NEAR(ellipseOf(ellipseCovariance(2.5, 0.7, 200.0)).orientation_deg, 20.0, 1e-9);
}

TEST(GnssCovariance, SqrtInformationWhitensTheCovariance) {
  const Eigen::Matrix2d shape = horizontalShape(ellipseCovariance(4.0, 1.0, 60.0));
  const Eigen::Matrix3d W = gnssSqrtInformation(2.0, 5.0, shape);
  const Eigen::Matrix3d cov = gnssCovariance(2.0, 5.0, shape);
  EXPECT_LT((W.transpose() * W * cov - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_LT((W * cov * W.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_EQ(W(2, 0), 0.0);
  EXPECT_EQ(W(2, 2), 1.0 / 5.0);
  // A circle whitens each axis by exactly 1 / sigma (as before the ellipse was kept).
  const Eigen::Matrix3d circle = gnssSqrtInformation(1.5, 3.0, Eigen::Matrix2d::Identity());
  EXPECT_EQ(circle, Eigen::Vector3d(1.0 / 1.5, 1.0 / 1.5, 1.0 / 3.0).asDiagonal().toDenseMatrix());
}

}  // namespace
}  // namespace gvio::fusion
