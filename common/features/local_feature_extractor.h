// One entry point for every local-feature method of the paper's table, so the
// pipeline, the CLI and (later) the extract service select a method by name
// and never depend on which one it is.
//
// Methods: "dld" (DLD-SIFT, dense; dld_sift.h), "ld" (LD-SIFT, the baseline;
// ld_sift.h) and "rld" (RLD-SIFT, resampled; rld_sift.h).
#ifndef MESHSEEK_COMMON_FEATURES_LOCAL_FEATURE_EXTRACTOR_H_
#define MESHSEEK_COMMON_FEATURES_LOCAL_FEATURE_EXTRACTOR_H_

#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "common/base/json.h"
#include "common/features/dld_sift.h"
#include "common/features/ld_sift.h"
#include "common/features/local_features.h"
#include "common/features/rld_sift.h"
#include "common/geometry/mesh.h"

namespace meshseek {

enum class FeatureMethod { kDldSift, kLdSift, kRldSift };

// "dld", "ld", "rld". InvalidArgument listing the known names otherwise.
absl::StatusOr<FeatureMethod> ParseFeatureMethod(absl::string_view name);
const char* FeatureMethodName(FeatureMethod method);

struct ExtractorOptions {
  /// Which method extracts the features.
  FeatureMethod method = FeatureMethod::kDldSift;
  /// Parameters of each method; only the selected method's are used.
  DldSiftOptions dld;
  LdSiftOptions ld;
  RldSiftOptions rld;

  /// Validates the options of the selected method.
  absl::Status Validate() const;
  /// The method and its parameters, for reports (metrics.json).
  Json ToJson() const;
};

// Extracts the local features of one mesh with the selected method, on the
// calling thread. LD-SIFT and RLD-SIFT may return an empty set (nothing
// detected); DLD-SIFT always describes its points. For RLD-SIFT, `resampled`
// may carry the graph ResampleSurfaceGraph made for this mesh with the
// options' num_samples and neighbors (the resample service's output); the
// result is the same as without it. Other methods ignore it.
absl::StatusOr<LocalFeatures> ExtractLocalFeatures(const TriangleMesh& mesh,
                                                   const ExtractorOptions& options,
                                                   const PointGraph* resampled = nullptr);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_FEATURES_LOCAL_FEATURE_EXTRACTOR_H_
