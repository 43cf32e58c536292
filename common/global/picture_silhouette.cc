#include "common/global/picture_silhouette.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "absl/strings/str_cat.h"
#include "common/render/jpeg.h"
#include "common/render/png.h"

namespace meshseek {
namespace {

// The median of a channel's border pixels: the background's level.
int BorderMedian(const cv::Mat& channel) {
  std::vector<uint8_t> border;
  const int rows = channel.rows, cols = channel.cols;
  border.reserve(2 * static_cast<std::size_t>(rows + cols));
  for (int x = 0; x < cols; ++x) {
    border.push_back(channel.at<uint8_t>(0, x));
    border.push_back(channel.at<uint8_t>(rows - 1, x));
  }
  for (int y = 0; y < rows; ++y) {
    border.push_back(channel.at<uint8_t>(y, 0));
    border.push_back(channel.at<uint8_t>(y, cols - 1));
  }
  std::nth_element(border.begin(), border.begin() + border.size() / 2, border.end());
  return border[border.size() / 2];
}

// Step 1: 255 where the object is (header, "Method").
cv::Mat ForegroundMask(const cv::Mat& picture, int min_contrast) {
  std::vector<cv::Mat> channels;
  cv::split(picture, channels);
  cv::Mat mask;
  if (channels.size() == 4) {
    double lowest = 0;
    cv::minMaxLoc(channels[3], &lowest);
    if (lowest < 255) {
      cv::threshold(channels[3], mask, 127, 255, cv::THRESH_BINARY);
      return mask;
    }
    channels.pop_back();  // opaque everywhere: the colours decide
  }
  cv::Mat difference = cv::Mat::zeros(picture.size(), CV_8UC1);
  for (const cv::Mat& channel : channels) {
    cv::Mat d;
    cv::absdiff(channel, cv::Scalar::all(BorderMedian(channel)), d);
    cv::max(difference, d, difference);
  }
  const double otsu =
      cv::threshold(difference, mask, 0, 255, cv::THRESH_BINARY | cv::THRESH_OTSU);
  if (otsu < min_contrast) {
    cv::threshold(difference, mask, min_contrast - 1, 255, cv::THRESH_BINARY);
  }
  return mask;
}

// Step 2: the pieces of at least 1/50 of the largest one's area.
cv::Mat DropSpecks(const cv::Mat& mask) {
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8, CV_32S);
  int largest = 0;
  for (int i = 1; i < n; ++i) largest = std::max(largest, stats.at<int>(i, cv::CC_STAT_AREA));
  std::vector<uint8_t> keep(static_cast<std::size_t>(n), 0);
  for (int i = 1; i < n; ++i) {
    keep[i] = stats.at<int>(i, cv::CC_STAT_AREA) * 50 >= largest ? 255 : 0;
  }
  cv::Mat kept(mask.size(), CV_8UC1);
  for (int y = 0; y < mask.rows; ++y) {
    const int* label = labels.ptr<int>(y);
    uint8_t* out = kept.ptr<uint8_t>(y);
    for (int x = 0; x < mask.cols; ++x) out[x] = keep[label[x]];
  }
  return kept;
}

// Step 3: a line drawing filled; a filled silhouette as it is.
cv::Mat FillIfOutline(const cv::Mat& mask, double fill_ratio) {
  const cv::Rect box = cv::boundingRect(mask);
  const int gap = std::max(3, static_cast<int>(std::lround(0.02 * std::max(box.width, box.height))));
  cv::Mat closed;
  cv::morphologyEx(mask, closed, cv::MORPH_CLOSE,
                   cv::getStructuringElement(cv::MORPH_ELLIPSE, {gap | 1, gap | 1}));
  // The background is what the border reaches around the closed pieces.
  cv::Mat padded;
  cv::copyMakeBorder(closed, padded, 1, 1, 1, 1, cv::BORDER_CONSTANT, cv::Scalar(0));
  cv::floodFill(padded, cv::Point(0, 0), cv::Scalar(128));
  const cv::Mat filled = padded(cv::Rect(1, 1, mask.cols, mask.rows)) != 128;
  return cv::countNonZero(filled) >= fill_ratio * cv::countNonZero(mask) ? filled : mask;
}

// Step 4: the object framed in image_size x image_size, 1 where covered.
std::vector<uint8_t> Frame(const cv::Mat& mask, const PictureSilhouetteOptions& options) {
  const int size = options.image_size;
  const cv::Rect box = cv::boundingRect(mask);
  const double scale = options.object_extent * size / std::max(box.width, box.height);
  const cv::Size scaled(std::clamp(static_cast<int>(std::lround(box.width * scale)), 1, size),
                        std::clamp(static_cast<int>(std::lround(box.height * scale)), 1, size));
  cv::Mat small;
  cv::resize(mask(box), small, scaled, 0, 0, scale < 1 ? cv::INTER_AREA : cv::INTER_LINEAR);
  // A structure thinner than a pixel after the reduction still shows.
  const int threshold = cv::countNonZero(small >= 128) > 0 ? 128 : 1;
  std::vector<uint8_t> out(static_cast<std::size_t>(size) * size, 0);
  const int x0 = (size - scaled.width) / 2, y0 = (size - scaled.height) / 2;
  for (int y = 0; y < scaled.height; ++y) {
    const uint8_t* row = small.ptr<uint8_t>(y);
    for (int x = 0; x < scaled.width; ++x) {
      out[static_cast<std::size_t>(y0 + y) * size + x0 + x] = row[x] >= threshold ? 1 : 0;
    }
  }
  return out;
}

}  // namespace

