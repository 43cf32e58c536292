#include "services/coordinator/coordinator_options.h"

#include <utility>

#include "absl/strings/str_cat.h"
#include "common/base/status_macros.h"
#include "services/coordinator/index_shards.h"

namespace meshseek {

absl::Status CoordinatorOptions::Validate() const {
  if (data_dir.empty()) return absl::InvalidArgumentError("coordinator: --data_dir is required");
  for (const auto& [name, target] : {std::pair<const char*, const std::string*>{"resample", &resample_target},
                                     {"extract", &extract_target},
                                     {"codebook", &codebook_target},
                                     {"index", &index_target}}) {
    if (target->empty()) {
      return absl::InvalidArgumentError(absl::StrCat("coordinator: the ", name, " target is empty"));
    }
  }
  MESHSEEK_RETURN_IF_ERROR(IndexShards::ParseTargets(index_target).status());
  if (max_in_flight < 1 || max_in_flight > 1024) {
    return absl::InvalidArgumentError(
        absl::StrCat("coordinator: max_in_flight must be in [1, 1024], got ", max_in_flight));
  }
  if (max_pending < 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("coordinator: max_pending must be at least 1, got ", max_pending));
  }
  if (call_attempts < 1 || extract_deadline <= absl::ZeroDuration() ||
      call_deadline <= absl::ZeroDuration()) {
    return absl::InvalidArgumentError("coordinator: attempts and deadlines must be positive");
  }
  MESHSEEK_RETURN_IF_ERROR(mesh_limits.Validate());
  if (model_attempts < 1 || model_attempts > 100) {
    return absl::InvalidArgumentError(
        absl::StrCat("coordinator: model_attempts must be in [1, 100], got ", model_attempts));
  }
  if (retry_backoff <= absl::ZeroDuration() || max_retry_backoff < retry_backoff) {
    return absl::InvalidArgumentError(absl::StrCat(
        "coordinator: retry_backoff must be positive and at most max_retry_backoff, got ",
        absl::FormatDuration(retry_backoff), " and ", absl::FormatDuration(max_retry_backoff)));
  }
  if (ranking_graph.query_candidates < 1 || ranking_graph.query_candidates > kMaxFusedCandidates) {
    return absl::InvalidArgumentError(absl::StrCat("coordinator: query_candidates must be in [1, ",
                                                   kMaxFusedCandidates, "], got ",
                                                   ranking_graph.query_candidates));
  }
  if (ranking_graph.graph_candidates < 1 || ranking_graph.graph_candidates > kMaxFusedCandidates ||
      ranking_graph.threads < 1) {
    return absl::InvalidArgumentError(absl::StrCat(
        "coordinator: graph_candidates must be in [1, ", kMaxFusedCandidates,
        "] and graph threads at least 1, got ", ranking_graph.graph_candidates, " and ",
        ranking_graph.threads));
  }
  return absl::OkStatus();
}

}  // namespace meshseek
