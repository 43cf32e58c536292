// SIFT descriptors of local depth images (docs/design.md 2.3).
//
// One 128-d descriptor (4 x 4 spatial cells x 8 orientations) centred on the
// image and covering it, as OpenCV's cv::SIFT computes it for a keypoint of
// size I / 6 at the centre of an 8-bit version of the depth image (descriptor
// window of 4 cells x 3 sigma = I pixels), but computed here directly: for such
// a keypoint (octave 0, layer 0) OpenCV describes the base of its Gaussian
// pyramid, i.e. the image blurred once by sqrt(sigma^2 - 0.5^2), and builds
// the rest of the pyramid for nothing. This code blurs once and runs OpenCV's
// calcSIFTDescriptor arithmetic on the result (same window, Gaussian weight,
// trilinear interpolation, bin layout, 0.2 clipping and byte scaling); the
// gradients are shared by all orientations of an image. It matches OpenCV's
// descriptors up to float rounding (sift_descriptor_test compares them on
// rendered depth images: 99.8 % of McGill's are bit-identical, no byte differs
// by more than 2) in about a quarter of the time (12 us per 21 x 21 image
// with its dominant orientations, against 44 us for cv::SIFT alone).
//
// Orientation is fixed either by the frame (the PCA up axis is "up" in the
// image) or by Lowe's dominant gradient orientations. Since the sign of the up
// axis is arbitrary, LD-SIFT adds the descriptor of the image turned by 180
// degrees; that turn is an exact permutation of the descriptor's bins (cell
// (i, j) -> (3 - i, 3 - j), orientation k -> k + 4), so it costs no second
// descriptor. The result is normalised as SIFT does (unit length, entries
// clipped at 0.2, unit length again) and quantised to bytes (x 512,
// saturated), the usual storage form of SIFT.
#ifndef MESHSEEK_COMMON_FEATURES_SIFT_DESCRIPTOR_H_
#define MESHSEEK_COMMON_FEATURES_SIFT_DESCRIPTOR_H_

#include <cstdint>
#include <vector>

#include "absl/status/status.h"
#include "common/features/depth_image.h"

namespace meshseek {

inline constexpr int kSiftDimension = 128;

// How depths become grey levels. They are rounded to 8 bits, as cv::SIFT
// required when the settings were chosen (the quantisation is part of the
// measured descriptor).
enum class DepthToGray {
  // grey = 255 * depth / (2 s): the same depth difference gives the same
  // contrast in every image of the model (scale-invariant, since s scales
  // with the model).
  kFixedRange,
  // The image's own depth range stretched to 0..255: maximal precision for
  // nearly flat patches, at the price of amplifying small relief.
  kStretch,
};

// How the descriptor's rotation about the view axis is fixed.
enum class ImageOrientation {
  // The frame's up axis is up in the image, and the descriptor of the image
  // turned by 180 degrees is added (LD-SIFT): one descriptor per image.
  kUpAxis,
  // Lowe's dominant gradient orientations: one descriptor per peak of the
  // image's orientation histogram within 80 % of the highest ("one or more
  // SIFT features per image", Ohishi & Ohbuchi). Independent of the frame's
  // up axis, which PCA leaves unstable on nearly isotropic patches.
  kDominant,
};

struct SiftDescriptorOptions {
  /// How rotation about the view axis is fixed.
  ImageOrientation orientation = ImageOrientation::kDominant;
  /// Mapping from depth to grey level.
  DepthToGray depth_to_gray = DepthToGray::kFixedRange;
  /// With kDominant: at most this many orientations (the strongest peaks) per
  /// image; 0 keeps every peak within 80 % of the highest, as Lowe does.
  int max_orientations = 0;
  /// Gaussian blur sigma of the image before gradients, in pixels (cv::SIFT's
  /// `sigma`, which assumes the input already carries 0.5 of blur, so the
  /// image is blurred by sqrt(sigma^2 - 0.5^2): 0.5 means no extra blur, as in
  /// VLFeat's raw descriptor that LD-SIFT's authors used; 1.6 is Lowe's and
  /// OpenCV's default).
  double blur_sigma = 1.6;
  /// With kUpAxis: add the 180-degree-turned descriptor (LD-SIFT's cure for
  /// the sign ambiguity of the PCA up axis). Off only for experiments.
  bool symmetrize_180 = true;

