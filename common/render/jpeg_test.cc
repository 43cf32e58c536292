#include "common/render/jpeg.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <string>

namespace meshseek {
namespace {

// A smooth picture (JPEG keeps it within a few levels): a disc on a ramp.
cv::Mat Picture(int type, int rows, int cols) {
  cv::Mat image(rows, cols, type);
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      for (int c = 0; c < image.channels(); ++c) {
        image.ptr<uint8_t>(y)[x * image.channels() + c] = static_cast<uint8_t>(40 + x + 30 * c);
      }
    }
  }
  cv::circle(image, {cols / 2, rows / 2}, rows / 4, cv::Scalar::all(220), cv::FILLED);
  return image;
}

TEST(JpegTest, GreyAndColourComeBackClose) {
  for (const int type : {CV_8UC1, CV_8UC3}) {
    const cv::Mat image = Picture(type, 64, 80);
    const absl::StatusOr<std::string> jpeg = EncodeJpeg(image, 95);
    ASSERT_TRUE(jpeg.ok()) << jpeg.status();
    const absl::StatusOr<cv::Mat> back = DecodeJpeg(*jpeg);
    ASSERT_TRUE(back.ok()) << back.status();
    ASSERT_EQ(back->type(), type);
    ASSERT_EQ(back->size(), image.size());
    // Lossy, so close on average, not exact.
    EXPECT_LT(cv::norm(*back, image, cv::NORM_L1) / static_cast<double>(image.total()), 6)
        << "type " << type;
  }
}

TEST(JpegTest, RefusesWhatItCannotWriteOrRead) {
  EXPECT_EQ(EncodeJpeg(cv::Mat()).status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(EncodeJpeg(cv::Mat(4, 4, CV_8UC4)).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(EncodeJpeg(cv::Mat(4, 4, CV_8UC1), 0).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(DecodeJpeg("").status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(DecodeJpeg("not a jpeg at all").status().code(), absl::StatusCode::kInvalidArgument);
  const std::string jpeg = *EncodeJpeg(Picture(CV_8UC3, 40, 40));
  // Only the start marker: libjpeg's fatal error, caught.
  EXPECT_EQ(DecodeJpeg(jpeg.substr(0, 4)).status().code(), absl::StatusCode::kInvalidArgument);
  // Truncated after the header: libjpeg warns and fills grey; refused.
  const absl::Status truncated = DecodeJpeg(jpeg.substr(0, jpeg.size() * 2 / 3)).status();
  EXPECT_EQ(truncated.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(truncated.message().find("truncated"), std::string::npos) << truncated;
  // Over the pixel limit, refused before any pixel is decoded.
  const absl::Status big = DecodeJpeg(jpeg, 1000).status();
  EXPECT_EQ(big.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(big.message().find("40 x 40"), std::string::npos) << big;
}

TEST(JpegTest, AHugeDeclaredSizeIsRefusedFromTheHeader) {
  std::string jpeg = *EncodeJpeg(Picture(CV_8UC1, 16, 16));
  // The baseline frame header (FF C0, length, precision, height, width):
  // declare 60,000 x 60,000 pixels.
  const std::size_t sof = jpeg.find("\xFF\xC0");
  ASSERT_NE(sof, std::string::npos);
  jpeg[sof + 5] = jpeg[sof + 7] = static_cast<char>(0xEA);
  jpeg[sof + 6] = jpeg[sof + 8] = static_cast<char>(0x60);
  const absl::Status status = DecodeJpeg(jpeg).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(status.message().find("60000 x 60000"), std::string::npos) << status;
}

}  // namespace
}  // namespace meshseek
