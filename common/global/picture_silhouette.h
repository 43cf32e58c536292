// Pictures to query with: a photo, a rendering or a drawing of an object
// becomes the silhouette the light field descriptor describes (lfd.h,
// DescribeLfdSilhouette), so that one picture can be matched against every
// model's 100 rendered views (Chen et al. 2003, query by one image or sketch).
//
// Method (PictureSilhouette), in the picture's pixels, scaled first to at
// most kPictureWorkingSide on its longer side (area averaging):
//   1. Foreground. A picture with an alpha channel that is not opaque
//      everywhere is its alpha (>= 128). Otherwise the object stands against
//      a plain background: the background colour is the per-channel median of
//      the border pixels, each pixel's difference the largest over its
//      channels, and the object is what differs by more than Otsu's threshold
//      of those differences, and by at least min_contrast grey levels (so
//      that a plain or nearly plain picture has no object rather than noise).
//   2. Specks: connected pieces smaller than 1/50 of the largest are
//      dropped (JPEG ringing, dust, a signature).
//   3. Line drawings: a closed outline (a sketch, a contour drawn 2 or 3
//      pixels wide) is filled. The pieces are first closed over gaps of about
//      2 % of the object's size, then every pixel the border cannot reach
//      around them is filled; if that makes the silhouette at least
//      outline_fill_ratio times larger, it was a drawing and the filled one is
//      kept. A filled silhouette keeps its holes (a mug's handle: the
//      rendered views have them too), since filling them grows it far less.
//   4. Framing: the object's bounding box scaled (area averaging, then
//      >= 0.5) so that its longer side is object_extent of image_size, and
//      centred. Position and scale do not change the descriptor (it is
//      centred on the centroid and scaled by the silhouette), the resolution
//      matches the views'.
//
// Bounds: pictures are decoded only up to max_pixels (checked from the
// header), and every step is linear in the working picture's pixels.
#ifndef MESHSEEK_COMMON_GLOBAL_PICTURE_SILHOUETTE_H_
#define MESHSEEK_COMMON_GLOBAL_PICTURE_SILHOUETTE_H_

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace meshseek {

/// The most pixels a picture may declare: 16.7 million (4,096 x 4,096; a
/// 12-megapixel photo fits).
inline constexpr uint64_t kMaxPicturePixels = uint64_t{1} << 24;
/// The largest picture file a client sends: 32 MiB (within the services'
/// 64 MiB messages; a 12-megapixel photo is a few megabytes).
inline constexpr uint64_t kMaxPictureFileBytes = uint64_t{32} << 20;
/// The longer side pictures are reduced to before they are segmented.
inline constexpr int kPictureWorkingSide = 1024;

struct PictureSilhouetteOptions {
  /// Side of the silhouette in pixels, as LfdOptions::image_size (32 to 1024).
  int image_size = 128;
  /// The object's longer side as a share of image_size, in (0, 1].
  double object_extent = 0.75;
  /// The least difference from the background, in grey levels (1 to 255),
  /// that counts as object.
  int min_contrast = 24;
  /// A silhouette that filling makes at least this many times larger was a
  /// line drawing (> 1).
  double outline_fill_ratio = 2.0;

  absl::Status Validate() const;
};

/// A PNG or JPEG file's pixels (png.h, jpeg.h), told apart by its first
/// bytes: CV_8UC1, CV_8UC3 or CV_8UC4. InvalidArgument naming what is wrong
/// for anything else, a damaged file, or one declaring more than
/// `max_pixels`.
absl::StatusOr<cv::Mat> DecodePicture(absl::string_view bytes,
                                      uint64_t max_pixels = kMaxPicturePixels);

/// The object's silhouette in `picture` (CV_8UC1, CV_8UC3 or CV_8UC4):
/// image_size x image_size bytes, row-major, 1 where covered. InvalidArgument
/// for bad options, another image type, or a picture in which no object
/// stands out (a plain picture, a 1 x 1 one).
absl::StatusOr<std::vector<uint8_t>> PictureSilhouette(const cv::Mat& picture,
                                                       const PictureSilhouetteOptions& options);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_GLOBAL_PICTURE_SILHOUETTE_H_
