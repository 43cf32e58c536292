#include "common/render/png.h"

#include <gtest/gtest.h>

#include <string>

namespace meshseek {
namespace {

// An image of `type` whose every byte differs from its neighbours'.
cv::Mat Pattern(int type, int rows, int cols) {
  cv::Mat image(rows, cols, type);
  for (std::size_t i = 0; i < image.total() * image.elemSize(); ++i) {
    image.data[i] = static_cast<uchar>(i * 37 + 11);
  }
  return image;
}

TEST(PngTest, GreyColourAndAlphaComeBackByteForByte) {
  for (const int type : {CV_8UC1, CV_8UC3, CV_8UC4}) {
    const cv::Mat image = Pattern(type, 17, 23);
    const absl::StatusOr<std::string> png = EncodePng(image);
    ASSERT_TRUE(png.ok()) << png.status();
    EXPECT_EQ(png->substr(1, 3), "PNG");
    const absl::StatusOr<cv::Mat> back = DecodePng(*png);
    ASSERT_TRUE(back.ok()) << back.status();
    ASSERT_EQ(back->type(), type);
    ASSERT_EQ(back->size(), image.size());
    EXPECT_EQ(cv::norm(*back, image, cv::NORM_INF), 0) << "type " << type;
  }
}

TEST(PngTest, AViewOfALargerImageIsWrittenByItsRows) {
  const cv::Mat big = Pattern(CV_8UC3, 20, 30);
  const cv::Mat view = big(cv::Rect(3, 4, 10, 5));  // step larger than 10 pixels
  const absl::StatusOr<cv::Mat> back = DecodePng(*EncodePng(view));
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(cv::norm(*back, view, cv::NORM_INF), 0);
}

TEST(PngTest, RefusesWhatItCannotWriteOrRead) {
  EXPECT_EQ(EncodePng(cv::Mat()).status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(EncodePng(cv::Mat(4, 4, CV_32FC1)).status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(DecodePng("").status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(DecodePng("not a png at all").status().code(), absl::StatusCode::kInvalidArgument);
  const std::string png = *EncodePng(Pattern(CV_8UC1, 40, 40));
  // Truncated: the header reads, the pixels do not.
  EXPECT_EQ(DecodePng(png.substr(0, png.size() / 2)).status().code(),
            absl::StatusCode::kInvalidArgument);
  // Over the pixel limit, refused before any pixel is decoded.
  const absl::Status big = DecodePng(png, 1000).status();
  EXPECT_EQ(big.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(big.message().find("40 x 40"), std::string::npos) << big;
  EXPECT_EQ(WritePng("/nonexistent-folder/x.png", Pattern(CV_8UC1, 2, 2)).code(),
            absl::StatusCode::kPermissionDenied);
}

}  // namespace
}  // namespace meshseek
