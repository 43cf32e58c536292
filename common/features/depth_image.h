// Local depth images: orthographic z-buffer renderings of the surface around a
// point, the "image" that LD-SIFT and its variants describe with SIFT
// (Darom & Keller 2012; Ohishi & Ohbuchi 2013, Fig. 2; docs/design.md 2.2).
//
// Geometry of a view pair for a point p, support radius s and an orthonormal
// frame (up u, normal n):
//   - the front camera sits at p + s n and looks along -n; the back camera sits
//     at p - s n and looks along +n (the paper renders "looking into" and
//     "looking out of" the surface, since inside/outside is meaningless for
//     soups and face orientation is unreliable);
//   - each image is I x I pixels covering [-s, s]^2 of the view plane, p at the
//     centre pixel, u pointing up in the image, and the camera's right vector
//     (forward x up) pointing right: the back image is the mirror image a real
//     camera on the other side would see;
//   - only surface inside the cube |x|, |y|, |h| <= s around p is drawn: the
//     camera's near plane is its own position, the far plane lies 2s away, so a
//     depth is in [0, 2s]. Back faces are kept; nearest surface wins.
// Triangles are found through a TriangleBvh and rasterised by sampling pixel
// centres (inclusive edges, so shared edges leave no cracks). Both images of
// a pair come from one pass: the front image keeps the highest surface along
// n per pixel, the back image the lowest. Dense meshes put a few thousand
// triangles, most smaller than a pixel, into each view cube, so the renderer
// culls them in vectorised blocks without branches and tests pixel centres
// only for the few that can cover one.
#ifndef MESHSEEK_COMMON_FEATURES_DEPTH_IMAGE_H_
#define MESHSEEK_COMMON_FEATURES_DEPTH_IMAGE_H_

#include <cstdint>
#include <limits>
#include <vector>

#include "absl/status/status.h"
#include "common/geometry/mesh.h"
#include "common/geometry/triangle_bvh.h"

namespace meshseek {

struct DepthImageOptions {
  /// Image side I in pixels. The paper compared 21, 41 and 61 and chose 21.
  /// Odd, so that the feature point falls on the centre of a pixel.
  int image_size = 21;

  absl::Status Validate() const;
};

// A square depth image, row-major, row 0 at the top. Depths are distances from
// the camera along its viewing direction, in model units; pixels that saw no
// surface hold kEmpty until FinishDepthImage fills them.
struct DepthImage {
  static constexpr float kEmpty = std::numeric_limits<float>::infinity();

  int size = 0;
  float support_radius = 0;  // s: depths lie in [0, 2s]
  std::vector<float> depth;

  float at(int row, int col) const { return depth[static_cast<std::size_t>(row) * size + col]; }
  float& at(int row, int col) { return depth[static_cast<std::size_t>(row) * size + col]; }
};

// Where and how to look: the feature point, its support radius s and the
// orthonormal (up, normal) pair of its local frame.
struct ViewFrame {
  Vec3d point;
  Vec3d up;
  Vec3d normal;
  double radius = 0;
};

// Renders view pairs of one mesh. Holds scratch buffers, so use one renderer
// per thread; the mesh and BVH must outlive it.
class DepthImageRenderer {
 public:
  DepthImageRenderer(const TriangleMesh& mesh,
                     const TriangleBvh& bvh,
                     const DepthImageOptions& options);

  // Renders the front and back images of `frame` (raw: empty pixels are
  // DepthImage::kEmpty). Either output may be null if not wanted.
  void RenderPair(const ViewFrame& frame, DepthImage* front, DepthImage* back);

 private:
  const TriangleMesh& mesh_;
  const TriangleBvh& bvh_;
  DepthImageOptions options_;
  Vec3d origin_;                // centre of the mesh's bounding box
  std::vector<Vec3f> centred_;  // vertices minus origin_
  std::vector<uint32_t> candidates_;
  std::vector<float> highest_, lowest_;
};

// LD-SIFT's post-processing, in place: empty pixels take the largest depth in
// the image (the surface seems to continue at the far end rather than jump to
// a fixed background), then the centre pixel becomes the mean of its four
// neighbours (the point itself is not allowed to spike the descriptor).
// Returns false, leaving the image unusable, if no pixel saw any surface: such
// a view yields no feature (never a zero vector in the bag of features).
bool FinishDepthImage(DepthImage* image);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_FEATURES_DEPTH_IMAGE_H_
