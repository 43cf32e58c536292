#include "common/features/sift_descriptor.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "common/base/cpu_features.h"

namespace meshseek {
namespace {

// OpenCV's SIFT constants (sift.simd.hpp).
constexpr int kCells = 4;             // SIFT_DESCR_WIDTH
constexpr int kOrientationBins = 8;   // SIFT_DESCR_HIST_BINS
constexpr float kCellSigmas = 3.0f;   // SIFT_DESCR_SCL_FCTR
constexpr float kClip = 0.2f;         // SIFT_DESCR_MAG_THR
constexpr float kByteScale = 512.0f;  // SIFT_INT_DESCR_FCTR
constexpr float kInputBlur = 0.5f;    // SIFT_INIT_SIGMA
// The padded histogram of calcSIFTDescriptor: one spare cell on each side of
// each spatial axis and two spare orientation bins, so that the trilinear
// update needs no bounds checks.
constexpr int kPaddedCells = kCells + 2;
constexpr int kPaddedBins = kOrientationBins + 2;
constexpr int kHistogramSize = kPaddedCells * kPaddedCells * kPaddedBins;

// atan2 in degrees, [0, 360], by OpenCV's polynomial (cv::fastAtan2; error
// about 0.01 degree): several times faster than std::atan2, and the same
// angles OpenCV's descriptor saw. Written with selects rather than branches:
// the octant of a gradient is unpredictable.
inline float FastAtan2Degrees(float y, float x) {
  constexpr float kP1 = 0.9997878412794807f * static_cast<float>(180 / M_PI);
  constexpr float kP3 = -0.3258083974640975f * static_cast<float>(180 / M_PI);
  constexpr float kP5 = 0.1555786518463281f * static_cast<float>(180 / M_PI);
  constexpr float kP7 = -0.04432655554792128f * static_cast<float>(180 / M_PI);
  constexpr float kEps = static_cast<float>(DBL_EPSILON);
  const float ax = std::abs(x), ay = std::abs(y);
  const bool steep = ay > ax;
  const float c = (steep ? ax : ay) / ((steep ? ay : ax) + kEps), c2 = c * c;
  const float p = (((kP7 * c2 + kP5) * c2 + kP3) * c2 + kP1) * c;
  float a = steep ? 90.0f - p : p;
  a = x < 0 ? 180.0f - a : a;
  return y < 0 ? 360.0f - a : a;
}

// out[c] = sum_k kernel[k] tap[k][c] for c < width (a multiple of 16), summed
// in tap order from 0 as a row-at-a-time accumulation would: each 16 columns
// stay in registers over the taps instead of going through memory per tap.
MESHSEEK_TARGET_CLONES_AVX void WeightedRowSum(int taps,
                                               const float* __restrict kernel,
                                               const float* const* __restrict tap,
                                               int width,
                                               float* __restrict out) {
  for (int c0 = 0; c0 < width; c0 += 16) {
    float sum[16] = {};
    for (int k = 0; k < taps; ++k) {
      const float w = kernel[k];
      const float* __restrict in = tap[k] + c0;
      for (int j = 0; j < 16; ++j) sum[j] += w * in[j];
    }
    for (int j = 0; j < 16; ++j) out[c0 + j] = sum[j];
  }
}

// cv::borderInterpolate with BORDER_REFLECT_101 (GaussianBlur's default):
// ... 2 1 | 0 1 2 ... n-1 | n-2 n-3 ...
int Reflect101(int p, int n) {
  if (n == 1) return 0;
  while (p < 0 || p >= n) p = p < 0 ? -p : 2 * n - 2 - p;
  return p;
}

constexpr int kOrientationHistogramBins = 36;

// Gradient magnitude and orientation-histogram bin of every interior pixel of
// `image` (row-major, image-sized; what the border columns get is never
// read): the vectorisable half of FindDominantOrientations, compiled wider
// like ComputeSamples.
MESHSEEK_TARGET_CLONES_AVX void OrientationGradients(const DepthImage& image,
                                                     float* __restrict magnitude,
                                                     int* __restrict bin) {
  constexpr int kBins = kOrientationHistogramBins;
  const int size = image.size;
  const float* __restrict depth = image.depth.data();
  // Rows 1 .. size - 2 as one flat array: the border columns' values (which
  // wrap around a row's ends) are computed too and never read.
  for (int i = size, end = (size - 1) * size; i < end; ++i) {
    const float dx = depth[i + 1] - depth[i - 1];
    const float dy = depth[i - size] - depth[i + size];  // y up
    magnitude[i] = std::sqrt(dx * dx + dy * dy);
    bin[i] = static_cast<int>(FastAtan2Degrees(dy, dx) * kBins / 360.0f) % kBins;
  }
}

// Lowe's dominant orientations (see DominantOrientations) with the Gaussian
// weight of each pixel given (row-major, image-sized), into `angles`;
// `magnitude` and `bin` are image-sized scratch.
void FindDominantOrientations(const DepthImage& image,
                              const float* weight,
                              float peak_ratio,
                              std::vector<float>* magnitude,
                              std::vector<int>* bin,
                              std::vector<float>* angles) {
  constexpr int kBins = kOrientationHistogramBins;
  const int size = image.size;
  angles->clear();
  magnitude->resize(image.depth.size());
  bin->resize(image.depth.size());
  OrientationGradients(image, magnitude->data(), bin->data());
  float hist[kBins] = {};
  // Summed in pixel order, as one pass computing the gradients would.
  for (int r = 1; r + 1 < size; ++r) {
    const std::size_t at = static_cast<std::size_t>(r) * size;
    const float* m = magnitude->data() + at;
    const int* b = bin->data() + at;
    const float* w = weight + at;
    for (int c = 1; c + 1 < size; ++c) {
      if (!(m[c] <= 0)) hist[b[c]] += m[c] * w[c];
    }
  }
  float smooth[kBins];
  for (int b = 0; b < kBins; ++b) {  // [1 4 6 4 1] / 16, circular, as OpenCV's SIFT
    auto h = [&](int k) { return hist[(k + kBins) % kBins]; };
    smooth[b] = (h(b - 2) + h(b + 2)) / 16 + (h(b - 1) + h(b + 1)) * 4 / 16 + h(b) * 6 / 16;
  }
  const float highest = *std::max_element(smooth, smooth + kBins);
  if (!(highest > 0)) return;
  std::pair<float, float> peaks[kBins];  // (height, angle)
  int num_peaks = 0;
  for (int b = 0; b < kBins; ++b) {
    const float left = smooth[(b + kBins - 1) % kBins], right = smooth[(b + 1) % kBins];
    if (smooth[b] > left && smooth[b] > right && smooth[b] >= peak_ratio * highest) {
      const float offset = 0.5f * (left - right) / (left - 2 * smooth[b] + right);
      const float angle = (b + 0.5f + offset) * 360.0f / kBins;
      peaks[num_peaks++] = {smooth[b], std::fmod(angle + 360.0f, 360.0f)};
    }
  }
  std::stable_sort(
      peaks, peaks + num_peaks, [](const auto& a, const auto& b) { return a.first > b.first; });
  for (int k = 0; k < num_peaks; ++k) angles->push_back(peaks[k].second);
}

// The centred Gaussian of DominantOrientations, sigma 0.4 I: most of the
// image, centre first.
void OrientationWeights(int size, std::vector<float>* weight) {
  const float centre = (size - 1) / 2.0f;
  const float sigma = 0.4f * size;
  weight->resize(static_cast<std::size_t>(size) * size);
  for (int r = 0; r < size; ++r) {
    for (int c = 0; c < size; ++c) {
      const float d2 = (r - centre) * (r - centre) + (c - centre) * (c - centre);
      (*weight)[static_cast<std::size_t>(r) * size + c] = std::exp(-d2 / (2 * sigma * sigma));
    }
  }
}

}  // namespace

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
    // Rounded half up (the bins are non-negative), saturated.
    out[k] = static_cast<uint8_t>(std::min(255.0f, bins[k] * 512.0f + 0.5f));
  }
}

