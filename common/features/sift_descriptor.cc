#include "common/features/sift_descriptor.h"

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <vector>

#include "absl/strings/str_cat.h"

namespace meshseek {

absl::Status SiftDescriptorOptions::Validate() const {
  if (max_orientations < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("max_orientations must be >= 0, got ", max_orientations));
  }
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

double DescriptorDistance(const uint8_t* a, const uint8_t* b) {
  double sum = 0;
  for (int k = 0; k < kSiftDimension; ++k) {
    const double d = static_cast<double>(a[k]) - b[k];
    sum += d * d;
  }
  return std::sqrt(sum);
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
  // Only sigma matters when describing keypoints of octave 0, layer 0; the
  // rest are OpenCV's detection defaults. (OpenCV still builds the octave's
  // other layers; fewer layers means coarser steps and longer blur kernels,
  // measured slower.)
  impl_->sift = cv::SIFT::create(0, 3, 0.04, 10, options.blur_sigma);
}

DepthSiftDescriber::~DepthSiftDescriber() = default;

std::vector<float> DominantOrientations(const DepthImage& image, float peak_ratio) {
  constexpr int kBins = 36;
  const int size = image.size;
  const float centre = (size - 1) / 2.0f;
  const float sigma = 0.4f * size;  // most of the image, centre first
  float hist[kBins] = {};
  for (int r = 1; r + 1 < size; ++r) {
    for (int c = 1; c + 1 < size; ++c) {
      const float dx = image.at(r, c + 1) - image.at(r, c - 1);
      const float dy = image.at(r - 1, c) - image.at(r + 1, c);  // y up
      const float magnitude = std::sqrt(dx * dx + dy * dy);
      if (magnitude <= 0) continue;
      const float d2 = (r - centre) * (r - centre) + (c - centre) * (c - centre);
      float angle = std::atan2(dy, dx) * static_cast<float>(180.0 / M_PI);
      if (angle < 0) angle += 360.0f;
      const int bin = static_cast<int>(angle * kBins / 360.0f) % kBins;
      hist[bin] += magnitude * std::exp(-d2 / (2 * sigma * sigma));
    }
  }
  float smooth[kBins];
  for (int b = 0; b < kBins; ++b) {  // [1 4 6 4 1] / 16, circular, as OpenCV's SIFT
    auto h = [&](int k) { return hist[(k + kBins) % kBins]; };
    smooth[b] = (h(b - 2) + h(b + 2)) / 16 + (h(b - 1) + h(b + 1)) * 4 / 16 + h(b) * 6 / 16;
  }
  const float highest = *std::max_element(smooth, smooth + kBins);
  std::vector<std::pair<float, float>> peaks;  // (height, angle)
  if (!(highest > 0)) return {};
  for (int b = 0; b < kBins; ++b) {
    const float left = smooth[(b + kBins - 1) % kBins], right = smooth[(b + 1) % kBins];
    if (smooth[b] > left && smooth[b] > right && smooth[b] >= peak_ratio * highest) {
      const float offset = 0.5f * (left - right) / (left - 2 * smooth[b] + right);
      const float angle = (b + 0.5f + offset) * 360.0f / kBins;
      peaks.emplace_back(smooth[b], std::fmod(angle + 360.0f, 360.0f));
    }
  }
  std::stable_sort(
      peaks.begin(), peaks.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<float> angles;
  for (const auto& peak : peaks) angles.push_back(peak.second);
  return angles;
}

int DepthSiftDescriber::Describe(const DepthImage& image, std::vector<uint8_t>* out) {
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
  const float keypoint_size = size / 6.0f;
  impl_->keypoints.clear();
  const bool up_axis = impl_->options.orientation == ImageOrientation::kUpAxis;
  if (up_axis) {
    impl_->keypoints.emplace_back(centre, centre, keypoint_size, 0.0f);
  } else {
    // OpenCV's keypoint angle is clockwise (image y points down): 360 - theta.
    std::vector<float> thetas = DominantOrientations(image);
    if (impl_->options.max_orientations > 0 &&
        static_cast<int>(thetas.size()) > impl_->options.max_orientations) {
      thetas.resize(impl_->options.max_orientations);
    }
    for (const float theta : thetas) {
      const float angle = 360.0f - theta;
      impl_->keypoints.emplace_back(centre, centre, keypoint_size, angle >= 360.0f ? 0.0f : angle);
    }
    // A flat image has no orientation; describe it upright (all zeros anyway).
    if (impl_->keypoints.empty())
      impl_->keypoints.emplace_back(centre, centre, keypoint_size, 0.0f);
  }
  impl_->sift->compute(gray, impl_->keypoints, impl_->descriptors);
  if (impl_->descriptors.cols != kSiftDimension) return 0;
  float bins[kSiftDimension];
  for (int row = 0; row < impl_->descriptors.rows; ++row) {
    const float* raw = impl_->descriptors.ptr<float>(row);
    const bool sum_turned = up_axis && impl_->options.symmetrize_180;
    for (int k = 0; k < kSiftDimension; ++k)
      bins[k] = raw[k] + (sum_turned ? raw[Rotate180Index(k)] : 0.0f);
    const std::size_t at = out->size();
    out->resize(at + kSiftDimension);
    NormalizeSiftDescriptor(bins, out->data() + at);
  }
  return impl_->descriptors.rows;
}

}  // namespace meshseek
