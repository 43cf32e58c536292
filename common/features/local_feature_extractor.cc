#include "common/features/local_feature_extractor.h"

#include "absl/strings/str_cat.h"

namespace meshseek {
namespace {

void DescriptorToJson(const SiftDescriptorOptions& d, Json* json) {
  json->Set("depth_to_gray",
            d.depth_to_gray == DepthToGray::kFixedRange ? "fixed_range" : "stretch");
  json->Set("orientation",
            d.orientation == ImageOrientation::kUpAxis ? "up_axis_180_sum" : "dominant_gradient");
  json->Set("max_orientations", d.max_orientations);
  json->Set("sift_blur_sigma", d.blur_sigma);
}

void ScaleSpaceToJson(const ScaleSpaceOptions& s, Json* json) {
  json->Set("levels_L", s.levels);
  json->Set("scale_factor_C", s.scale_factor);
  json->Set("support_radius", "C * d * sqrt(l) (d: mean edge length at the point, l: level)");
}

}  // namespace

absl::StatusOr<FeatureMethod> ParseFeatureMethod(absl::string_view name) {
  if (name == "dld") return FeatureMethod::kDldSift;
  if (name == "ld") return FeatureMethod::kLdSift;
  if (name == "rld") return FeatureMethod::kRldSift;
  return absl::InvalidArgumentError(
      absl::StrCat("unknown feature method '", name, "' (known: dld, ld, rld)"));
}

const char* FeatureMethodName(FeatureMethod method) {
  switch (method) {
    case FeatureMethod::kDldSift:
      return "dld";
    case FeatureMethod::kLdSift:
      return "ld";
    case FeatureMethod::kRldSift:
      return "rld";
  }
  return "?";
}

absl::Status ExtractorOptions::Validate() const {
  switch (method) {
    case FeatureMethod::kDldSift:
      return dld.Validate();
    case FeatureMethod::kLdSift:
      return ld.Validate();
    case FeatureMethod::kRldSift:
      return rld.Validate();
  }
  return absl::InvalidArgumentError("unknown feature method");
}

Json ExtractorOptions::ToJson() const {
  Json json = Json::MakeObject();
  json.Set("method", FeatureMethodName(method));
  switch (method) {
    case FeatureMethod::kDldSift:
      json.Set("num_points", dld.num_points);
      json.Set("scale_E", dld.scale);
      json.Set("support_radius", "E * D / 2 (D: minimum enclosing sphere diameter)");
      json.Set("two_views", dld.two_views);
      json.Set("frame_samples_per_support", dld.frame_samples_per_support);
      json.Set("weighted_frame", dld.weighted_frame);
      json.Set("frame_radius_factor", dld.frame_radius_factor);
      json.Set("image_size", dld.depth_image.image_size);
      DescriptorToJson(dld.descriptor, &json);
      break;
    case FeatureMethod::kLdSift:
      ScaleSpaceToJson(ld.scale_space, &json);
      json.Set("graph", "mesh vertex 1-ring (OpenMesh)");
      json.Set("two_views", false);
      json.Set("image_size", ld.depth_image.image_size);
      DescriptorToJson(ld.descriptor, &json);
      break;
    case FeatureMethod::kRldSift:
      json.Set("num_samples_N_RLD", rld.num_samples);
      json.Set("neighbors_k", rld.neighbors);
      ScaleSpaceToJson(rld.scale_space, &json);
      json.Set("two_views", rld.two_views);
      json.Set("weighted_frame", rld.weighted_frame);
      json.Set("image_size", rld.depth_image.image_size);
      DescriptorToJson(rld.descriptor, &json);
      break;
  }
  return json;
}

absl::StatusOr<LocalFeatures> ExtractLocalFeatures(const TriangleMesh& mesh,
                                                   const ExtractorOptions& options,
                                                   const PointGraph* resampled) {
  switch (options.method) {
    case FeatureMethod::kDldSift:
      return ExtractDldSift(mesh, options.dld);
    case FeatureMethod::kLdSift:
      return ExtractLdSift(mesh, options.ld);
    case FeatureMethod::kRldSift:
      if (resampled != nullptr) return DescribeRldSift(mesh, *resampled, options.rld);
      return ExtractRldSift(mesh, options.rld);
  }
  return absl::InvalidArgumentError("unknown feature method");
}

}  // namespace meshseek
