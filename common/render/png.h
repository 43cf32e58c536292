// PNG files of 8-bit images (thumbnails, the inspect command's pictures) with
// libpng's simplified API, rather than OpenCV's imgcodecs: imgcodecs loads
// about 140 shared libraries (GDAL, GDCM, HEIF, OpenEXR, ...) when a process
// starts, 65 ms measured on the development machine, which every `meshseek`
// command and service start paid for writing a PNG now and then (the CLI
// started in 107 ms with it).
//
// Images are OpenCV matrices in OpenCV's channel order: CV_8UC1 (grey),
// CV_8UC3 (BGR), CV_8UC4 (BGRA, straight alpha).
#ifndef MESHSEEK_COMMON_RENDER_PNG_H_
#define MESHSEEK_COMMON_RENDER_PNG_H_

#include <opencv2/core.hpp>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace meshseek {

/// The PNG file of `image` (zlib's default compression). InvalidArgument for
/// an empty image or another type.
absl::StatusOr<std::string> EncodePng(const cv::Mat& image);

/// EncodePng written to `path`; PermissionDenied naming the path when it
/// cannot be written.
absl::Status WritePng(const std::string& path, const cv::Mat& image);

/// A PNG file's pixels as CV_8UC1, CV_8UC3 or CV_8UC4 as it holds grey,
/// colour or an alpha channel (16-bit samples reduced to 8, palettes
/// expanded). InvalidArgument naming what is wrong for bytes that are not a
/// PNG file, or one larger than `max_pixels`, checked before decoding.
absl::StatusOr<cv::Mat> DecodePng(absl::string_view bytes, uint64_t max_pixels = 1 << 26);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_RENDER_PNG_H_
