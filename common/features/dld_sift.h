// DLD-SIFT: dense local depth SIFT (Ohishi & Ohbuchi 2013, sec. 3.2;
// docs/design.md 2.4). No interest-point detection: N_DLD "forced" feature points
// are sampled area-uniformly on the surface (SampleSurface), and each gets a
// pair of local depth images (front and back) described by SIFT.
//
// Per model:
//   1. D = diameter of the minimum enclosing sphere; support radius
//      s = scale * D / 2, i.e. `scale` is E relative to the enclosing sphere
//      (E = 1: the sphere itself).
//   2. Feature points: SampleSurface(mesh, num_points).
//   3. Local frame of each point: PCA of a dense area-uniform sample of the
//      surface within distance s (up = largest axis, view = smallest). The dense
//      set, not the mesh vertices, makes the frame independent of
//      tessellation; its size adapts to s so that a flat disc of radius s holds
//      about `frame_samples_per_support` samples.
//   4. Two depth images per point (DepthImageRenderer), finished as LD-SIFT
//      does (FinishDepthImage), described by DepthSiftDescriber.
// Points whose support holds fewer than 3 samples and views that see nothing
// yield no feature. Deterministic; single-threaded per model (meshseek
// parallelises across models).
#ifndef MESHSEEK_COMMON_FEATURES_DLD_SIFT_H_
#define MESHSEEK_COMMON_FEATURES_DLD_SIFT_H_

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "common/features/depth_image.h"
#include "common/features/local_features.h"
#include "common/features/sift_descriptor.h"
#include "common/geometry/mesh.h"

namespace meshseek {

struct DldSiftOptions {
  /// N_DLD, feature points per model. The paper found accuracy saturating at
  /// 1,024.
  int num_points = 1024;
  /// E, the support radius relative to the minimum enclosing sphere:
  /// s = scale * D / 2. The paper's Fig. 6: articulated shapes (McGill) prefer
  /// small E, rigid ones (PSB) larger. Chosen by the sweep in bench/.
  double scale = 0.2;
  /// Render the back view too (the paper's two views). One view only for
  /// experiments.
  bool two_views = true;
  /// Weight the local PCA by (s - distance) about the feature point (SHOT's
  /// repeatable local reference frame) instead of plain PCA about the
  /// centroid of the support.
  bool weighted_frame = true;
  /// The local frame's PCA uses the samples within this many times s (the
  /// depth images always cover s).
  double frame_radius_factor = 1.0;
  /// Target number of dense samples in a flat disc of radius s for the local
  /// PCA frame; the dense sample count is this times area / (pi s^2).
  int frame_samples_per_support = 512;
  /// Lower and upper bounds on that dense sample count (time and memory guard
  /// for very small E or huge models).
  int min_frame_samples = 2048;
  int max_frame_samples = 200000;
  /// Depth image parameters (size I).
  DepthImageOptions depth_image;
  /// Descriptor parameters.
  SiftDescriptorOptions descriptor;

  absl::Status Validate() const;
};

// Extracts DLD-SIFT features. The mesh must be valid (ValidateMesh), which is
// checked. Errors name the problem (e.g. a degenerate model). num_threads > 1
// describes the frames on that many threads (DescribeFrames): the same features.
absl::StatusOr<LocalFeatures> ExtractDldSift(const TriangleMesh& mesh,
                                             const DldSiftOptions& options,
                                             int num_threads = 1);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_FEATURES_DLD_SIFT_H_
