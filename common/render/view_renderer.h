// Whole-model views: orthographic depth images and silhouettes of a mesh from
// directions on the sphere, I x I pixels, framed by the model's minimum
// enclosing sphere. The input of view-based descriptors: BF-DSIFT describes
// depth images by dense SIFT, LFD describes silhouettes by Zernike moments
// and Fourier descriptors.
//
// Geometry. The mesh is moved and scaled so that its enclosing sphere is the
// unit sphere. A view looks along a unit direction d; its frame (CameraFor)
// has right x up = -d. A surface point p lands on the pixel whose centre is
// nearest (dot(p, right), dot(p, up)) / window_scale, row 0 at the top, and
// its depth is (1 - dot(p, d)) / 2: 1 at the sphere's pole nearest the
// camera, 0 at the far pole. Background pixels are 0 with mask 0; the value
// kept per pixel is the nearest surface (largest depth): a z-buffer.
//
// Rasterising. Every triangle (no back-face culling: soups and open meshes
// have no consistent orientation) covers the pixels whose centres lie in it
// (closed edges, so abutting triangles leave no gaps), with depth
// interpolated linearly. Cost: one projection per vertex and view, an
// integer pixel box per triangle (empty for most triangles of a detailed mesh,
// which are smaller than a pixel), then the pixels of the boxes left.
// Deterministic and thread-safe (Render is const).
#ifndef MESHSEEK_COMMON_RENDER_VIEW_RENDERER_H_
#define MESHSEEK_COMMON_RENDER_VIEW_RENDERER_H_

#include <cstdint>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "common/geometry/enclosing_sphere.h"
#include "common/geometry/mesh.h"

namespace meshseek {

struct ViewRenderOptions {
  /// Pixels per side I (8 to 4096).
  int image_size = 256;
  /// Half-width of the view window relative to the enclosing sphere's radius
  /// (1: the sphere just fits; larger leaves a margin). In (0, 16].
  double window_scale = 1.0;
  /// Also record which triangle each pixel shows (ViewImage::face): what a
  /// shaded picture needs (thumbnail.h); off for descriptors, which need
  /// only depth and silhouette.
  bool record_faces = false;

  absl::Status Validate() const;
};

/// One rendered view, row-major, row 0 at the top.
struct ViewImage {
  int size = 0;
  /// Depth in [0, 1] (see above); 0 where the model is not.
  std::vector<float> depth;
  /// 1 where the model covers the pixel: the silhouette.
  std::vector<uint8_t> mask;
  /// The visible triangle's index per pixel, -1 where the model is not; only
  /// with ViewRenderOptions::record_faces, empty otherwise.
  std::vector<int32_t> face;

  float DepthAt(int x, int y) const { return depth[static_cast<std::size_t>(y) * size + x]; }
  bool Covered(int x, int y) const { return mask[static_cast<std::size_t>(y) * size + x] != 0; }
};

/// The camera frame of a view direction: `right` and `up` span the image,
/// right x up = -direction. Deterministic: up is the world axis least
/// aligned with the direction, made orthogonal.
struct ViewCamera {
  Vec3d direction;
  Vec3d right;
  Vec3d up;
};
ViewCamera CameraFor(const Vec3d& direction);

class ViewRenderer {
 public:
  /// InvalidArgument for bad options, a mesh without triangles or one whose
  /// enclosing sphere has no extent.
  static absl::StatusOr<ViewRenderer> Create(const TriangleMesh& mesh,
                                             const ViewRenderOptions& options);

  ViewImage Render(const Vec3d& direction) const { return Render(CameraFor(direction)); }
  ViewImage Render(const ViewCamera& frame) const;

  /// Render(frame).mask alone, sooner: without depths, a pixel covered once
  /// is not tested again and a triangle whose pixel box is covered already
  /// is skipped, so the surfaces behind the first cost little (LFD's
  /// silhouettes).
  std::vector<uint8_t> RenderSilhouette(const Vec3d& direction) const {
    return RenderSilhouette(CameraFor(direction));
  }
  std::vector<uint8_t> RenderSilhouette(const ViewCamera& frame) const;

  /// The enclosing sphere the views are framed by, in the mesh's coordinates.
  const Sphere& sphere() const { return sphere_; }
  const ViewRenderOptions& options() const { return options_; }

 private:
  ViewRenderer(const ViewRenderOptions& options, const Sphere& sphere)
      : options_(options), sphere_(sphere) {}

  ViewRenderOptions options_;
  Sphere sphere_;
  // Vertices in the unit enclosing sphere's coordinates, one array per axis
  // (the projection runs over them in vectors).
  std::vector<double> x_, y_, z_;
  std::vector<Triangle> triangles_;
};

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_RENDER_VIEW_RENDERER_H_
