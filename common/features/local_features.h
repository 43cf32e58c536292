// The output of every local-feature extractor: keypoints and their
// descriptors, one keypoint per descriptor (a point seen from two sides gives
// two keypoints with the same position and opposite view directions).
// Descriptors are bytes of one dimension per method: 128 for the SIFT
// methods, the method's own for the others (LSF); the codebook learns and
// encodes any dimension.
#ifndef MESHSEEK_COMMON_FEATURES_LOCAL_FEATURES_H_
#define MESHSEEK_COMMON_FEATURES_LOCAL_FEATURES_H_

#include <cstddef>
#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

#include "common/features/sift_descriptor.h"
#include "common/geometry/vec3.h"

namespace meshseek {

struct Keypoint {
  Vec3f position;
  Vec3f view;   // unit direction the camera looks along
  Vec3f up;     // unit up axis of the image
  float scale;  // support radius s, model units
  int level;    // scale-space level of a detected point; 0 for dense points
};

/// Bound on a descriptor's dimension: what a peer may declare before its
/// bytes are trusted.
inline constexpr std::size_t kMaxDescriptorDimension = 16384;

struct LocalFeatures {
  std::vector<Keypoint> keypoints;
  /// Bytes per descriptor (1 to kMaxDescriptorDimension).
  std::size_t dimension = kSiftDimension;
  std::vector<uint8_t> descriptors;  // keypoints.size() x dimension, row-major

  std::size_t size() const { return keypoints.size(); }
  const uint8_t* descriptor(std::size_t i) const { return descriptors.data() + i * dimension; }
};

/// Appends the features of `from` to `to` (the same dimension).
inline void AppendFeatures(const LocalFeatures& from, LocalFeatures* to) {
  to->keypoints.insert(to->keypoints.end(), from.keypoints.begin(), from.keypoints.end());
  to->descriptors.insert(to->descriptors.end(), from.descriptors.begin(), from.descriptors.end());
}

/// The features of items 0 .. n - 1 as `describe(begin, end, out)` appends
/// those of the items [begin, end) to `out`, in item order, on up to
/// `num_threads` threads (<= 1: one run on the calling thread): contiguous
/// runs, about four a thread so that unequal items even out, each into its
/// own set, concatenated. The same features for every thread count when
/// `describe` depends on nothing but its items. Several threads on one
/// model are for a query's latency (docs/design.md 1.1); models side by
/// side keep one core each.
LocalFeatures DescribeInRuns(
    std::size_t n,
    int num_threads,
    const std::function<void(std::size_t begin, std::size_t end, LocalFeatures* out)>& describe);

/// A global method's output in the same form: one feature whose descriptor is
/// the model's whole fixed-size descriptor (its keypoint is all zeros), so
/// that extraction, transport and storage are the same for every method.
inline LocalFeatures GlobalDescriptorFeatures(std::vector<uint8_t> bytes) {
  LocalFeatures features;
  features.dimension = bytes.size();
  features.descriptors = std::move(bytes);
  features.keypoints.resize(1, Keypoint{Vec3f(0, 0, 0), Vec3f(0, 0, 0), Vec3f(0, 0, 0), 0, 0});
  return features;
}

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_FEATURES_LOCAL_FEATURES_H_
