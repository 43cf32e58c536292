#include "common/global/contour_fourier.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace meshseek {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A five-pointed star-like polygon, lopsided so that several harmonics
// matter.
std::vector<Point2d> Star(double angle, double scale, Point2d shift, int start) {
  std::vector<Point2d> out;
  const int k = 10;
  for (int i = 0; i < k; ++i) {
    const double t = 2 * kPi * ((i + start) % k) / k;
    const double r = (i + start) % 2 ? 0.45 : 1.0 + 0.2 * std::cos(t);
    const double x = r * std::cos(t), y = r * std::sin(t);
    out.push_back({shift.x + scale * (std::cos(angle) * x - std::sin(angle) * y),
                   shift.y + scale * (std::sin(angle) * x + std::cos(angle) * y)});
  }
  return out;
}

TEST(ContourFourierOptionsTest, DefaultsArePinnedAndValid) {
  const ContourFourierOptions options;
  EXPECT_EQ(options.samples, 128);
  EXPECT_TRUE(options.Validate().ok());
  ContourFourierOptions bad;
  bad.samples = 20;
  EXPECT_EQ(bad.Validate().code(), absl::StatusCode::kInvalidArgument);
}

TEST(CentroidDistanceFourierTest, PolygonIsRotationScaleAndStartPointInvariant) {
  const ContourFourierOptions options;
  const auto reference = *CentroidDistanceFourier(Star(0, 1, {0, 0}, 0), {0, 0}, options);
  double largest = 0;
  for (double v : reference) largest = std::max(largest, v);
  EXPECT_GT(largest, 0.1);
  // Rotation, scale and translation of polygon and centre together: the
  // samples land on the same arc-length fractions, exactly.
  const auto moved = *CentroidDistanceFourier(Star(1.1, 3.5, {7, -2}, 0), {7, -2}, options);
  for (int k = 0; k < kFourierCoefficients; ++k) EXPECT_NEAR(moved[k], reference[k], 1e-9) << k;
  // Starting elsewhere on the contour, or running the other way: only the
  // phases change, up to resampling (a fraction of a step).
  const auto restarted = *CentroidDistanceFourier(Star(0, 1, {0, 0}, 3), {0, 0}, options);
  std::vector<Point2d> reversed = Star(0, 1, {0, 0}, 0);
  std::reverse(reversed.begin(), reversed.end());
  const auto backwards = *CentroidDistanceFourier(reversed, {0, 0}, options);
  for (int k = 0; k < kFourierCoefficients; ++k) {
    EXPECT_NEAR(restarted[k], reference[k], 5e-3) << k;
    EXPECT_NEAR(backwards[k], reference[k], 5e-3) << k;
  }
}

TEST(CentroidDistanceFourierTest, CircleHasNoHarmonicsAndEllipseAnEvenOne) {
  std::vector<Point2d> circle, ellipse;
  for (int i = 0; i < 400; ++i) {
    const double t = 2 * kPi * i / 400;
    circle.push_back({std::cos(t), std::sin(t)});
    ellipse.push_back({2 * std::cos(t), std::sin(t)});
  }
  const auto c = *CentroidDistanceFourier(circle, {0, 0}, {});
  for (double v : c) EXPECT_NEAR(v, 0.0, 1e-9);
  const auto e = *CentroidDistanceFourier(ellipse, {0, 0}, {});
  EXPECT_GT(e[1], 0.1);          // k = 2: twice per turn
  EXPECT_NEAR(e[0], 0.0, 1e-9);  // odd harmonics vanish by symmetry
  EXPECT_NEAR(e[2], 0.0, 1e-9);
}

TEST(CentroidDistanceFourierTest, DegenerateContoursGiveZeros) {
  for (const std::vector<Point2d>& contour : {std::vector<Point2d>{},
                                              std::vector<Point2d>{{1, 1}, {2, 2}},
                                              std::vector<Point2d>{{1, 1}, {1, 1}, {1, 1}},
                                              std::vector<Point2d>{{0, 0}, {0, 0}, {0, 0}}}) {
    auto f = CentroidDistanceFourier(contour, {0, 0}, {});
    ASSERT_TRUE(f.ok());
    for (double v : *f) EXPECT_EQ(v, 0.0);
  }
}

TEST(SilhouetteFourierTest, RasterisedRotatedPolygonsAgree) {
  auto raster = [](double angle, double scale) {
    const int n = 256;
    cv::Mat m(n, n, CV_8U, cv::Scalar(0));
    std::vector<cv::Point> pts;
    for (const Point2d& p : Star(angle, scale, {n / 2.0, n / 2.0}, 0)) {
      pts.emplace_back(static_cast<int>(std::lround(p.x * 256)),
                       static_cast<int>(std::lround(p.y * 256)));
    }
    cv::fillPoly(m, std::vector<std::vector<cv::Point>>{pts}, cv::Scalar(1), cv::LINE_8, 8);
    // A stray speck elsewhere: the largest piece's contour is the one used.
    m.at<uint8_t>(3, 3) = 1;
    return m;
  };
  const ContourFourierOptions options;
  const cv::Mat a = raster(0, 100);
  const auto reference = *SilhouetteFourier({a.ptr<uint8_t>(0), a.cols, a.rows}, options);
  for (const auto& [angle, scale] :
       std::vector<std::pair<double, double>>{{0.5, 100}, {2.0, 80}, {4.0, 120}}) {
    const cv::Mat b = raster(angle, scale);
    const auto f = *SilhouetteFourier({b.ptr<uint8_t>(0), b.cols, b.rows}, options);
    for (int k = 0; k < kFourierCoefficients; ++k) EXPECT_NEAR(f[k], reference[k], 0.02) << k;
  }
  cv::Mat empty(32, 32, CV_8U, cv::Scalar(0));
  const auto none = *SilhouetteFourier({empty.ptr<uint8_t>(0), 32, 32}, options);
  for (double v : none) EXPECT_EQ(v, 0.0);
  EXPECT_TRUE(OuterContour({empty.ptr<uint8_t>(0), 32, 32}).empty());
}

}  // namespace
}  // namespace meshseek