std::vector<float> DominantOrientations(const DepthImage& image, float peak_ratio) {
  std::vector<float> weight, magnitude, angles;
  std::vector<int> bin;
  OrientationWeights(image.size, &weight);
  FindDominantOrientations(image, weight.data(), peak_ratio, &magnitude, &bin, &angles);
  return angles;
}

DepthSiftDescriber::DepthSiftDescriber(const SiftDescriptorOptions& options)
    : options_(options) {
  // The blur is what cv::GaussianBlur applies to build the base of SIFT's
  // pyramid (createInitialImage without upscaling): the input is assumed to
  // carry 0.5 pixel of blur already; the kernel size is OpenCV's automatic
  // one for float images (8 sigma + 1, odd).
  const float sigma = static_cast<float>(options.blur_sigma);
  const float blur = std::sqrt(std::max(sigma * sigma - kInputBlur * kInputBlur, 0.01f));
  const int taps = static_cast<int>(std::lround(blur * 4 * 2 + 1)) | 1;
  blur_radius_ = taps / 2;
  std::vector<double> kernel(taps);
  double sum = 0;
  for (int k = 0; k < taps; ++k) {
    const double x = k - blur_radius_;
    kernel[k] = std::exp(-x * x / (2.0 * blur * blur));
    sum += kernel[k];
  }
  for (const double k : kernel) kernel_.push_back(static_cast<float>(k / sum));
  tap_rows_.resize(taps);
}

