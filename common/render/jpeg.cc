#include "common/render/jpeg.h"

// jpeglib.h needs FILE and size_t declared before it.
#include <cstddef>
#include <cstdio>
#include <cstdlib>
// clang-format off
#include <jpeglib.h>
// clang-format on

#include <csetjmp>
#include <limits>

#include "absl/strings/str_cat.h"

namespace meshseek {
namespace {

// libjpeg's error manager with a place to jump back to and the last message.
struct ErrorManager {
  jpeg_error_mgr pub;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX] = "";
};

[[noreturn]] void OnFatal(j_common_ptr info) {
  auto* err = reinterpret_cast<ErrorManager*>(info->err);
  (*info->err->format_message)(info, err->message);
  std::longjmp(err->jump, 1);
}

// Warnings are counted by libjpeg (num_warnings) and their text kept here;
// nothing is printed.
void OnMessage(j_common_ptr info) {
  auto* err = reinterpret_cast<ErrorManager*>(info->err);
  (*info->err->format_message)(info, err->message);
}

void Install(ErrorManager* err) {
  jpeg_std_error(&err->pub);
  err->pub.error_exit = OnFatal;
  err->pub.output_message = OnMessage;
}

// Runs one libjpeg step, false if libjpeg raised a fatal error in it. The
// step's frame holds no object with a destructor: longjmp skips none.
template <typename Step>
bool Guarded(ErrorManager* err, Step&& step) {
  if (setjmp(err->jump) != 0) return false;
  step();
  return true;
}

struct Decompressor {
  jpeg_decompress_struct info{};
  ErrorManager err;
  bool created = false;
  ~Decompressor() {
    if (created) jpeg_destroy_decompress(&info);
  }
};

struct Compressor {
  jpeg_compress_struct info{};
  ErrorManager err;
  bool created = false;
  unsigned char* out = nullptr;
  unsigned long size = 0;  // NOLINT(runtime/int): libjpeg's type
  ~Compressor() {
    if (created) jpeg_destroy_compress(&info);
    std::free(out);
  }
};

absl::Status Refused(const ErrorManager& err) {
  return absl::InvalidArgumentError(absl::StrCat("not a JPEG file we can read: ", err.message));
}

}  // namespace

absl::StatusOr<std::string> EncodeJpeg(const cv::Mat& image, int quality) {
  if (image.empty() || (image.type() != CV_8UC1 && image.type() != CV_8UC3) || quality < 1 ||
      quality > 100) {
    return absl::InvalidArgumentError(absl::StrCat(
        "JPEG: cannot encode an image of ", image.cols, " x ", image.rows, " of OpenCV type ",
        image.type(), " at quality ", quality, " (8-bit, 1 or 3 channels; quality 1 to 100)"));
  }
  Compressor c;
  c.info.err = &c.err.pub;
  Install(&c.err);
  const bool grey = image.type() == CV_8UC1;
  const bool ok = Guarded(&c.err, [&] {
    jpeg_create_compress(&c.info);
    c.created = true;
    jpeg_mem_dest(&c.info, &c.out, &c.size);
    c.info.image_width = static_cast<JDIMENSION>(image.cols);
    c.info.image_height = static_cast<JDIMENSION>(image.rows);
    c.info.input_components = grey ? 1 : 3;
    c.info.in_color_space = grey ? JCS_GRAYSCALE : JCS_EXT_BGR;
    jpeg_set_defaults(&c.info);
    jpeg_set_quality(&c.info, quality, TRUE);
    jpeg_start_compress(&c.info, TRUE);
    while (c.info.next_scanline < c.info.image_height) {
      JSAMPROW row = const_cast<JSAMPROW>(image.ptr<uint8_t>(static_cast<int>(c.info.next_scanline)));
      jpeg_write_scanlines(&c.info, &row, 1);
    }
    jpeg_finish_compress(&c.info);
  });
  if (!ok) return absl::InternalError(absl::StrCat("JPEG: ", c.err.message));
  return std::string(reinterpret_cast<const char*>(c.out), c.size);
}

absl::StatusOr<cv::Mat> DecodeJpeg(absl::string_view bytes, uint64_t max_pixels) {
  if (bytes.size() < 3 || static_cast<unsigned char>(bytes[0]) != 0xFF ||
      static_cast<unsigned char>(bytes[1]) != 0xD8) {
    return absl::InvalidArgumentError("not a JPEG file: it does not start with FF D8");
  }
  if (bytes.size() > std::numeric_limits<unsigned long>::max()) {  // NOLINT(runtime/int)
    return absl::InvalidArgumentError("JPEG file too large");
  }
  Decompressor d;
  d.info.err = &d.err.pub;
  Install(&d.err);
  if (!Guarded(&d.err, [&] {
        jpeg_create_decompress(&d.info);
        d.created = true;
        jpeg_mem_src(&d.info, reinterpret_cast<const unsigned char*>(bytes.data()),
                     static_cast<unsigned long>(bytes.size()));  // NOLINT(runtime/int)
        jpeg_read_header(&d.info, TRUE);
      })) {
    return Refused(d.err);
  }
  const uint64_t pixels = uint64_t{d.info.image_width} * d.info.image_height;
  if (pixels == 0 || pixels > max_pixels) {
    return absl::InvalidArgumentError(absl::StrCat("JPEG of ", d.info.image_width, " x ",
                                                   d.info.image_height, " pixels: at most ",
                                                   max_pixels, " allowed"));
  }
  const bool grey = d.info.num_components == 1;
  d.info.out_color_space = grey ? JCS_GRAYSCALE : JCS_EXT_BGR;
  if (!Guarded(&d.err, [&] { jpeg_start_decompress(&d.info); })) return Refused(d.err);
  cv::Mat image(static_cast<int>(d.info.output_height), static_cast<int>(d.info.output_width),
                grey ? CV_8UC1 : CV_8UC3);
  if (!Guarded(&d.err, [&] {
        while (d.info.output_scanline < d.info.output_height) {
          JSAMPROW row = image.ptr<uint8_t>(static_cast<int>(d.info.output_scanline));
          jpeg_read_scanlines(&d.info, &row, 1);
        }
        jpeg_finish_decompress(&d.info);
      })) {
    return Refused(d.err);
  }
  if (d.err.pub.num_warnings > 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("JPEG file truncated or corrupt: ", d.err.message));
  }
  return image;
}

}  // namespace meshseek