absl::Status PictureSilhouetteOptions::Validate() const {
  if (image_size < 32 || image_size > 1024) {
    return absl::InvalidArgumentError(
        absl::StrCat("picture: image_size must be in [32, 1024], got ", image_size));
  }
  if (!(object_extent > 0 && object_extent <= 1)) {
    return absl::InvalidArgumentError(
        absl::StrCat("picture: object_extent must be in (0, 1], got ", object_extent));
  }
  if (min_contrast < 1 || min_contrast > 255) {
    return absl::InvalidArgumentError(
        absl::StrCat("picture: min_contrast must be in [1, 255], got ", min_contrast));
  }
  if (!(outline_fill_ratio > 1 && std::isfinite(outline_fill_ratio))) {
    return absl::InvalidArgumentError(
        absl::StrCat("picture: outline_fill_ratio must be above 1, got ", outline_fill_ratio));
  }
  return absl::OkStatus();
}

absl::StatusOr<cv::Mat> DecodePicture(absl::string_view bytes, uint64_t max_pixels) {
  if (bytes.size() >= 8 && bytes.substr(0, 8) == "\x89PNG\r\n\x1a\n") {
    return DecodePng(bytes, max_pixels);
  }
  if (bytes.size() >= 3 && bytes.substr(0, 3) == "\xFF\xD8\xFF") {
    return DecodeJpeg(bytes, max_pixels);
  }
  return absl::InvalidArgumentError(
      absl::StrCat("not a picture: ", bytes.size(), " bytes that are neither PNG nor JPEG"));
}

absl::StatusOr<std::vector<uint8_t>> PictureSilhouette(const cv::Mat& picture,
                                                       const PictureSilhouetteOptions& options) {
  if (absl::Status s = options.Validate(); !s.ok()) return s;
  const int type = picture.type();
  if (picture.empty() || (type != CV_8UC1 && type != CV_8UC3 && type != CV_8UC4)) {
    return absl::InvalidArgumentError(
        absl::StrCat("picture: ", picture.cols, " x ", picture.rows, " of OpenCV type ", type,
                     " is not an 8-bit grey, colour or colour-and-alpha picture"));
  }
  cv::Mat working = picture;
  const int longer = std::max(picture.cols, picture.rows);
  if (longer > kPictureWorkingSide) {
    const double f = static_cast<double>(kPictureWorkingSide) / longer;
    cv::resize(picture, working,
               cv::Size(std::max(1, static_cast<int>(std::lround(picture.cols * f))),
                        std::max(1, static_cast<int>(std::lround(picture.rows * f)))),
               0, 0, cv::INTER_AREA);
  }
  const cv::Mat mask = ForegroundMask(working, options.min_contrast);
  if (cv::countNonZero(mask) == 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "picture: no object stands out in ", picture.cols, " x ", picture.rows,
        " pixels: it is wholly transparent, or every pixel is within ", options.min_contrast - 1,
        " grey levels of its border's colour"));
  }
  return Frame(FillIfOutline(DropSpecks(mask), options.outline_fill_ratio), options);
}

}  // namespace meshseek