void DepthSiftDescriber::Prepare(int size) {
  if (size == size_) return;
  size_ = size;
  // Rows of the working images are padded to whole 512-bit vectors (16
  // floats), so that every loop over a row, or over the image as one flat
  // array, runs in whole vectors; padding is finite and weighs nothing.
  stride_ = (size + 15) / 16 * 16;
  const std::size_t pixels = static_cast<std::size_t>(size) * stride_;
  const int padded = size + 2 * blur_radius_;
  border_.resize(padded);
  for (int p = 0; p < padded; ++p) border_[p] = Reflect101(p - blur_radius_, size);
  // The descriptor window's Gaussian: sigma = half the window (2 cells) in
  // cell units, cells of 3 keypoint sigmas, keypoint sigma I / 12. Zero off
  // the interior: border pixels have no central difference, padding no pixel.
  const float cell = kCellSigmas * (size / 12.0f);
  const float scale = -1.0f / (kCells * kCells * 0.5f) / (cell * cell);
  const int centre = size / 2;
  window_weight_.assign(pixels, 0.0f);
  for (int r = 1; r + 1 < size; ++r) {
    for (int c = 1; c + 1 < size; ++c) {
      const float d2 = static_cast<float>((r - centre) * (r - centre) + (c - centre) * (c - centre));
      window_weight_[static_cast<std::size_t>(r) * stride_ + c] = std::exp(d2 * scale);
    }
  }
  OrientationWeights(size, &orientation_weight_);
  gray_.assign(pixels, 0.0f);
  rows_.assign(pixels, 0.0f);
  blurred_.assign(pixels, 0.0f);
  padded_.assign(stride_ + 2 * blur_radius_, 0.0f);
  // One sample per pixel of rows 1 .. size - 2, row by row, padding
  // included: calcSIFTDescriptor's window (radius 0.88 I) always covers the
  // whole image, and only interior pixels have a weight (so a gradient). The
  // offsets are fixed; ComputeSamples fills in the gradients.
  sample_row_.clear();
  sample_col_.clear();
  for (int r = 1; r + 1 < size; ++r) {
    for (int c = 0; c < stride_; ++c) {
      sample_row_.push_back(static_cast<float>(r - centre));
      sample_col_.push_back(static_cast<float>(c - centre));
    }
  }
  const std::size_t samples = sample_row_.size();
  sample_orientation_.assign(samples, 0.0f);
  sample_magnitude_.assign(samples, 0.0f);
  sample_offset_.assign(samples, 0);
  for (auto& weights : sample_weights_) weights.assign(samples, 0.0f);
}

