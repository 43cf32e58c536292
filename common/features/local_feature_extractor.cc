#include "common/features/local_feature_extractor.h"

#include "absl/strings/str_cat.h"

namespace meshseek {

absl::StatusOr<FeatureMethod> ParseFeatureMethod(absl::string_view name) {
  if (name == "dld") return FeatureMethod::kDldSift;
  return absl::InvalidArgumentError(
      absl::StrCat("unknown feature method '", name, "' (known: dld)"));
}

const char* FeatureMethodName(FeatureMethod method) {
  switch (method) {
    case FeatureMethod::kDldSift: return "dld";
  }
  return "?";
}

absl::Status ExtractorOptions::Validate() const {
  switch (method) {
    case FeatureMethod::kDldSift: return dld.Validate();
  }
  return absl::InvalidArgumentError("unknown feature method");
}

Json ExtractorOptions::ToJson() const {
  Json json = Json::MakeObject();
  json.Set("method", FeatureMethodName(method));
  switch (method) {
    case FeatureMethod::kDldSift: {
      json.Set("num_points", dld.num_points);
      json.Set("scale_E", dld.scale);
      json.Set("support_radius", "E * D / 2 (D: minimum enclosing sphere diameter)");
      json.Set("two_views", dld.two_views);
      json.Set("frame_samples_per_support", dld.frame_samples_per_support);
      json.Set("weighted_frame", dld.weighted_frame);
      json.Set("image_size", dld.depth_image.image_size);
      json.Set("depth_to_gray",
               dld.descriptor.depth_to_gray == DepthToGray::kFixedRange ? "fixed_range" : "stretch");
      json.Set("orientation", dld.descriptor.orientation == ImageOrientation::kUpAxis
                                  ? "up_axis_180_sum"
                                  : "dominant_gradient");
      json.Set("sift_blur_sigma", dld.descriptor.blur_sigma);
      json.Set("symmetrize_180", dld.descriptor.symmetrize_180);
      break;
    }
  }
  return json;
}

absl::StatusOr<LocalFeatures> ExtractLocalFeatures(const TriangleMesh& mesh,
                                                   const ExtractorOptions& options) {
  switch (options.method) {
    case FeatureMethod::kDldSift: return ExtractDldSift(mesh, options.dld);
  }
  return absl::InvalidArgumentError("unknown feature method");
}

}  // namespace meshseek
