#include "services/coordinator/fused_candidates.h"

#include <algorithm>
#include <limits>
#include <string>

#include "absl/container/flat_hash_map.h"
#include "absl/container/flat_hash_set.h"
#include "absl/strings/str_cat.h"
#include "common/base/parallel.h"
#include "common/base/status_macros.h"
#include "common/search/fusion.h"

namespace meshseek {
namespace {

// Calls fn(p) for every part on its own thread; the first error.
template <typename Fn>
absl::Status ForEachPart(std::size_t parts, Fn&& fn) {
  std::vector<absl::Status> errors(parts);
  ParallelFor(parts, static_cast<int>(parts), [&](std::size_t p) { errors[p] = fn(p); });
  for (const absl::Status& e : errors) MESHSEEK_RETURN_IF_ERROR(e);
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<std::vector<std::vector<IndexShards::Scored>>> PartDistances(
    IndexShards* index,
    const CollectionPlan& plan,
    const std::vector<const IndexSignature*>& signatures,
    const std::vector<std::string>* only) {
  const std::size_t parts = plan.parts.size();
  if (signatures.size() != parts) {
    return absl::InternalError(absl::StrCat(signatures.size(), " signatures for ", parts, " parts"));
  }
  std::vector<std::vector<IndexShards::Scored>> distances(parts);
  std::vector<absl::Status> errors(parts);
  ParallelFor(parts, static_cast<int>(parts), [&](std::size_t p) {
    const CollectionInfo& part = plan.parts[p];
    v1::DistancesRequest ask;
    ask.set_collection(part.name);
    ask.set_kl_epsilon(part.options.kl.epsilon);
    if (signatures[p]->descriptor.has_value()) {
      *ask.add_global_queries() = *signatures[p]->descriptor;
    } else {
      *ask.add_queries() = signatures[p]->histogram;
    }
    if (only != nullptr) {
      for (const std::string& id : *only) ask.add_model_ids(id);
    }
    absl::StatusOr<std::vector<IndexShards::Scored>> got = index->QueryDistances(ask);
    if (got.ok()) {
      distances[p] = *std::move(got);
    } else {
      errors[p] = got.status();
    }
  });
  for (const absl::Status& e : errors) MESHSEEK_RETURN_IF_ERROR(e);
  return distances;
}

absl::StatusOr<std::vector<std::vector<IndexShards::Scored>>> CandidatePartDistances(
    IndexShards* index,
    const CollectionPlan& plan,
    const std::vector<const IndexSignature*>& signatures,
    uint32_t candidates) {
  const std::size_t parts = plan.parts.size();
  if (signatures.size() != parts) {
    return absl::InternalError(absl::StrCat(signatures.size(), " signatures for ", parts, " parts"));
  }
  if (candidates == 0 || candidates > kMaxFusedCandidates) {
    return absl::InvalidArgumentError(absl::StrCat("query: candidates=", candidates,
                                                   " on a fused or re-ranked collection must be in [1, ",
                                                   kMaxFusedCandidates, "]"));
  }
  // 1. The histogram parts' proposals (every part's when none is one): a
  //    global part's search is a scan of every descriptor, LFD's 18 us each.
  bool any_histogram = false;
  for (const IndexSignature* s : signatures) any_histogram |= !s->descriptor.has_value();
  std::vector<std::vector<v1::ScoredModel>> proposed(parts);
  MESHSEEK_RETURN_IF_ERROR(ForEachPart(parts, [&](std::size_t p) -> absl::Status {
    if (any_histogram && signatures[p]->descriptor.has_value()) return absl::OkStatus();
    const CollectionInfo& part = plan.parts[p];
    v1::SearchRequest search;
    search.set_collection(part.name);
    if (signatures[p]->descriptor.has_value()) {
      *search.mutable_global_descriptor() = *signatures[p]->descriptor;
    } else {
      *search.mutable_histogram() = signatures[p]->histogram;
    }
    search.set_top_k(candidates);
    search.set_candidates(candidates);
    search.set_kl_epsilon(part.options.kl.epsilon);
    MESHSEEK_ASSIGN_OR_RETURN(proposed[p], index->Search(search));
    return absl::OkStatus();
  }));
  // 2. Every part's distances to their union (sorted: the requests do not
  //    depend on the parts' timing).
  absl::flat_hash_set<std::string> seen;
  std::vector<std::string> ids;
  for (const auto& found : proposed) {
    for (const v1::ScoredModel& m : found) {
      if (seen.insert(m.model_id()).second) ids.push_back(m.model_id());
    }
  }
  std::sort(ids.begin(), ids.end());
  return PartDistances(index, plan, signatures, &ids);
}

absl::StatusOr<NeighborGraph> ApproximateNeighborGraph(IndexShards* index,
                                                       const CollectionPlan& plan,
                                                       const IndexShards::PartModels& models,
                                                       absl::Span<const double> factors,
                                                       int k,
                                                       const RankingGraphOptions& options) {
  const std::size_t n = models.size();
  const std::size_t parts = plan.parts.size();
  MESHSEEK_ASSIGN_OR_RETURN(NeighborGraph graph, NeighborGraph::Create(n, k));
  std::vector<absl::Status> errors(n);
  ParallelFor(n, options.threads, [&](std::size_t i) {
    std::vector<IndexSignature> own(parts);
    std::vector<const IndexSignature*> signatures(parts);
    for (std::size_t p = 0; p < parts; ++p) {
      const v1::IndexedModel& m = *models.entry[p][i];
      if (m.has_global_descriptor()) {
        own[p].descriptor = m.global_descriptor();
      } else {
        own[p].histogram = m.histogram();
      }
      signatures[p] = &own[p];
    }
    absl::StatusOr<std::vector<std::vector<IndexShards::Scored>>> distances =
        CandidatePartDistances(index, plan, signatures, options.graph_candidates);
    if (!distances.ok()) {
      errors[i] = distances.status();
      return;
    }
    // Each part's distances as rows over the union (the nodes in the first
    // part's answer order), fused with FuseRows' arithmetic.
    std::vector<uint32_t> nodes;
    absl::flat_hash_map<std::string, std::size_t> column;
    for (const IndexShards::Scored& s : (*distances)[0]) {
      const auto row = models.row_of.find(s.model_id);
      if (row == models.row_of.end()) continue;  // added since the export
      column[s.model_id] = nodes.size();
      nodes.push_back(static_cast<uint32_t>(row->second));
    }
    std::vector<std::vector<float>> rows(
        parts, std::vector<float>(nodes.size(), std::numeric_limits<float>::infinity()));
    for (std::size_t p = 0; p < parts; ++p) {
      for (const IndexShards::Scored& s : (*distances)[p]) {
        const auto c = column.find(s.model_id);
        if (c != column.end()) rows[p][c->second] = s.distance;
      }
    }
    std::vector<absl::Span<const float>> spans(rows.begin(), rows.end());
    std::vector<float> fused(nodes.size());
    FuseRows(spans, factors, absl::MakeSpan(fused));
    std::vector<GraphNeighbor> known(nodes.size());
    for (std::size_t c = 0; c < nodes.size(); ++c) known[c] = {nodes[c], fused[c]};
    graph.SetSparseRow(static_cast<uint32_t>(i), known);
  });
  for (const absl::Status& e : errors) MESHSEEK_RETURN_IF_ERROR(e);
  return graph;
}

}  // namespace meshseek
