// BF-DSIFT (Furuya & Ohbuchi, CIVR 2009): the view-based method of the
// paper's table. The whole model is rendered as depth images from directions
// spread over the sphere, SIFT describes each image densely, and the
// descriptors of all views form the model's bag of features (a large
// vocabulary, KL ranking, as for the local methods).
//
// Views: orthographic depth images of the model normalised into its minimum
// enclosing sphere (common/render/view_renderer.h), from the vertices of a
// subdivided icosahedron (42 at level 1, the original's count), I x I pixels
// (256 in the original; 128 here, measured as good). Rotation invariance
// comes from the views covering the sphere and from SIFT's own orientation:
// no pose normalisation.
//
// Dense sampling: in each view, points on a square grid inside the silhouette
// whose step is chosen so that about `points_per_view` fall in it (so a small
// silhouette is sampled as densely as a large one, as the original's
// per-image count), each described at `patch_scales` radii: patch_radius
// (in units of the image side), then twice that, and so on. A patch of radius r around a
// point is resampled into a local depth image (depth_image.h's
// conventions: a camera plane r in front of the point, depths clipped to
// [0, 2r], background at the far plane) from the level of a 2x image pyramid
// whose pixels are nearest to the patch's, and described with Lowe's
// dominant orientations by the same SIFT code as the local methods
// (sift_descriptor.h).
#ifndef MESHSEEK_COMMON_FEATURES_BF_DSIFT_H_
#define MESHSEEK_COMMON_FEATURES_BF_DSIFT_H_

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "common/features/depth_image.h"
#include "common/features/local_features.h"
#include "common/features/sift_descriptor.h"
#include "common/geometry/mesh.h"

namespace meshseek {

struct BfDsiftOptions {
  /// Subdivisions of the icosahedron whose vertices are the view directions:
  /// 0: 12 views, 1: 42 (the original), 2: 162.
  int view_level = 1;
  /// Side of each rendered view in pixels. 128, not the original's 256: the
  /// same first tier on McGill (74.0 against 74.3, 72.4 against 72.3 with
  /// one scale) at half the extraction time (bench/results/bfdsift.txt).
  int view_size = 128;
  /// Grid points per view inside the silhouette (about; the original sampled
  /// 300 per image, which measured 0.6 below 150 with three scales).
  int points_per_view = 150;
  /// Smallest patch radius relative to the view's side (the view spans the
  /// enclosing sphere's diameter).
  double patch_radius = 0.05;
  /// Radii per point: patch_radius, 2 patch_radius, ... (1 to 4). Four
  /// (0.05 to 0.4) by measurement (bench/results/bfdsift.txt): PSB's rigid
  /// shapes need the largest, which covers most of the model (PSB train 50.5
  /// against 48.5 for three), and at V = 40,000 McGill's articulated ones
  /// lose nothing by it (76.9 with four or three); with one radius the best
  /// (0.15) is 2 points below three.
  int patch_scales = 4;
  /// The local depth image each patch is resampled into (size I, odd).
  DepthImageOptions patch_image;
  /// SIFT of each patch: Lowe's dominant orientation, the strongest peak
  /// only. Every peak within 80 % (one descriptor per peak, as the local
  /// methods) measured 1.5 below on McGill (74.0 against 75.5 at V = 8,000):
  /// a patch with a second peak would count twice in the histogram.
  SiftDescriptorOptions descriptor = OneOrientation();

  absl::Status Validate() const;

 private:
  static SiftDescriptorOptions OneOrientation() {
    SiftDescriptorOptions sift;
    sift.max_orientations = 1;
    return sift;
  }
};

/// The dense SIFT features of every view of `mesh`. Keypoints: position = the
/// surface point seen at the patch centre, view = the view direction, up = the
/// view's up axis, scale = the patch radius in model units. InvalidArgument
/// for a mesh without area or extent. num_threads > 1 describes the views on
/// that many threads: the same features, in the same order.
absl::StatusOr<LocalFeatures> ExtractBfDsift(const TriangleMesh& mesh,
                                             const BfDsiftOptions& options,
                                             int num_threads = 1);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_FEATURES_BF_DSIFT_H_
