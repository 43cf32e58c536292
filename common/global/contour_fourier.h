// Fourier descriptor of a silhouette's outer contour, the contour descriptor
// of the Light Field Descriptor (Chen et al., Eurographics 2003; Zhang & Lu,
// "A comparative study of Fourier descriptors for shape representation and
// retrieval", ACCV 2002, who found the centroid distance signature best).
//
// The signature is the distance r(s) from the centre to the contour point at
// arc length s. Its discrete Fourier transform F_k, taken over `samples`
// points at equal arc-length steps, gives |F_k| / |F_0| for k = 1..10: the
// magnitudes do not depend on where the contour starts or which way it runs
// (so on in-plane rotation and mirroring), the division by the mean distance
// |F_0| removes scale. Each value is about the relative amplitude of the
// k-th harmonic, in [0, 1] in practice, ready for 8-bit quantisation.
//
// Differences from the original implementation, and why:
//   - it takes every contour pixel as a sample (N varies with the size of the
//     silhouette); here the contour is resampled to a fixed count, so that
//     the descriptor does not depend on the image resolution and the
//     transform has a fixed cost;
//   - the centre is the silhouette's area centroid (zernike_moments.h
//     ComputeCentroid) rather than its bounding box centre, which moves when
//     the image turns;
//   - a silhouette in several pieces: the original erodes and thins until one
//     outer contour is left; here the outer contour of the largest piece (by
//     enclosed area) is used.
#ifndef MESHSEEK_COMMON_GLOBAL_CONTOUR_FOURIER_H_
#define MESHSEEK_COMMON_GLOBAL_CONTOUR_FOURIER_H_

#include <array>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "common/global/zernike_moments.h"

namespace meshseek {

/// Coefficients kept: |F_1| .. |F_10|, each over |F_0|.
inline constexpr int kFourierCoefficients = 10;

struct Point2d {
  double x = 0;
  double y = 0;
};

struct ContourFourierOptions {
  /// Points the contour is resampled to at equal arc-length steps before the
  /// transform. At least 2 * 10 + 1 (Nyquist for the 10th harmonic), at most
  /// 65,536. 128 resolves the 10 harmonics with room to spare and costs
  /// about 1,400 multiply-adds.
  int samples = 128;

  absl::Status Validate() const;
};

/// The descriptor of a closed polygon (the last point joins the first), with
/// the centroid distance measured from `centre`. Fewer than 3 distinct
/// points, or a contour of zero length or whose points all lie on the
/// centre, give all zeros (nothing to describe; never NaN).
absl::StatusOr<std::array<double, kFourierCoefficients>> CentroidDistanceFourier(
    const std::vector<Point2d>& contour,
    const Point2d& centre,
    const ContourFourierOptions& options);

/// The outer contour of the largest piece of the silhouette (OpenCV
/// findContours, pixel-centre coordinates: pixel (x, y) at (x + 0.5, y + 0.5)).
/// Empty when nothing is covered.
std::vector<Point2d> OuterContour(const BinaryImageView& image);

/// CentroidDistanceFourier of OuterContour, centred on the silhouette's
/// centroid. An empty silhouette gives all zeros.
absl::StatusOr<std::array<double, kFourierCoefficients>> SilhouetteFourier(
    const BinaryImageView& image, const ContourFourierOptions& options);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_GLOBAL_CONTOUR_FOURIER_H_
