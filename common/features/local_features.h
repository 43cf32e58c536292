// The output of every local-feature extractor: keypoints and their SIFT
// descriptors, one keypoint per descriptor (a point seen from two sides gives
// two keypoints with the same position and opposite view directions).
#ifndef MESHSEEK_COMMON_FEATURES_LOCAL_FEATURES_H_
#define MESHSEEK_COMMON_FEATURES_LOCAL_FEATURES_H_

#include <cstdint>
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

struct LocalFeatures {
  std::vector<Keypoint> keypoints;
  std::vector<uint8_t> descriptors;  // keypoints.size() x kSiftDimension, row-major

  std::size_t size() const { return keypoints.size(); }
  const uint8_t* descriptor(std::size_t i) const { return descriptors.data() + i * kSiftDimension; }
};

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_FEATURES_LOCAL_FEATURES_H_
