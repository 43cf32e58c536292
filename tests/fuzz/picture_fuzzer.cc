// A picture to query with, from arbitrary bytes: the PNG and JPEG decoders
// (bounded by their pixel limit, here 2^20 so that runs stay fast), the
// silhouette and its light-field view. What is accepted must be a silhouette
// of image_size^2 bytes, 0 or 1, with something covered, and describe.
#include <cstdint>
#include <cstdlib>

#include "common/global/lfd.h"
#include "common/global/picture_silhouette.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const absl::string_view bytes(reinterpret_cast<const char*>(data), size);
  const auto picture = meshseek::DecodePicture(bytes, uint64_t{1} << 20);
  if (!picture.ok()) {
    if (picture.status().message().empty()) std::abort();
    return 0;
  }
  const meshseek::PictureSilhouetteOptions options;
  const auto silhouette = meshseek::PictureSilhouette(*picture, options);
  if (!silhouette.ok()) {
    if (silhouette.status().code() != absl::StatusCode::kInvalidArgument) std::abort();
    return 0;
  }
  const int n = options.image_size;
  if (silhouette->size() != static_cast<std::size_t>(n) * n) std::abort();
  int covered = 0;
  for (const uint8_t b : *silhouette) {
    if (b > 1) std::abort();
    covered += b;
  }
  if (covered == 0) std::abort();
  if (!meshseek::DescribeLfdSilhouette({silhouette->data(), n, n}, {}).ok()) std::abort();
  return 0;
}
