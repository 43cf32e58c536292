// JPEG files of 8-bit images with libjpeg (Debian's libjpeg-turbo), for the
// pictures users query with (common/global/picture_silhouette.h), not
// OpenCV's imgcodecs for the reason png.h gives.
//
// libjpeg reports a fatal error by calling a function that must not return;
// the decoder here leaves it by longjmp back to its own frame, and treats
// libjpeg's warnings (a truncated file: "Premature end of JPEG file", a
// corrupt segment) as errors too, so that a damaged file is refused rather
// than decoded into grey.
//
// Images are OpenCV matrices in OpenCV's channel order: CV_8UC1 (grey),
// CV_8UC3 (BGR).
#ifndef MESHSEEK_COMMON_RENDER_JPEG_H_
#define MESHSEEK_COMMON_RENDER_JPEG_H_

#include <cstdint>
#include <opencv2/core.hpp>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace meshseek {

/// The JPEG file of `image` (CV_8UC1 or CV_8UC3) at `quality` (1 to 100).
/// InvalidArgument for an empty image, another type or a bad quality.
absl::StatusOr<std::string> EncodeJpeg(const cv::Mat& image, int quality = 90);

/// A JPEG file's pixels as CV_8UC1 (grey) or CV_8UC3 (colour; CMYK and
/// other colour spaces converted by libjpeg). InvalidArgument naming what
/// is wrong for bytes that are not a JPEG file, a truncated or corrupt one,
/// or one larger than `max_pixels`, checked before any pixel is decoded.
absl::StatusOr<cv::Mat> DecodeJpeg(absl::string_view bytes, uint64_t max_pixels = 1 << 26);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_RENDER_JPEG_H_
