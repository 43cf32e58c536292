#include "common/global/zernike_moments.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace meshseek {
namespace {

constexpr double kPi = 3.14159265358979323846;

BinaryImageView View(const cv::Mat& m) { return {m.ptr<uint8_t>(0), m.cols, m.rows}; }

// A closed polygon rasterised into an n x n image, rotated by `angle`
// about (cx, cy) and scaled by `scale`.
cv::Mat Polygon(int n, const std::vector<cv::Point2d>& shape, double angle, double scale) {
  cv::Mat m(n, n, CV_8U, cv::Scalar(0));
  std::vector<cv::Point> points;
  const double c = std::cos(angle), s = std::sin(angle);
  for (const cv::Point2d& p : shape) {
    // Sub-pixel precision for fillPoly: 8 fractional bits.
    const double x = n / 2.0 + scale * (c * p.x - s * p.y),
                 y = n / 2.0 + scale * (s * p.x + c * p.y);
    points.emplace_back(static_cast<int>(std::lround(x * 256)),
                        static_cast<int>(std::lround(y * 256)));
  }
  cv::fillPoly(m, std::vector<std::vector<cv::Point>>{points}, cv::Scalar(1), cv::LINE_8, 8);
  return m;
}

// An asymmetric shape: a thick L with a notch, about 1 unit across.
std::vector<cv::Point2d> LShape() {
  return {{-0.5, -0.6}, {0.1, -0.6}, {0.1, 0.1}, {0.6, 0.1}, {0.6, 0.5}, {0.0, 0.55}, {-0.5, 0.5}};
}

TEST(ZernikeIndicesTest, ThirtyFiveOrdersUpToTenWithoutTheZeroth) {
  const auto& indices = ZernikeIndices();
  EXPECT_EQ(indices.front().n, 1);
  EXPECT_EQ(indices.front().m, 1);
  EXPECT_EQ(indices.back().n, 10);
  EXPECT_EQ(indices.back().m, 10);
  for (const ZernikeIndex& z : indices) {
    EXPECT_LE(z.m, z.n);
    EXPECT_EQ((z.n - z.m) % 2, 0);
    EXPECT_FALSE(z.n == 0);
  }
}

// A centred disc of radius rho (in unit-disc coordinates): rotationally
// symmetric, so every m > 0 moment vanishes, and A_20 / A_00 is the mean of
// 2 r^2 - 1 over the disc, 2 (rho^2 / 2) - 1.
TEST(ZernikeMagnitudesTest, DiscMatchesTheAnalyticMoments) {
  const int n = 256;
  cv::Mat disc(n, n, CV_8U, cv::Scalar(0));
  const double r = 50;
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      if (std::hypot(x + 0.5 - n / 2.0, y + 0.5 - n / 2.0) <= r) disc.at<uint8_t>(y, x) = 1;
    }
  }
  const SilhouetteCentroid c = ComputeCentroid(View(disc));
  EXPECT_NEAR(c.x, n / 2.0, 1e-9);
  EXPECT_NEAR(c.y, n / 2.0, 1e-9);
  EXPECT_NEAR(c.pixels, kPi * r * r, 2 * kPi * r);
  auto z = ZernikeMagnitudes(View(disc), c.x, c.y, 2 * r);  // rho = 1/2
  ASSERT_TRUE(z.ok()) << z.status();
  const auto& indices = ZernikeIndices();
  for (int i = 0; i < kZernikeCoefficients; ++i) {
    if (indices[i].m > 0) {
      EXPECT_NEAR((*z)[i], 0.0, 2e-3) << indices[i].n << "," << indices[i].m;
    }
    if (indices[i].n == 2 && indices[i].m == 0) {
      EXPECT_NEAR((*z)[i], 0.75, 5e-3);
    }
    EXPECT_LE((*z)[i], 1.0);
  }
  // Over the disc it fills (rho = 1), every R_n0 is orthogonal to R_00.
  auto full = ZernikeMagnitudes(View(disc), c.x, c.y, LargestRadius(View(disc), c.x, c.y));
  ASSERT_TRUE(full.ok());
  EXPECT_NEAR((*full)[1], 0.0, 0.03);  // (2, 0)
}

TEST(ZernikeMagnitudesTest, RotatedMirroredAndScaledImagesAgree) {
  const int n = 256;
  const cv::Mat base = Polygon(n, LShape(), 0.0, 150);
  auto describe = [](const cv::Mat& m) {
    const SilhouetteCentroid c = ComputeCentroid(View(m));
    return *ZernikeMagnitudes(View(m), c.x, c.y, LargestRadius(View(m), c.x, c.y));
  };
  const auto reference = describe(base);
  double largest = 0;
  for (double v : reference) largest = std::max(largest, v);
  EXPECT_GT(largest, 0.1);  // an asymmetric shape has sizeable moments
  cv::Mat mirrored;
  cv::flip(base, mirrored, 1);
  for (const cv::Mat& other : {Polygon(n, LShape(), 0.7, 150),
                               Polygon(n, LShape(), 2.9, 150),
                               Polygon(n, LShape(), 1.3, 110),
                               mirrored}) {
    const auto z = describe(other);
    for (int i = 0; i < kZernikeCoefficients; ++i) EXPECT_NEAR(z[i], reference[i], 0.01) << i;
  }
  // A different shape differs by far more than that.
  const auto square =
      describe(Polygon(n, {{-0.5, -0.5}, {0.5, -0.5}, {0.5, 0.5}, {-0.5, 0.5}}, 0, 150));
  double diff = 0;
  for (int i = 0; i < kZernikeCoefficients; ++i)
    diff = std::max(diff, std::abs(square[i] - reference[i]));
  EXPECT_GT(diff, 0.05);
}

TEST(ZernikeMagnitudesTest, EmptyImageGivesZerosAndBadInputIsRejected) {
  cv::Mat empty(64, 64, CV_8U, cv::Scalar(0));
  auto z = ZernikeMagnitudes(View(empty), 32, 32, 10);
  ASSERT_TRUE(z.ok());
  for (double v : *z) EXPECT_EQ(v, 0.0);
  EXPECT_EQ(ComputeCentroid(View(empty)).pixels, 0);
  EXPECT_EQ(LargestRadius(View(empty), 32, 32), 0.0);
  EXPECT_EQ(ZernikeMagnitudes(View(empty), 32, 32, 0).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(ZernikeMagnitudes(View(empty), 32, 32, std::nan("")).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(ZernikeMagnitudes(BinaryImageView{}, 0, 0, 1).status().code(),
            absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace meshseek
