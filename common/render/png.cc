#include "common/render/png.h"

#include <png.h>

#include <cstring>
#include <optional>

#include "absl/strings/str_cat.h"
#include "common/base/file_io.h"

namespace meshseek {
namespace {

// The simplified API's pixel format of an OpenCV 8-bit type (PNG_FORMAT_GRAY
// is 0); none for others.
std::optional<png_uint_32> FormatOf(int type) {
  switch (type) {
    case CV_8UC1: return PNG_FORMAT_GRAY;
    case CV_8UC3: return PNG_FORMAT_BGR;
    case CV_8UC4: return PNG_FORMAT_BGRA;
    default: return std::nullopt;
  }
}

// Frees the simplified API's state on every path (png_image_finish_read
// and the write calls free it themselves; png_image_free is then a no-op).
struct ImageGuard {
  png_image* image;
  ~ImageGuard() { png_image_free(image); }
};

}  // namespace

absl::StatusOr<std::string> EncodePng(const cv::Mat& image) {
  const std::optional<png_uint_32> format = FormatOf(image.type());
  if (image.empty() || !format.has_value()) {
    return absl::InvalidArgumentError(absl::StrCat("PNG: cannot encode an image of ", image.cols,
                                                   " x ", image.rows, " of OpenCV type ",
                                                   image.type(), " (8-bit, 1, 3 or 4 channels)"));
  }
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(image.cols);
  png.height = static_cast<png_uint_32>(image.rows);
  png.format = *format;
  ImageGuard guard{&png};
  const png_int_32 stride = static_cast<png_int_32>(image.step[0]);
  // The first call sizes the file, the second writes it.
  png_alloc_size_t size = 0;
  if (!png_image_write_to_memory(&png, nullptr, &size, 0, image.data, stride, nullptr)) {
    return absl::InternalError(absl::StrCat("PNG: ", png.message));
  }
  std::string bytes(size, '\0');
  if (!png_image_write_to_memory(&png, bytes.data(), &size, 0, image.data, stride, nullptr)) {
    return absl::InternalError(absl::StrCat("PNG: ", png.message));
  }
  bytes.resize(size);
  return bytes;
}

absl::Status WritePng(const std::string& path, const cv::Mat& image) {
  absl::StatusOr<std::string> bytes = EncodePng(image);
  if (!bytes.ok()) return bytes.status();
  return WriteStringToFile(path, *bytes);
}

absl::StatusOr<cv::Mat> DecodePng(absl::string_view bytes, uint64_t max_pixels) {
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  ImageGuard guard{&png};
  if (!png_image_begin_read_from_memory(&png, bytes.data(), bytes.size())) {
    return absl::InvalidArgumentError(absl::StrCat("not a PNG file we can read: ", png.message));
  }
  const uint64_t pixels = uint64_t{png.width} * png.height;
  if (pixels == 0 || pixels > max_pixels) {
    return absl::InvalidArgumentError(absl::StrCat("PNG of ", png.width, " x ", png.height,
                                                   " pixels: at most ", max_pixels, " allowed"));
  }
  int type = CV_8UC1;
  if (png.format & PNG_FORMAT_FLAG_ALPHA) {
    png.format = PNG_FORMAT_BGRA, type = CV_8UC4;
  } else if (png.format & PNG_FORMAT_FLAG_COLOR) {
    png.format = PNG_FORMAT_BGR, type = CV_8UC3;
  } else {
    png.format = PNG_FORMAT_GRAY;
  }
  cv::Mat image(static_cast<int>(png.height), static_cast<int>(png.width), type);
  if (!png_image_finish_read(&png, nullptr, image.data, static_cast<png_int_32>(image.step[0]),
                             nullptr)) {
    return absl::InvalidArgumentError(absl::StrCat("PNG: ", png.message));
  }
  return image;
}

}  // namespace meshseek