// Compiled for AVX-512 and AVX2 as well, picked at run time: the blur and
// gradient loops vectorise wider, with the same operations per lane.
MESHSEEK_TARGET_CLONES_AVX void
DepthSiftDescriber::ComputeSamples(const DepthImage& image) {
  const int size = size_, stride = stride_;
  float lo = 0, hi = 2 * image.support_radius;
  if (options_.depth_to_gray == DepthToGray::kStretch) {
    const auto [mn, mx] = std::minmax_element(image.depth.begin(), image.depth.end());
    lo = *mn;
    hi = *mx;
  }
  const float scale = hi > lo ? 255.0f / (hi - lo) : 0.0f;
  for (int r = 0; r < size; ++r) {
    const float* __restrict in = &image.depth[static_cast<std::size_t>(r) * size];
    float* __restrict gray = &gray_[static_cast<std::size_t>(r) * stride];
    for (int c = 0; c < size; ++c) {
      // Rounded half up, as std::lround for these non-negative values.
      const float g = std::clamp((in[c] - lo) * scale, 0.0f, 255.0f);
      gray[c] = static_cast<float>(static_cast<int>(g + 0.5f));
    }
  }
  // Separable blur, rows then columns, borders reflected as OpenCV does.
  const int taps = static_cast<int>(kernel_.size());
  const float** tap = tap_rows_.data();
  for (int r = 0; r < size; ++r) {
    const float* in = &gray_[static_cast<std::size_t>(r) * stride];
    for (std::size_t p = 0; p < border_.size(); ++p) padded_[p] = in[border_[p]];
    for (int k = 0; k < taps; ++k) tap[k] = &padded_[k];
    WeightedRowSum(taps, kernel_.data(), tap, stride, &rows_[static_cast<std::size_t>(r) * stride]);
  }
  for (int r = 0; r < size; ++r) {
    for (int k = 0; k < taps; ++k) tap[k] = &rows_[static_cast<std::size_t>(border_[r + k]) * stride];
    WeightedRowSum(taps, kernel_.data(), tap, stride, &blurred_[static_cast<std::size_t>(r) * stride]);
  }
  // Gradients of rows 1 .. size - 2 as one flat array (see Prepare): what
  // wraps around a row's ends lands on a border or padding pixel, weight 0.
  const float* __restrict blurred = blurred_.data();
  const float* __restrict weight = window_weight_.data();
  float* __restrict orientation = sample_orientation_.data();
  float* __restrict magnitude = sample_magnitude_.data();
  const int first = stride, end = (size - 1) * stride;
  for (int i = first; i < end; ++i) {
    const float dx = blurred[i + 1] - blurred[i - 1];
    const float dy = blurred[i - stride] - blurred[i + stride];  // y up
    orientation[i - first] = FastAtan2Degrees(dy, dx);
    magnitude[i - first] = std::sqrt(dx * dx + dy * dy) * weight[i];
  }
}

