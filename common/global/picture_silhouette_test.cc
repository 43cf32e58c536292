#include "common/global/picture_silhouette.h"

#include <gtest/gtest.h>

#include <numeric>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "common/global/lfd.h"
#include "common/render/jpeg.h"
#include "common/render/png.h"

namespace meshseek {
namespace {

constexpr int kSize = 128;

// A white picture with a dark object: a disc with a bar through it
// (asymmetric enough to have a shape), `scale` times the base size, at `at`.
cv::Mat DrawnObject(int type, double scale, cv::Point at, int thickness = cv::FILLED) {
  cv::Mat picture(400, 600, type, cv::Scalar::all(255));
  const cv::Scalar ink(40, 60, 80, 255);
  cv::circle(picture, at, static_cast<int>(60 * scale), ink, thickness, cv::LINE_8);
  if (thickness == cv::FILLED) {
    cv::rectangle(picture, at + cv::Point(0, -static_cast<int>(12 * scale)),
                  at + cv::Point(static_cast<int>(130 * scale), static_cast<int>(12 * scale)), ink,
                  cv::FILLED);
  }
  return picture;
}

std::vector<uint8_t> Silhouette(const cv::Mat& picture) {
  absl::StatusOr<std::vector<uint8_t>> s = PictureSilhouette(picture, {});
  EXPECT_TRUE(s.ok()) << s.status();
  return s.ok() ? *s : std::vector<uint8_t>(kSize * kSize, 0);
}

int Covered(const std::vector<uint8_t>& s) { return std::accumulate(s.begin(), s.end(), 0); }

std::array<uint8_t, kLfdViewStride> Block(const std::vector<uint8_t>& s) {
  return *DescribeLfdSilhouette({s.data(), kSize, kSize}, LfdOptions{});
}

int L1(const std::array<uint8_t, kLfdViewStride>& a, const std::array<uint8_t, kLfdViewStride>& b) {
  int sum = 0;
  for (int k = 0; k < kLfdCoefficientsPerView; ++k) sum += std::abs(a[k] - b[k]);
  return sum;
}

TEST(PictureSilhouetteTest, AnObjectOnAPlainBackgroundIsFramedWhateverItsPlaceAndSize) {
  const std::vector<uint8_t> base = Silhouette(DrawnObject(CV_8UC3, 1.0, {250, 200}));
  // Framed: its longer side is 0.75 of the image (96 pixels), centred.
  const cv::Mat mask(kSize, kSize, CV_8UC1, const_cast<uint8_t*>(base.data()));
  const cv::Rect box = cv::boundingRect(mask);
  EXPECT_NEAR(std::max(box.width, box.height), 96, 1);
  EXPECT_NEAR(box.x + box.width / 2.0, kSize / 2.0, 1);
  EXPECT_NEAR(box.y + box.height / 2.0, kSize / 2.0, 1);
  const auto block = Block(base);
  // Grey, colour, or colour with an opaque alpha: the same object.
  for (const int type : {CV_8UC1, CV_8UC4}) {
    EXPECT_LE(L1(Block(Silhouette(DrawnObject(type, 1.0, {250, 200}))), block), 4) << type;
  }
  // Moved and scaled: nearly the same block (the pixels differ a little).
  EXPECT_LE(L1(Block(Silhouette(DrawnObject(CV_8UC3, 0.6, {150, 120}))), block), 30);
  EXPECT_LE(L1(Block(Silhouette(DrawnObject(CV_8UC3, 1.3, {260, 210}))), block), 30);
}

TEST(PictureSilhouetteTest, TransparencyIsTheSilhouetteWhenThereIsAny) {
  // The object is the background's colour; only its alpha tells it apart.
  cv::Mat picture(300, 300, CV_8UC4, cv::Scalar(255, 255, 255, 0));
  cv::rectangle(picture, {100, 50}, {200, 250}, cv::Scalar(255, 255, 255, 255), cv::FILLED);
  const std::vector<uint8_t> s = Silhouette(picture);
  const cv::Rect box = cv::boundingRect(cv::Mat(kSize, kSize, CV_8UC1, const_cast<uint8_t*>(s.data())));
  EXPECT_NEAR(box.height, 96, 1);
  EXPECT_NEAR(box.width, 48, 1);
  EXPECT_NEAR(Covered(s), 96 * 48, 150);
}

TEST(PictureSilhouetteTest, AnOutlineIsFilledAndAHoleInASolidIsKept) {
  const std::vector<uint8_t> disc = Silhouette(DrawnObject(CV_8UC1, 1.0, {300, 200}));
  // A circle drawn 2 pixels wide, with a gap in it, becomes the filled disc.
  cv::Mat outline(400, 600, CV_8UC1, cv::Scalar(255));
  cv::ellipse(outline, {300, 200}, {60, 60}, 0, 2, 360, cv::Scalar(0), 2);
  const std::vector<uint8_t> filled = Silhouette(outline);
  const int disc_area = static_cast<int>(3.14159 * 48 * 48);
  EXPECT_NEAR(Covered(filled), disc_area, disc_area * 0.05);
  EXPECT_EQ(filled[64 * kSize + 64], 1);
  // A ring with a large hole stays a ring (filling would add only a third).
  cv::Mat ring(400, 600, CV_8UC1, cv::Scalar(255));
  cv::circle(ring, {300, 200}, 60, cv::Scalar(0), cv::FILLED);
  cv::circle(ring, {300, 200}, 30, cv::Scalar(255), cv::FILLED);
  const std::vector<uint8_t> kept = Silhouette(ring);
  EXPECT_EQ(kept[64 * kSize + 64], 0);
  EXPECT_NEAR(Covered(kept), disc_area * 0.75, disc_area * 0.05);
  EXPECT_GT(Covered(disc), 0);
}

TEST(PictureSilhouetteTest, SpecksAndJpegNoiseDoNotCount) {
  cv::Mat picture = DrawnObject(CV_8UC3, 1.0, {250, 200});
  cv::circle(picture, {560, 360}, 3, cv::Scalar(0, 0, 0), cv::FILLED);  // a speck far away
  const std::vector<uint8_t> clean = Silhouette(DrawnObject(CV_8UC3, 1.0, {250, 200}));
  const std::vector<uint8_t> specked = Silhouette(picture);
  EXPECT_EQ(specked, clean);  // same bounding box, same pixels
  // Through JPEG: at quality 40 its ringing moves a few edge pixels (32 of
  // the block's L1, against 636 between this object and the disc without its
  // bar); at 60 and above nothing changes.
  cv::Mat disc(400, 600, CV_8UC3, cv::Scalar::all(255));
  cv::circle(disc, {250, 200}, 60, cv::Scalar(40, 60, 80), cv::FILLED);
  const int shape_difference = L1(Block(Silhouette(disc)), Block(clean));
  EXPECT_GT(shape_difference, 400);
  for (const int quality : {40, 60, 90}) {
    const absl::StatusOr<cv::Mat> decoded =
        DecodePicture(*EncodeJpeg(DrawnObject(CV_8UC3, 1.0, {250, 200}), quality));
    ASSERT_TRUE(decoded.ok()) << decoded.status();
    EXPECT_LE(L1(Block(Silhouette(*decoded)), Block(clean)) * 10, shape_difference) << quality;
  }
}

TEST(PictureSilhouetteTest, PicturesWithNoObjectAndBadInputAreRefused) {
  for (const cv::Mat& plain : {cv::Mat(1, 1, CV_8UC3, cv::Scalar(9, 9, 9)),
                               cv::Mat(50, 80, CV_8UC1, cv::Scalar(200)),
                               cv::Mat(50, 80, CV_8UC4, cv::Scalar(1, 2, 3, 0))}) {
    const absl::Status s = PictureSilhouette(plain, {}).status();
    EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
    EXPECT_NE(s.message().find("no object"), std::string::npos) << s;
  }
  // Noise below the least contrast is no object either.
  cv::Mat faint(60, 60, CV_8UC1, cv::Scalar(128));
  cv::randu(faint, 120, 136);
  EXPECT_EQ(PictureSilhouette(faint, {}).status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(PictureSilhouette(cv::Mat(), {}).status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(PictureSilhouette(cv::Mat(9, 9, CV_32FC1), {}).status().code(),
            absl::StatusCode::kInvalidArgument);
  PictureSilhouetteOptions bad;
  bad.image_size = 16;
  EXPECT_EQ(bad.Validate().code(), absl::StatusCode::kInvalidArgument);
  bad = {};
  bad.object_extent = 0;
  EXPECT_EQ(bad.Validate().code(), absl::StatusCode::kInvalidArgument);
  bad = {};
  bad.outline_fill_ratio = 1;
  EXPECT_EQ(bad.Validate().code(), absl::StatusCode::kInvalidArgument);
}

TEST(DecodePictureTest, PngAndJpegByTheirFirstBytesAnythingElseRefused) {
  const cv::Mat picture = DrawnObject(CV_8UC3, 1.0, {250, 200});
  const absl::StatusOr<cv::Mat> png = DecodePicture(*EncodePng(picture));
  ASSERT_TRUE(png.ok()) << png.status();
  EXPECT_EQ(cv::norm(*png, picture, cv::NORM_INF), 0);
  const absl::StatusOr<cv::Mat> jpeg = DecodePicture(*EncodeJpeg(picture));
  ASSERT_TRUE(jpeg.ok()) << jpeg.status();
  EXPECT_EQ(jpeg->size(), picture.size());
  for (const std::string& bytes : {std::string(), std::string("GIF89a"), std::string("\xFF\xD8", 2),
                                  std::string("\x89PNG\r\n\x1a\n", 8)}) {
    EXPECT_EQ(DecodePicture(bytes).status().code(), absl::StatusCode::kInvalidArgument);
  }
  EXPECT_EQ(DecodePicture(*EncodePng(picture), 1000).status().code(),
            absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace meshseek
