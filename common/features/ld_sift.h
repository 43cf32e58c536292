// LD-SIFT, the baseline (Darom & Keller, "Scale-invariant features for 3-D
// mesh models", TIP 2012; docs/design.md 2.5): interest points by the scale space
// of the mesh's own vertex graph (scale_space.h), described by one depth
// image each, seen from outside along the vertex normal.
//
// Per model: the OpenMesh vertex graph (mesh_vertex_graph.h: non-manifold
// faces and soups come apart, as in the original), interest points with
// s = C * d * sqrt(l), then at each point the PCA of the mesh vertices within s
// (up = largest axis, made orthogonal to the normal), a front view along the
// vertex normal, and one SIFT descriptor with the 180-degree sum. A point with
// fewer than 3 vertices in its support gives no feature.
//
// This is the reference that shows why the paper's methods exist: it does well
// on dense manifold meshes and poorly on sparse meshes and soups. It is kept
// that way on purpose; nothing here "fixes" it.
#ifndef MESHSEEK_COMMON_FEATURES_LD_SIFT_H_
#define MESHSEEK_COMMON_FEATURES_LD_SIFT_H_

#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "common/features/depth_image.h"
#include "common/features/local_features.h"
#include "common/features/scale_space.h"
#include "common/features/sift_descriptor.h"
#include "common/geometry/mesh.h"

namespace meshseek {

struct LdSiftOptions {
  LdSiftOptions() {
    descriptor.orientation = ImageOrientation::kUpAxis;
    scale_space.scale_factor = 20;
  }

  /// Detector: L = 20 levels (the LD-SIFT code's value) and C = 20, chosen on
  /// McGill articulated (first tier 56.0 at the code's C = 5, 64.2 at 10, 67.9
  /// at 15, 69.0 at 20, 67.1 at 25; V = 2,000). Only the scale is tuned: the
  /// graph, normals, single view and descriptor stay the original's.
  ScaleSpaceOptions scale_space;
  /// Depth image size I (21, as for the other methods).
  DepthImageOptions depth_image;
  /// Descriptor: the original's PCA up axis with the 180-degree sum.
  SiftDescriptorOptions descriptor;

  absl::Status Validate() const;
};

// Extracts LD-SIFT features; `detected`, if given, receives the interest
// points (vertex indices refer to the OpenMesh vertex graph, whose positions
// are in each keypoint). A model on which nothing is detected gives an empty
// set, not an error: that is LD-SIFT's documented weakness on sparse meshes
// and soups. num_threads > 1 describes the points on that many threads
// (DescribeFrames): the same features.
absl::StatusOr<LocalFeatures> ExtractLdSift(const TriangleMesh& mesh,
                                            const LdSiftOptions& options,
                                            std::vector<InterestPoint>* detected = nullptr,
                                            int num_threads = 1);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_FEATURES_LD_SIFT_H_