namespace {

// Where each of `n` gradient samples lands in the padded histogram, and its
// eight trilinear weights, for orientation `degrees`, in OpenCV's order of
// operations; offset -1 for a sample outside the window or without gradient
// (whose weights are +0: adding them would change no bin). Each sample on
// its own, so it vectorises (compiled wider like ComputeSamples; a free
// function because GCC honours __restrict on parameters, not on locals).
MESHSEEK_TARGET_CLONES_AVX void BinSamplesKernel(int n,
                                                 float degrees,
                                                 float cos_t,
                                                 float sin_t,
                                                 const float* __restrict row,
                                                 const float* __restrict col,
                                                 const float* __restrict orientation,
                                                 const float* __restrict magnitude,
                                                 int* __restrict offset,
                                                 float* __restrict w000,
                                                 float* __restrict w001,
                                                 float* __restrict w010,
                                                 float* __restrict w011,
                                                 float* __restrict w100,
                                                 float* __restrict w101,
                                                 float* __restrict w110,
                                                 float* __restrict w111) {
  constexpr float kBinsPerDegree = kOrientationBins / 360.0f;
  for (int i = 0; i < n; ++i) {
    // Histogram coordinates of the sample, rotated by the orientation;
    // - 0.5 so that a sample at the centre of a cell lands there with full
    // weight after interpolation.
    const float c_rot = col[i] * cos_t - row[i] * sin_t;
    const float r_rot = col[i] * sin_t + row[i] * cos_t;
    float rbin = r_rot + kCells / 2 - 0.5f;
    float cbin = c_rot + kCells / 2 - 0.5f;
    float obin = (orientation[i] - degrees) * kBinsPerDegree;
    // Floors by truncation of shifted values: rbin, cbin > -1 (inside the
    // window; outside the sample is dropped) and obin in (-8, 8] (both
    // angles in [0, 360]).
    const int r0 = static_cast<int>(rbin + 1.0f) - 1;
    const int c0 = static_cast<int>(cbin + 1.0f) - 1;
    const int o0_unwrapped = static_cast<int>(obin + kOrientationBins) - kOrientationBins;
    int o0 = o0_unwrapped;
    o0 += o0 < 0 ? kOrientationBins : 0;
    o0 -= o0 >= kOrientationBins ? kOrientationBins : 0;
    // Selects on 32-bit values only (a bool would make the loop's vectors
    // bytes wide, and it stays scalar).
    int at = ((r0 + 1) * kPaddedCells + c0 + 1) * kPaddedBins + o0;
    at = rbin > -1 ? at : -1;
    at = rbin < kCells ? at : -1;
    at = cbin > -1 ? at : -1;
    at = cbin < kCells ? at : -1;
    const float mag = magnitude[i];
    offset[i] = mag != 0 ? at : -1;
    rbin -= r0;
    cbin -= c0;
    obin -= o0_unwrapped;
    const float v_r1 = mag * rbin, v_r0 = mag - v_r1;
    const float v_rc11 = v_r1 * cbin, v_rc10 = v_r1 - v_rc11;
    const float v_rc01 = v_r0 * cbin, v_rc00 = v_r0 - v_rc01;
    const float v_rco111 = v_rc11 * obin, v_rco110 = v_rc11 - v_rco111;
    const float v_rco101 = v_rc10 * obin, v_rco100 = v_rc10 - v_rco101;
    const float v_rco011 = v_rc01 * obin, v_rco010 = v_rc01 - v_rco011;
    const float v_rco001 = v_rc00 * obin, v_rco000 = v_rc00 - v_rco001;
    w000[i] = v_rco000;
    w001[i] = v_rco001;
    w010[i] = v_rco010;
    w011[i] = v_rco011;
    w100[i] = v_rco100;
    w101[i] = v_rco101;
    w110[i] = v_rco110;
    w111[i] = v_rco111;
  }
}

}  // namespace

void DepthSiftDescriber::BinSamples(float degrees) {
  const float cell = kCellSigmas * (size_ / 12.0f);
  const float radians = degrees * static_cast<float>(M_PI / 180);
  const float cos_t = std::cos(radians) / cell, sin_t = std::sin(radians) / cell;
  std::vector<float>* w = sample_weights_;
  BinSamplesKernel(static_cast<int>(sample_row_.size()), degrees, cos_t, sin_t,
                   sample_row_.data(), sample_col_.data(), sample_orientation_.data(),
                   sample_magnitude_.data(), sample_offset_.data(), w[0].data(), w[1].data(),
                   w[2].data(), w[3].data(), w[4].data(), w[5].data(), w[6].data(), w[7].data());
}

