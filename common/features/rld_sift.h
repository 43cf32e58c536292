// RLD-SIFT: resampled LD-SIFT (Ohishi & Ohbuchi 2013, sec. 3.1; docs/design.md
// 2.6). The surface is resampled with N_RLD area-uniform Sobol points
// (SampleSurface), each joined to its k nearest neighbours (symmetrised), and
// LD-SIFT's scale-space detector runs on that graph, so interest points no
// longer depend on the input's tessellation, manifoldness or components.
// Each interest point is then described like a DLD-SIFT point: a local frame
// from the resample points within its scale s = C * d * sqrt(l), and two
// depth images of the original triangles (into and out of the surface).
#ifndef MESHSEEK_COMMON_FEATURES_RLD_SIFT_H_
#define MESHSEEK_COMMON_FEATURES_RLD_SIFT_H_

#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "common/features/depth_image.h"
#include "common/features/local_features.h"
#include "common/features/scale_space.h"
#include "common/features/sift_descriptor.h"
#include "common/geometry/mesh.h"
#include "common/geometry/point_graph.h"
#include "common/geometry/surface_sampler.h"

namespace meshseek {

struct RldSiftOptions {
  RldSiftOptions() { scale_space.scale_factor = 15; }

  /// N_RLD, resample points (the paper: 15,000).
  int num_samples = 15000;
  /// k of the k-nearest-neighbour graph (the paper: 10).
  int neighbors = 10;
  /// Detector: L = 20 levels and C = 15, chosen on McGill articulated (first
  /// tier 75.2 at C = 5, 78.4 at 10, 80.0 at 12.5, 80.7 at 15, 79.5 at 17.5,
  /// 78.4 at 20; V = 2,000): at C = 5 the supports of the 10-NN graph's level-1
  /// points are a third of the best DLD-SIFT support.
  ScaleSpaceOptions scale_space;
  /// Render the back view too (the paper's two views).
  bool two_views = true;
  /// SHOT-style distance-weighted PCA frame (as DLD-SIFT's default).
  bool weighted_frame = true;
  /// Depth image size I.
  DepthImageOptions depth_image;
  /// Descriptor parameters.
  SiftDescriptorOptions descriptor;

  absl::Status Validate() const;
};

// Step 1 of RLD-SIFT, the resample service's work: `num_samples` area-uniform
// Sobol points on the mesh joined to their `neighbors` nearest (symmetrised).
// `samples`, if given, receives the points with normals and faces.
absl::StatusOr<PointGraph> ResampleSurfaceGraph(const TriangleMesh& mesh,
                                                int num_samples,
                                                int neighbors,
                                                SurfacePoints* samples = nullptr);

// Step 2, the extract service's work: scale-space detection on `graph` (as
// ResampleSurfaceGraph made it with options.num_samples and
// options.neighbors) and two depth images of `mesh` per interest point. The
// graph is checked (ValidatePointGraph); options.num_samples and neighbors
// are not used. num_threads > 1 describes the points on that many threads
// (DescribeFrames): the same features.
absl::StatusOr<LocalFeatures> DescribeRldSift(const TriangleMesh& mesh,
                                              const PointGraph& graph,
                                              const RldSiftOptions& options,
                                              std::vector<InterestPoint>* detected = nullptr,
                                              int num_threads = 1);

// Extracts RLD-SIFT features: both steps. `resampled` and `detected`, if given, receive
// the resample points and the interest points (vertex = resample index). A
// model with no interest point gives an empty set, not an error.
absl::StatusOr<LocalFeatures> ExtractRldSift(const TriangleMesh& mesh,
                                             const RldSiftOptions& options,
                                             SurfacePoints* resampled = nullptr,
                                             std::vector<InterestPoint>* detected = nullptr,
                                             int num_threads = 1);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_FEATURES_RLD_SIFT_H_