  absl::Status Validate() const;
};

// Lowe's dominant orientations of an image, in degrees counter-clockwise from
// the image's +x axis (y up): peaks of a 36-bin histogram of gradient
// orientations weighted by magnitude and a centred Gaussian, smoothed, with
// every local peak within `peak_ratio` of the highest kept and refined by a
// parabola; strongest first. Empty for an image without gradient.
std::vector<float> DominantOrientations(const DepthImage& image, float peak_ratio = 0.8f);

// Euclidean distance between two byte descriptors.
double DescriptorDistance(const uint8_t* a, const uint8_t* b);

// Turns float SIFT bins into SIFT's normalised byte form (in place on `bins`,
// result in `out`).
void NormalizeSiftDescriptor(float* bins, uint8_t* out);

// The bin permutation of a 180-degree image turn: out[k] = in[Rotate180Index(k)].
int Rotate180Index(int bin);

// Describes depth images. Holds scratch buffers and per-size tables: one per
// thread.
class DepthSiftDescriber {
 public:
  explicit DepthSiftDescriber(const SiftDescriptorOptions& options);
  DepthSiftDescriber(const DepthSiftDescriber&) = delete;
  DepthSiftDescriber& operator=(const DepthSiftDescriber&) = delete;

  // Appends the descriptors of a finished image (FinishDepthImage) to `out`,
  // kSiftDimension bytes each, and returns how many: one with kUpAxis, one or
  // more with kDominant (a flat image, which has no orientation, is described
  // upright).
  int Describe(const DepthImage& image, std::vector<uint8_t>* out);

 private:
  // (Re)builds the tables that depend on the image size only.
  void Prepare(int size);
  // Grey levels of `image`, blurred, into blurred_, and their gradient
  // samples (sample_orientation_, sample_magnitude_).
  void ComputeSamples(const DepthImage& image);
  // Each sample's histogram offset and trilinear weights for orientation
  // `degrees` (sample_offset_, sample_weights_).
  void BinSamples(float degrees);
  // OpenCV's calcSIFTDescriptor on the samples for orientation `degrees`,
  // including its normalisation: 128 values in 0..255 (integers) into `bins`.
  void DescribeAt(float degrees, float* bins);

  SiftDescriptorOptions options_;
  int size_ = 0;
  int stride_ = 0;  // floats per row of the working images
  int blur_radius_ = 0;
  std::vector<float> kernel_;              // 2 blur_radius_ + 1 taps
  std::vector<const float*> tap_rows_;     // the blur's input row of each tap
  std::vector<int> border_;                // padded column -> reflected column
  std::vector<float> window_weight_;       // Gaussian of the descriptor window
  std::vector<float> orientation_weight_;  // DominantOrientations' Gaussian
  std::vector<float> gray_, padded_, rows_, blurred_;
  // The gradient samples of the blurred image inside the descriptor window,
  // one per pixel of rows 1 .. size - 2 with the row padding (weight 0 off
  // the interior), row by row, as arrays (so that the loops over
  // them vectorise): offset from the centre (row down, column right),
  // orientation in degrees (y up), magnitude times the window's Gaussian
  // weight; then, per orientation described, each one's histogram offset
  // and its eight trilinear weights.
  std::vector<float> sample_row_, sample_col_, sample_orientation_, sample_magnitude_;
  std::vector<int> sample_offset_;
  std::vector<float> sample_weights_[8];
  // DominantOrientations' per-pixel scratch.
  std::vector<float> orientation_magnitude_;
  std::vector<int> orientation_bin_;
  std::vector<float> angles_;
};

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_FEATURES_SIFT_DESCRIPTOR_H_
