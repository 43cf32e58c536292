// Thumbnails: a small shaded picture of a model from a fixed three-quarter
// view, as PNG, so that people can judge a ranking by looking at shapes (the
// coordinator stores one per model at ingest; the web page and the
// evaluation report show them).
//
// The picture is rasterised by ViewRenderer (no display, no GPU), every
// pixel shaded by the normal of the triangle it shows: two-sided Lambert
// (soups and open meshes have no consistent orientation) under a key light
// above and to the left of the camera plus a headlight, over a transparent
// background, so that it sits on any page colour. It is rendered at
// `supersample` times the size and averaged down, which smooths the edges.
// Framed by the minimum enclosing sphere, so every model fills the picture
// alike whatever its units. Deterministic.
#ifndef MESHSEEK_COMMON_RENDER_THUMBNAIL_H_
#define MESHSEEK_COMMON_RENDER_THUMBNAIL_H_

#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "common/geometry/mesh.h"

namespace meshseek {

struct ThumbnailOptions {
  /// Pixels per side of the PNG, in [16, 1024].
  int size = 128;
  /// Rendered at size x supersample per side, then averaged down; in [1, 4].
  int supersample = 3;
  /// Where the camera is, seen from the model's centre (any length; not
  /// parallel to `up`): in front (+z), to the right (+x) and above (+y),
  /// the three-quarter view of product pictures.
  Vec3d eye = Vec3d(1.0, 0.7, 1.6);
  /// The model's up axis, shown upwards (most benchmark sets are y-up).
  Vec3d up = Vec3d(0, 1, 0);
  /// Surface colour, RGB in [0, 1].
  Vec3d colour = Vec3d(0.62, 0.70, 0.82);

  absl::Status Validate() const;
};

/// The model's thumbnail as PNG bytes (RGBA). InvalidArgument for bad
/// options or a mesh ViewRenderer refuses (no triangles, no extent).
absl::StatusOr<std::string> RenderThumbnailPng(const TriangleMesh& mesh,
                                               const ThumbnailOptions& options = {});

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_RENDER_THUMBNAIL_H_
