#pragma once
// The error ellipse a GNSS solution states: RTKLIB's sdn/sde/sdne (or its ECEF covariance), an NMEA
// GST's semi-major and semi-minor axes with their orientation, a NavSatFix's full covariance. A fix
// keeps it as a scalar horizontal sigma and the ellipse's shape (GnssFix::shape_en), so everything
// that scales a fix's sigma (the learned noise, the reader's floors) keeps the stated correlation:
//   cov_en = sigma_h^2 S,  S symmetric positive definite, trace(S) = 2,
// S = I for a circle (a source that states no correlation).
#include <Eigen/Core>

namespace gvio::fusion {

// How thin a stated ellipse may be: its minor axis at least this fraction of its major axis. A
// receiver's correlations are estimates too, and a near-degenerate ellipse would let a fix pin one
// direction to its stated precision while claiming nothing across it.
inline constexpr double kMinEllipseAxisRatio = 0.1;

// The shape S of a stated horizontal covariance (east, north; m^2): normalised to trace 2, its
// minor axis raised to kMinEllipseAxisRatio of its major one. The identity when cov_en is not
// finite, not symmetric positive definite, or of zero size.
Eigen::Matrix2d horizontalShape(const Eigen::Matrix2d& cov_en);

// A stated horizontal covariance raised to a floor: the sigma sqrt(trace / 2) at least floor_m,
// what the floor adds added as a circle (cov + (floor^2 - trace / 2) I): a floor stands for
// errors the receiver does not state (an RTK fix's few centimetres against its formal
// millimetres), which follow no satellite geometry, so a floored fix's ellipse rounds off.
struct HorizontalError {
  double sigma_m = 0.0;
  Eigen::Matrix2d shape_en = Eigen::Matrix2d::Identity();
};
HorizontalError flooredHorizontal(const Eigen::Matrix2d& cov_en, double floor_m);

// The horizontal covariance (east, north) of an ellipse of 1-sigma semi-axes major_m >= minor_m
// whose major axis points orientation_deg clockwise from true north (NMEA GST fields 3-5).
Eigen::Matrix2d ellipseCovariance(double major_m, double minor_m, double orientation_deg);

// The ellipse of a horizontal covariance: 1-sigma semi-axes and the major axis's orientation in
// [0, 180) degrees clockwise from north (what an NMEA GST states).
struct Ellipse {
  double major_m = 0.0, minor_m = 0.0, orientation_deg = 0.0;
};
Ellipse ellipseOf(const Eigen::Matrix2d& cov_en);

// The fix's covariance in ENU: sigma_h^2 S horizontally, sigma_v^2 up, no horizontal-vertical
// correlation.
Eigen::Matrix3d gnssCovariance(double sigma_h_m, double sigma_v_m, const Eigen::Matrix2d& shape_en);

// Its square-root information W (upper triangular, W^T W = covariance^-1): the whitening a GNSS
// position factor applies to its error.
Eigen::Matrix3d gnssSqrtInformation(double sigma_h_m, double sigma_v_m,
                                    const Eigen::Matrix2d& shape_en);

}  // namespace gvio::fusion
