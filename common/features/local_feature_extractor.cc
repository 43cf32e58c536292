#include "common/features/local_feature_extractor.h"

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "common/base/status_macros.h"

namespace meshseek {

namespace {

absl::StatusOr<LocalFeatures> ExtractDld(const TriangleMesh& mesh,
                                         const ExtractorOptions& options,
                                         const PointGraph*) {
  return ExtractDldSift(mesh, options.dld, options.num_threads);
}

absl::StatusOr<LocalFeatures> ExtractLd(const TriangleMesh& mesh,
                                        const ExtractorOptions& options,
                                        const PointGraph*) {
  return ExtractLdSift(mesh, options.ld, /*detected=*/nullptr, options.num_threads);
}

absl::StatusOr<LocalFeatures> ExtractRld(const TriangleMesh& mesh,
                                         const ExtractorOptions& options,
                                         const PointGraph* resampled) {
  if (resampled != nullptr) {
    return DescribeRldSift(mesh, *resampled, options.rld, /*detected=*/nullptr, options.num_threads);
  }
  return ExtractRldSift(mesh, options.rld, /*resampled=*/nullptr, /*detected=*/nullptr,
                        options.num_threads);
}

absl::StatusOr<LocalFeatures> ExtractBf(const TriangleMesh& mesh,
                                        const ExtractorOptions& options,
                                        const PointGraph*) {
  return ExtractBfDsift(mesh, options.bfdsift, options.num_threads);
}

absl::StatusOr<LocalFeatures> ExtractLocalStatistics(const TriangleMesh& mesh,
                                                     const ExtractorOptions& options,
                                                     const PointGraph*) {
  return ExtractLsf(mesh, options.lsf);
}

absl::StatusOr<LocalFeatures> ExtractLightField(const TriangleMesh& mesh,
                                                const ExtractorOptions& options,
                                                const PointGraph*) {
  MESHSEEK_ASSIGN_OR_RETURN(std::vector<uint8_t> descriptor, ExtractLfd(mesh, options.lfd));
  return GlobalDescriptorFeatures(std::move(descriptor));
}

float LightFieldDistance(const uint8_t* a, const uint8_t* b, std::size_t) {
  return LfdDistance(a, b);
}

}  // namespace

const std::vector<FeatureMethodInfo>& FeatureMethods() {
  static const auto* const kMethods = new std::vector<FeatureMethodInfo>{
      {FeatureMethod::kDldSift,
       "dld",
       "DLD-SIFT: dense local depth-image SIFT (the paper's)",
       DescriptorKind::kBagOfFeatures,
       2000,
       100,
       25,
       0,
       0,
       1,
       1,
       [](const ExtractorOptions& o) { return o.dld.Validate(); },
       ExtractDld},
      {FeatureMethod::kRldSift,
       "rld",
       "RLD-SIFT: LD-SIFT on a resampled point graph (the paper's)",
       DescriptorKind::kBagOfFeatures,
       2000,
       100,
       25,
       0,
       0,
       2,
       1,
       [](const ExtractorOptions& o) { return o.rld.Validate(); },
       ExtractRld},
      {FeatureMethod::kLdSift,
       "ld",
       "LD-SIFT (Darom & Keller): salient points on the mesh",
       DescriptorKind::kBagOfFeatures,
       2000,
       100,
       25,
       0,
       0,
       1,
       1,
       [](const ExtractorOptions& o) { return o.ld.Validate(); },
       ExtractLd},
      {FeatureMethod::kBfDsift,
       "bfdsift",
       "BF-DSIFT (Furuya & Ohbuchi): dense SIFT on depth views of the whole model",
       DescriptorKind::kBagOfFeatures,
       40000,
       40,
       6,
       4,
       3,
       2,
       1,
       [](const ExtractorOptions& o) { return o.bfdsift.Validate(); },
       ExtractBf},
      {FeatureMethod::kLsf,
       "lsf",
       "LSF: joint histograms of distance and normal angles about dense surface samples",
       DescriptorKind::kBagOfFeatures,
       2000,
       100,
       25,
       4,
       2,
       1.5,
       0.5,
       [](const ExtractorOptions& o) { return o.lsf.Validate(); },
       ExtractLocalStatistics},
      {FeatureMethod::kLfd,
       "lfd",
       "LFD (Chen et al.): Zernike and Fourier silhouette descriptors of 10 light fields",
       DescriptorKind::kGlobal,
       0,
       0,
       0,
       0,
       0,
       1,
       1,
       [](const ExtractorOptions& o) { return o.lfd.Validate(); },
       ExtractLightField,
       LightFieldDistance,
       kLfdDescriptorBytes,
       LfdViewDistance,
       kLfdViewStride},
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
  return absl::InvalidArgumentError(absl::StrCat(
      "unknown feature method '", name, "' (known: ", absl::StrJoin(known, ", "), ")"));
}

const char* FeatureMethodName(FeatureMethod method) { return FeatureMethodInfoOf(method).name; }

absl::StatusOr<float> GlobalDistance(FeatureMethod method,
                                     const LocalFeatures& a,
                                     const LocalFeatures& b) {
  const FeatureMethodInfo& info = FeatureMethodInfoOf(method);
  if (info.kind != DescriptorKind::kGlobal || info.distance == nullptr) {
    return absl::InvalidArgumentError(
        absl::StrCat("method ", info.name, " has no global descriptor distance"));
  }
  if (a.size() != 1 || b.size() != 1 || a.dimension != info.descriptor_bytes ||
      b.dimension != info.descriptor_bytes || a.descriptors.size() != a.dimension ||
      b.descriptors.size() != b.dimension) {
    return absl::InvalidArgumentError(absl::StrCat("method ",
                                                   info.name,
                                                   ": a global descriptor is one feature of ",
                                                   info.descriptor_bytes,
                                                   " bytes, got ",
                                                   a.size(),
                                                   " of ",
                                                   a.dimension,
                                                   " and ",
                                                   b.size(),
                                                   " of ",
                                                   b.dimension));
  }
  return info.distance(a.descriptors.data(), b.descriptors.data(), a.dimension);
}

absl::Status ExtractorOptions::Validate() const {
  return FeatureMethodInfoOf(method).validate(*this);
}

absl::StatusOr<LocalFeatures> ExtractLocalFeatures(const TriangleMesh& mesh,
                                                   const ExtractorOptions& options,
                                                   const PointGraph* resampled) {
  return FeatureMethodInfoOf(options.method).extract(mesh, options, resampled);
}

}  // namespace meshseek
