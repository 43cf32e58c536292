#include "common/features/local_feature_extractor.h"

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"

namespace meshseek {

namespace {

absl::StatusOr<LocalFeatures> ExtractDld(const TriangleMesh& mesh,
                                         const ExtractorOptions& options,
                                         const PointGraph*) {
  return ExtractDldSift(mesh, options.dld);
}

absl::StatusOr<LocalFeatures> ExtractLd(const TriangleMesh& mesh,
                                        const ExtractorOptions& options,
                                        const PointGraph*) {
  return ExtractLdSift(mesh, options.ld);
}

absl::StatusOr<LocalFeatures> ExtractRld(const TriangleMesh& mesh,
                                         const ExtractorOptions& options,
                                         const PointGraph* resampled) {
  if (resampled != nullptr) return DescribeRldSift(mesh, *resampled, options.rld);
  return ExtractRldSift(mesh, options.rld);
}

}  // namespace

const std::vector<FeatureMethodInfo>& FeatureMethods() {
  static const auto* const kMethods = new std::vector<FeatureMethodInfo>{
      {FeatureMethod::kDldSift, "dld", "DLD-SIFT: dense local depth-image SIFT (the paper's)",
       DescriptorKind::kBagOfFeatures, 2000,
       [](const ExtractorOptions& o) { return o.dld.Validate(); }, ExtractDld},
      {FeatureMethod::kRldSift, "rld", "RLD-SIFT: LD-SIFT on a resampled point graph (the paper's)",
       DescriptorKind::kBagOfFeatures, 2000,
       [](const ExtractorOptions& o) { return o.rld.Validate(); }, ExtractRld},
      {FeatureMethod::kLdSift, "ld", "LD-SIFT (Darom & Keller): salient points on the mesh",
       DescriptorKind::kBagOfFeatures, 2000,
       [](const ExtractorOptions& o) { return o.ld.Validate(); }, ExtractLd},
  };
  return *kMethods;
}

const FeatureMethodInfo& FeatureMethodInfoOf(FeatureMethod method) {
  for (const FeatureMethodInfo& info : FeatureMethods()) {
    if (info.method == method) return info;
  }
  return FeatureMethods().front();  // unreachable: every enumerator is registered (tested)
}

absl::StatusOr<FeatureMethod> ParseFeatureMethod(absl::string_view name) {
  std::vector<std::string> known;
  for (const FeatureMethodInfo& info : FeatureMethods()) {
    if (name == info.name) return info.method;
    known.push_back(info.name);
  }
  return absl::InvalidArgumentError(absl::StrCat("unknown feature method '", name,
                                                 "' (known: ", absl::StrJoin(known, ", "), ")"));
}

const char* FeatureMethodName(FeatureMethod method) { return FeatureMethodInfoOf(method).name; }

absl::Status ExtractorOptions::Validate() const { return FeatureMethodInfoOf(method).validate(*this); }

absl::StatusOr<LocalFeatures> ExtractLocalFeatures(const TriangleMesh& mesh,
                                                   const ExtractorOptions& options,
                                                   const PointGraph* resampled) {
  return FeatureMethodInfoOf(options.method).extract(mesh, options, resampled);
}

}  // namespace meshseek
