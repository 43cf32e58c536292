#include "common/features/sift_descriptor.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>

#include "absl/strings/str_cat.h"

namespace meshseek {

absl::Status SiftDescriptorOptions::Validate() const {
  if (!(blur_sigma >= 0.5 && blur_sigma <= 5)) {
    return absl::InvalidArgumentError(
        absl::StrCat("SIFT blur_sigma must be in [0.5, 5] pixels, got ", blur_sigma));
  }
  return absl::OkStatus();
}

int Rotate180Index(int bin) {
  const int cell = bin / 8, orientation = bin % 8;
  const int row = cell / 4, col = cell % 4;
  return ((3 - row) * 4 + (3 - col)) * 8 + (orientation + 4) % 8;
}

void NormalizeSiftDescriptor(float* bins, uint8_t* out) {
  auto normalize = [bins] {
    double sq = 0;
    for (int k = 0; k < kSiftDimension; ++k) sq += static_cast<double>(bins[k]) * bins[k];
    const float inv = sq > 0 ? static_cast<float>(1.0 / std::sqrt(sq)) : 0.0f;
    for (int k = 0; k < kSiftDimension; ++k) bins[k] *= inv;
  };
  normalize();
  for (int k = 0; k < kSiftDimension; ++k) bins[k] = std::min(bins[k], 0.2f);
  normalize();
  for (int k = 0; k < kSiftDimension; ++k) {
    out[k] = static_cast<uint8_t>(std::min(255.0f, std::round(bins[k] * 512.0f)));
  }
}

struct DepthSiftDescriber::Impl {
  SiftDescriptorOptions options;
  cv::Ptr<cv::SIFT> sift;
  cv::Mat gray;
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
};

DepthSiftDescriber::DepthSiftDescriber(const SiftDescriptorOptions& options)
    : impl_(std::make_unique<Impl>()) {
  impl_->options = options;
  // Only sigma matters when describing given keypoints; the others are
  // OpenCV's detection defaults.
  impl_->sift = cv::SIFT::create(0, 3, 0.04, 10, options.blur_sigma);
}

DepthSiftDescriber::~DepthSiftDescriber() = default;

bool DepthSiftDescriber::Describe(const DepthImage& image, uint8_t* out) {
  const int size = image.size;
  cv::Mat& gray = impl_->gray;
  gray.create(size, size, CV_8U);
  float lo = 0, hi = 2 * image.support_radius;
  if (impl_->options.depth_to_gray == DepthToGray::kStretch) {
    const auto [mn, mx] = std::minmax_element(image.depth.begin(), image.depth.end());
    lo = *mn;
    hi = *mx;
  }
  const float scale = hi > lo ? 255.0f / (hi - lo) : 0.0f;
  for (int r = 0; r < size; ++r) {
    uint8_t* row = gray.ptr<uint8_t>(r);
    for (int c = 0; c < size; ++c) {
      const float g = (image.at(r, c) - lo) * scale;
      row[c] = static_cast<uint8_t>(std::clamp(std::lround(g), 0L, 255L));
    }
  }
  const float centre = static_cast<float>(size / 2);
  impl_->keypoints.assign(1, cv::KeyPoint(centre, centre, size / 6.0f, 0.0f));
  impl_->sift->compute(gray, impl_->keypoints, impl_->descriptors);
  if (impl_->descriptors.rows != 1 || impl_->descriptors.cols != kSiftDimension) return false;
  const float* raw = impl_->descriptors.ptr<float>(0);
  float bins[kSiftDimension];
  for (int k = 0; k < kSiftDimension; ++k) {
    bins[k] = raw[k] + (impl_->options.symmetrize_180 ? raw[Rotate180Index(k)] : 0.0f);
  }
  NormalizeSiftDescriptor(bins, out);
  return true;
}

}  // namespace meshseek