void DepthSiftDescriber::DescribeAt(float degrees, float* bins) {
  BinSamples(degrees);
  float hist[kHistogramSize] = {};
  const int n = static_cast<int>(sample_offset_.size());
  const int* offset = sample_offset_.data();
  const float* w[8];
  for (int k = 0; k < 8; ++k) w[k] = sample_weights_[k].data();
  for (int i = 0; i < n; ++i) {
    if (offset[i] < 0) continue;
    // Trilinear interpolation, in OpenCV's order of operations.
    float* h = hist + offset[i];
    h[0] += w[0][i];
    h[1] += w[1][i];
    h[kPaddedBins] += w[2][i];
    h[kPaddedBins + 1] += w[3][i];
    h[kPaddedCells * kPaddedBins] += w[4][i];
    h[kPaddedCells * kPaddedBins + 1] += w[5][i];
    h[(kPaddedCells + 1) * kPaddedBins] += w[6][i];
    h[(kPaddedCells + 1) * kPaddedBins + 1] += w[7][i];
  }
  // Orientation histograms are circular: fold the spare bins back.
  for (int i = 0; i < kCells; ++i) {
    for (int j = 0; j < kCells; ++j) {
      float* h = hist + ((i + 1) * kPaddedCells + j + 1) * kPaddedBins;
      h[0] += h[kOrientationBins];
      h[1] += h[kOrientationBins + 1];
      std::copy(h, h + kOrientationBins, bins + (i * kCells + j) * kOrientationBins);
    }
  }
  // OpenCV's normalisation: clip at 0.2 of the norm, scale to 512 / norm of
  // the clipped vector, round to bytes.
  float norm2 = 0;
  for (int k = 0; k < kSiftDimension; ++k) norm2 += bins[k] * bins[k];
  const float threshold = std::sqrt(norm2) * kClip;
  norm2 = 0;
  for (int k = 0; k < kSiftDimension; ++k) {
    bins[k] = std::min(bins[k], threshold);
    norm2 += bins[k] * bins[k];
  }
  const float factor = kByteScale / std::max(std::sqrt(norm2), FLT_EPSILON);
  for (int k = 0; k < kSiftDimension; ++k) {
    bins[k] = static_cast<float>(std::clamp(std::lrint(bins[k] * factor), 0L, 255L));
  }
}

int DepthSiftDescriber::Describe(const DepthImage& image, std::vector<uint8_t>* out) {
  Prepare(image.size);
  ComputeSamples(image);
  const bool up_axis = options_.orientation == ImageOrientation::kUpAxis;
  angles_.clear();
  if (!up_axis) {
    FindDominantOrientations(
        image, orientation_weight_.data(), 0.8f, &orientation_magnitude_, &orientation_bin_, &angles_);
    if (options_.max_orientations > 0 &&
        static_cast<int>(angles_.size()) > options_.max_orientations) {
      angles_.resize(options_.max_orientations);
    }
  }
  // The up axis, or a flat image without orientation: upright.
  if (angles_.empty()) angles_.push_back(0.0f);
  const bool sum_turned = up_axis && options_.symmetrize_180;
  float raw[kSiftDimension], bins[kSiftDimension];
  for (const float angle : angles_) {
    DescribeAt(angle, raw);
    // The byte-valued result is normalised once more (and, for LD-SIFT,
    // summed with its 180-degree turn first), as the descriptors OpenCV
    // returned were when the settings were measured.
    for (int k = 0; k < kSiftDimension; ++k)
      bins[k] = raw[k] + (sum_turned ? raw[Rotate180Index(k)] : 0.0f);
    const std::size_t at = out->size();
    out->resize(at + kSiftDimension);
    NormalizeSiftDescriptor(bins, out->data() + at);
  }
  return static_cast<int>(angles_.size());
}

}  // namespace meshseek
