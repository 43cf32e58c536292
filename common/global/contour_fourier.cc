#include "common/global/contour_fourier.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "absl/strings/str_cat.h"

namespace meshseek {
namespace {

constexpr double kPi = 3.14159265358979323846;

}  // namespace

absl::Status ContourFourierOptions::Validate() const {
  if (samples < 2 * kFourierCoefficients + 1 || samples > 65536) {
    return absl::InvalidArgumentError(absl::StrCat("contour fourier: samples must be in [",
                                                   2 * kFourierCoefficients + 1,
                                                   ", 65536], got ",
                                                   samples));
  }
  return absl::OkStatus();
}

absl::StatusOr<std::array<double, kFourierCoefficients>> CentroidDistanceFourier(
    const std::vector<Point2d>& contour,
    const Point2d& centre,
    const ContourFourierOptions& options) {
  if (absl::Status valid = options.Validate(); !valid.ok()) return valid;
  std::array<double, kFourierCoefficients> out{};
  const std::size_t n = contour.size();
  if (n < 3) return out;
  // Cumulative arc length at each vertex, closing edge included.
  std::vector<double> at(n + 1, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    const Point2d& a = contour[i];
    const Point2d& b = contour[(i + 1) % n];
    at[i + 1] = at[i] + std::hypot(b.x - a.x, b.y - a.y);
  }
  const double length = at[n];
  if (!(length > 0) || !std::isfinite(length)) return out;
  // The centroid distance at `samples` equal steps, by linear interpolation
  // along the edges.
  const int s = options.samples;
  std::vector<double> r(s);
  std::size_t edge = 0;
  for (int k = 0; k < s; ++k) {
    const double target = length * k / s;
    while (edge + 1 < n && at[edge + 1] <= target) ++edge;
    const Point2d& a = contour[edge];
    const Point2d& b = contour[(edge + 1) % n];
    const double span = at[edge + 1] - at[edge];
    const double t = span > 0 ? (target - at[edge]) / span : 0;
    r[k] = std::hypot(a.x + t * (b.x - a.x) - centre.x, a.y + t * (b.y - a.y) - centre.y);
  }
  // Only |F_0| .. |F_10| are needed: 11 direct sums cost less than a whole
  // FFT would (11 s against s log s multiply-adds, s = 128).
  double f0 = 0;
  for (double v : r) f0 += v;
  if (!(f0 > 0)) return out;
  std::vector<double> cosine(s), sine(s);
  for (int t = 0; t < s; ++t) {
    cosine[t] = std::cos(2 * kPi * t / s);
    sine[t] = std::sin(2 * kPi * t / s);
  }
  for (int k = 1; k <= kFourierCoefficients; ++k) {
    double re = 0, im = 0;
    for (int t = 0; t < s; ++t) {
      const int phase = static_cast<int>((static_cast<int64_t>(k) * t) % s);
      re += r[t] * cosine[phase];
      im -= r[t] * sine[phase];
    }
    out[k - 1] = std::hypot(re, im) / f0;
  }
  return out;
}

std::vector<Point2d> OuterContour(const BinaryImageView& image) {
  std::vector<Point2d> out;
  if (image.pixels == nullptr || image.width <= 0 || image.height <= 0) return out;
  // findContours wants a writable 8-bit image; a one-pixel border keeps
  // shapes touching the image edge closed.
  cv::Mat mask(image.height + 2, image.width + 2, CV_8U, cv::Scalar(0));
  for (int y = 0; y < image.height; ++y) {
    const uint8_t* row = image.pixels + static_cast<std::size_t>(y) * image.width;
    uint8_t* dst = mask.ptr<uint8_t>(y + 1) + 1;
    for (int x = 0; x < image.width; ++x) dst[x] = row[x] ? 1 : 0;
  }
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(mask, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
  if (contours.empty()) return out;
  std::size_t best = 0;
  double best_area = -1;
  for (std::size_t i = 0; i < contours.size(); ++i) {
    // Ties (single pixels and lines have area 0) go to the longer contour.
    const double area = std::abs(cv::contourArea(contours[i])) + 1e-9 * contours[i].size();
    if (area > best_area) {
      best_area = area;
      best = i;
    }
  }
  out.reserve(contours[best].size());
  for (const cv::Point& p : contours[best]) out.push_back({p.x - 1 + 0.5, p.y - 1 + 0.5});
  return out;
}

absl::StatusOr<std::array<double, kFourierCoefficients>> SilhouetteFourier(
    const BinaryImageView& image, const ContourFourierOptions& options) {
  const SilhouetteCentroid c = ComputeCentroid(image);
  if (c.pixels == 0) {
    if (absl::Status valid = options.Validate(); !valid.ok()) return valid;
    return std::array<double, kFourierCoefficients>{};
  }
  return CentroidDistanceFourier(OuterContour(image), {c.x, c.y}, options);
}

}  // namespace meshseek
