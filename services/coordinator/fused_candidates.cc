#include "services/coordinator/fused_candidates.h"

#include <algorithm>
#include <limits>
#include <string>

#include "absl/container/flat_hash_map.h"
#include "absl/container/flat_hash_set.h"
#include "absl/strings/str_cat.h"
#include "common/base/parallel.h"
#include "common/base/status_macros.h"
#include "common/features/local_feature_extractor.h"
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

namespace {

// One part's lists of a batch of rows: per row, the models and distances.
using BatchLists = std::vector<std::vector<IndexShards::Scored>>;

// Each row's union of the proposing parts' lists, as nodes in increasing
// order (a model added since the export has no node: it waits for the next
// build).
std::vector<std::vector<uint32_t>> Unions(const std::vector<BatchLists>& lists,
                                          const std::vector<bool>& proposes,
                                          const IndexShards::PartModels& models,
                                          std::size_t rows) {
  std::vector<std::vector<uint32_t>> unions(rows);
  for (std::size_t r = 0; r < rows; ++r) {
    for (std::size_t p = 0; p < lists.size(); ++p) {
      if (!proposes[p]) continue;
      for (const IndexShards::Scored& s : lists[p][r]) {
        const auto node = models.row_of.find(s.model_id);
        if (node != models.row_of.end()) unions[r].push_back(static_cast<uint32_t>(node->second));
      }
    }
    std::sort(unions[r].begin(), unions[r].end());
    unions[r].erase(std::unique(unions[r].begin(), unions[r].end()), unions[r].end());
  }
  return unions;
}

// Writes the distances of `scored` into `row`, the distances to `row_union`.
void Place(const std::vector<IndexShards::Scored>& scored,
           const IndexShards::PartModels& models,
           const std::vector<uint32_t>& row_union,
           std::vector<float>* row,
           std::vector<bool>* known) {
  for (const IndexShards::Scored& s : scored) {
    const auto node = models.row_of.find(s.model_id);
    if (node == models.row_of.end()) continue;
    const auto at = std::lower_bound(row_union.begin(), row_union.end(), node->second);
    if (at == row_union.end() || *at != node->second) continue;
    (*row)[at - row_union.begin()] = s.distance;
    (*known)[at - row_union.begin()] = true;
  }
}

// One part's distances from each row's model to its union: what its lists
// hold, the rest in one PairDistances call.
absl::StatusOr<std::vector<std::vector<float>>> UnionDistances(
    IndexShards* index,
    const IndexShards::Part& part,
    const std::vector<std::string>& ids,
    const BatchLists* lists,  // nullptr: the part did not propose
    const std::vector<std::vector<uint32_t>>& unions,
    const IndexShards::PartModels& models) {
  std::vector<std::vector<float>> rows(ids.size());
  std::vector<std::vector<bool>> known(ids.size());
  std::vector<std::vector<std::string>> missing(ids.size());
  for (std::size_t r = 0; r < ids.size(); ++r) {
    rows[r].assign(unions[r].size(), std::numeric_limits<float>::infinity());
    known[r].assign(unions[r].size(), false);
    if (lists != nullptr) Place((*lists)[r], models, unions[r], &rows[r], &known[r]);
    for (std::size_t j = 0; j < unions[r].size(); ++j) {
      if (!known[r][j]) missing[r].push_back(models.models[0][unions[r][j]].model_id());
    }
  }
  MESHSEEK_ASSIGN_OR_RETURN(const BatchLists got, index->PairDistances(part, ids, missing));
  for (std::size_t r = 0; r < ids.size(); ++r) Place(got[r], models, unions[r], &rows[r], &known[r]);
  return rows;
}

}  // namespace

absl::StatusOr<NeighborGraph> ApproximateNeighborGraph(IndexShards* index,
                                                       const CollectionPlan& plan,
                                                       const IndexShards::PartModels& models,
                                                       absl::Span<const double> factors,
                                                       int k,
                                                       const RankingGraphOptions& options) {
  const std::size_t n = models.size();
  const std::size_t parts = plan.parts.size();
  std::vector<IndexShards::Part> index_parts;
  // The parts that propose: the histogram ones (every part when none is).
  std::vector<bool> proposes(parts);
  bool any_histogram = false;
  for (std::size_t p = 0; p < parts; ++p) {
    index_parts.push_back({plan.parts[p].name, plan.parts[p].options.kl.epsilon});
    proposes[p] = FeatureMethodInfoOf(plan.parts[p].options.extractor.method).kind !=
                  DescriptorKind::kGlobal;
    any_histogram |= proposes[p];
  }
  if (!any_histogram) proposes.assign(parts, true);
  const uint32_t c = options.graph_candidates;
  MESHSEEK_ASSIGN_OR_RETURN(NeighborGraph graph, NeighborGraph::Create(n, k));
  for (std::size_t begin = 0; begin < n; begin += kGraphBatch) {
    const std::size_t end = std::min(n, begin + kGraphBatch);
    std::vector<std::string> ids;
    for (std::size_t i = begin; i < end; ++i) ids.push_back(models.models[0][i].model_id());
    // 1. Each proposing part's lists of the batch, one call a part.
    std::vector<BatchLists> lists(parts);
    MESHSEEK_RETURN_IF_ERROR(ForEachPart(parts, [&](std::size_t p) -> absl::Status {
      if (!proposes[p]) return absl::OkStatus();
      MESHSEEK_ASSIGN_OR_RETURN(lists[p], index->Neighbors(index_parts[p], ids, c, c));
      return absl::OkStatus();
    }));
    // 2. Every part's distances to each row's union.
    const std::vector<std::vector<uint32_t>> unions = Unions(lists, proposes, models, ids.size());
    std::vector<std::vector<std::vector<float>>> rows(parts);
    MESHSEEK_RETURN_IF_ERROR(ForEachPart(parts, [&](std::size_t p) -> absl::Status {
      MESHSEEK_ASSIGN_OR_RETURN(rows[p], UnionDistances(index, index_parts[p], ids,
                                                        proposes[p] ? &lists[p] : nullptr,
                                                        unions, models));
      return absl::OkStatus();
    }));
    // 3. Fused with FuseRows' arithmetic, each row's list from its union.
    ParallelFor(ids.size(), options.threads, [&](std::size_t r) {
      std::vector<absl::Span<const float>> spans(parts);
      for (std::size_t p = 0; p < parts; ++p) spans[p] = rows[p][r];
      std::vector<float> fused(unions[r].size());
      FuseRows(spans, factors, absl::MakeSpan(fused));
      std::vector<GraphNeighbor> known(unions[r].size());
      for (std::size_t j = 0; j < unions[r].size(); ++j) known[j] = {unions[r][j], fused[j]};
      graph.SetSparseRow(static_cast<uint32_t>(begin + r), known);
    });
  }
  return graph;
}

}  // namespace meshseek
