// What every LD-SIFT variant does once it has a feature point and its
// support radius s (docs/design.md 2.2, 2.3): a local frame from the surface points
// within s, one or two depth images of the original triangles, and their SIFT
// descriptors. DLD-SIFT, LD-SIFT and RLD-SIFT differ only in where the points,
// radii and view directions come from.
#ifndef MESHSEEK_COMMON_FEATURES_LOCAL_DEPTH_SIFT_H_
#define MESHSEEK_COMMON_FEATURES_LOCAL_DEPTH_SIFT_H_

#include <functional>
#include <optional>
#include <vector>

#include "common/features/depth_image.h"
#include "common/features/local_features.h"
#include "common/features/scale_space.h"
#include "common/features/sift_descriptor.h"
#include "common/geometry/mesh.h"
#include "common/geometry/point_grid.h"
#include "common/geometry/principal_axes.h"
#include "common/geometry/triangle_bvh.h"

namespace meshseek {

// PCA axes of the points within distance s of p (found through `grid`, which
// indexes `points`), or nullopt if fewer than 3 lie there: such a point yields
// no feature. `weighted`: SHOT-style (s - distance) weights about p instead of
// plain PCA about the centroid. `scratch` holds the support between calls.
std::optional<PrincipalAxes> SupportAxes(const std::vector<Vec3f>& points,
                                         const PointGrid& grid,
                                         const Vec3f& p,
                                         double s,
                                         bool weighted,
                                         std::vector<uint32_t>* scratch);

// Renders and describes local depth images of one mesh. Holds scratch
// buffers: one per thread; the mesh and its BVH must outlive it.
class LocalDepthSift {
 public:
  LocalDepthSift(const TriangleMesh& mesh,
                 const TriangleBvh& bvh,
                 const DepthImageOptions& image_options,
                 const SiftDescriptorOptions& descriptor_options);

  // Appends the features of the front view of `frame` (camera at p + s n
  // looking along -n) and, if `two_views`, of the back view, each image giving
  // one or more descriptors (SiftDescriptorOptions::orientation); a view that
  // sees nothing gives none. Keypoints record `level`.
  void Describe(const ViewFrame& frame, bool two_views, int level, LocalFeatures* out);

 private:
  DepthImageRenderer renderer_;
  DepthSiftDescriber describer_;
  DepthImage front_, back_;
};

// One frame to describe and the scale-space level its keypoints record.
struct LevelFrame {
  ViewFrame frame;
  int level = 0;
};

// The frame of item i, nullopt to skip it; `support` is the calling thread's
// scratch for SupportAxes. Called concurrently for different items.
using FrameOf =
    std::function<std::optional<LevelFrame>(std::size_t i, std::vector<uint32_t>* support)>;

// The features of items 0 .. count - 1 (FrameOf, LocalDepthSift::Describe),
// in item order, on up to `num_threads` threads (DescribeInRuns: the same
// features for every count), each run of items with its own renderer and
// describer and the mesh's BVH built once and shared.
LocalFeatures DescribeFrames(const TriangleMesh& mesh,
                             std::size_t count,
                             bool two_views,
                             const DepthImageOptions& image_options,
                             const SiftDescriptorOptions& descriptor_options,
                             int num_threads,
                             const FrameOf& frame_of);

// The view frame of a detected point, made from the point and the PCA axes of
// its support; nullopt skips the point.
using InterestPointFrame = std::function<std::optional<ViewFrame>(
    const InterestPoint& point, const Vec3f& position, const PrincipalAxes& axes)>;

// Describes detected interest points (vertices of `positions`, with their
// scales), as LD-SIFT and RLD-SIFT both do: the support axes of the points of
// `positions` within each point's scale (SupportAxes, `weighted`), the frame
// `make_frame` makes of them, and LocalDepthSift's views of `mesh`. The two
// methods differ only in `make_frame`, `weighted` and `two_views`.
// `make_frame` is called concurrently with num_threads > 1 (DescribeFrames).
LocalFeatures DescribeInterestPoints(const TriangleMesh& mesh,
                                     const std::vector<Vec3f>& positions,
                                     const std::vector<InterestPoint>& points,
                                     bool weighted,
                                     bool two_views,
                                     const DepthImageOptions& image_options,
                                     const SiftDescriptorOptions& descriptor_options,
                                     const InterestPointFrame& make_frame,
                                     int num_threads = 1);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_FEATURES_LOCAL_DEPTH_SIFT_H_
