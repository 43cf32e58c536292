#include "services/coordinator/ranking.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <tuple>

#include "absl/container/flat_hash_map.h"
#include "absl/strings/str_cat.h"
#include "common/base/byte_order.h"
#include "common/base/hash.h"
#include "common/base/parallel.h"
#include "common/base/status_macros.h"
#include "common/search/fusion.h"
#include "common/search/rerank.h"
#include "services/coordinator/fused_candidates.h"

namespace meshseek {
namespace {

constexpr char kMagic[4] = {'M', 'S', 'R', 'S'};
constexpr char kJoinMagic[4] = {'M', 'S', 'R', 'J'};
constexpr uint32_t kVersion = 1;
constexpr std::size_t kMaxText = 1 << 16;  // ids and labels are far shorter

void PutText(const std::string& text, std::string* out) {
  PutLittleEndian(text.size(), 4, out);
  out->append(text);
}

// Reads little-endian fields from bytes, bounded: every read checks what is
// left first.
class Reader {
 public:
  explicit Reader(absl::string_view bytes) : bytes_(bytes) {}
  bool Has(std::size_t n) const { return bytes_.size() - at_ >= n; }
  bool Int(int width, uint64_t* v) {
    if (!Has(width)) return false;
    *v = GetLittleEndian(bytes_.data() + at_, width);
    at_ += width;
    return true;
  }
  bool Double(double* v) {
    uint64_t bits;
    if (!Int(8, &bits)) return false;
    std::memcpy(v, &bits, sizeof(*v));
    return true;
  }
  bool Text(std::string* text) {
    uint64_t size;
    if (!Int(4, &size) || size > kMaxText || !Has(size)) return false;
    text->assign(bytes_.data() + at_, size);
    at_ += size;
    return true;
  }
  bool Bytes(std::size_t n, absl::string_view* out) {
    if (!Has(n)) return false;
    *out = bytes_.substr(at_, n);
    at_ += n;
    return true;
  }
  std::size_t left() const { return bytes_.size() - at_; }

 private:
  absl::string_view bytes_;
  std::size_t at_ = 0;
};

void PutNeighbors(const std::vector<GraphNeighbor>& list, std::string* out) {
  PutLittleEndian(list.size(), 4, out);
  for (const GraphNeighbor& e : list) {
    PutLittleEndian(e.node, 4, out);
    PutFloat(e.distance, out);
  }
}

bool ReadNeighbors(Reader* in, std::vector<GraphNeighbor>* list) {
  uint64_t size = 0;
  if (!in->Int(4, &size) || size > in->left() / 8) return false;
  list->resize(size);
  for (GraphNeighbor& e : *list) {
    uint64_t node = 0;
    absl::string_view distance;
    if (!in->Int(4, &node) || !in->Bytes(4, &distance)) return false;
    e = GraphNeighbor{static_cast<uint32_t>(node), GetFloat(distance.data())};
  }
  return true;
}

// The query's (or joining model's) distance to every node from each part's
// answers: +inf where a part did not answer; per node, how many parts did.
std::vector<std::vector<float>> NodeRows(
    const absl::flat_hash_map<std::string, uint32_t>& node_of,
    std::size_t n,
    const std::vector<std::vector<IndexShards::Scored>>& part_distances,
    std::vector<uint8_t>* answered) {
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<std::vector<float>> rows(part_distances.size(), std::vector<float>(n, inf));
  answered->assign(n, 0);
  for (std::size_t p = 0; p < part_distances.size(); ++p) {
    for (const IndexShards::Scored& s : part_distances[p]) {
      auto it = node_of.find(s.model_id);
      if (it == node_of.end()) continue;  // not (yet) in the state
      rows[p][it->second] = s.distance;
      (*answered)[it->second] += 1;
    }
  }
  return rows;
}

}  // namespace

std::string RankingJoin::Serialize() const {
  std::string out(kJoinMagic, sizeof(kJoinMagic));
  PutLittleEndian(kVersion, 4, &out);
  PutText(model_id, &out);
  PutLittleEndian(ordinal, 8, &out);
  PutText(label, &out);
  PutNeighbors(graph.list, &out);
  PutNeighbors(graph.entered, &out);
  PutLittleEndian(Fnv1a64(out), 8, &out);
  return out;
}

absl::StatusOr<RankingJoin> RankingJoin::Parse(absl::string_view bytes) {
  const auto bad = [](const auto&... what) {
    return absl::DataLossError(absl::StrCat("ranking join: ", what...));
  };
  if (bytes.size() < sizeof(kJoinMagic) + 8 ||
      std::memcmp(bytes.data(), kJoinMagic, sizeof(kJoinMagic)) != 0) {
    return bad("not a ranking join (", bytes.size(), " bytes)");
  }
  const std::size_t body = bytes.size() - 8;
  if (Fnv1a64(bytes.substr(0, body)) != GetLittleEndian(bytes.data() + body, 8)) {
    return bad("checksum mismatch");
  }
  Reader in(bytes.substr(sizeof(kJoinMagic), body - sizeof(kJoinMagic)));
  uint64_t version = 0;
  RankingJoin join;
  if (!in.Int(4, &version) || version != kVersion) return bad("unsupported version ", version);
  if (!in.Text(&join.model_id) || !in.Int(8, &join.ordinal) || !in.Text(&join.label) ||
      !ReadNeighbors(&in, &join.graph.list) || !ReadNeighbors(&in, &join.graph.entered)) {
    return bad("cut short");
  }
  if (in.left() != 0) return bad(in.left(), " bytes after the end");
  return join;
}

std::string RankingState::Serialize() const {
  std::string out(kMagic, sizeof(kMagic));
  PutLittleEndian(kVersion, 4, &out);
  PutLittleEndian(scales.size(), 4, &out);
  for (double s : scales) {
    uint64_t bits;
    std::memcpy(&bits, &s, sizeof(bits));
    PutLittleEndian(bits, 8, &out);
  }
  PutLittleEndian(model_ids.size(), 8, &out);
  for (std::size_t i = 0; i < model_ids.size(); ++i) {
    PutText(model_ids[i], &out);
    PutLittleEndian(ordinals[i], 8, &out);
    PutText(labels[i], &out);
  }
  out.push_back(graph.has_value() ? 1 : 0);
  if (graph.has_value()) {
    const std::string bytes = graph->Serialize();
    PutLittleEndian(bytes.size(), 8, &out);
    out.append(bytes);
  }
  PutLittleEndian(Fnv1a64(out), 8, &out);
  return out;
}

absl::StatusOr<RankingState> RankingState::Parse(absl::string_view bytes) {
  const auto bad = [](const auto&... what) {
    return absl::DataLossError(absl::StrCat("ranking state: ", what...));
  };
  if (bytes.size() < sizeof(kMagic) + 8 || std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0) {
    return bad("not a ranking state (", bytes.size(), " bytes)");
  }
  const std::size_t body = bytes.size() - 8;
  if (Fnv1a64(bytes.substr(0, body)) != GetLittleEndian(bytes.data() + body, 8)) {
    return bad("checksum mismatch");
  }
  Reader in(bytes.substr(sizeof(kMagic), body - sizeof(kMagic)));
  uint64_t version = 0, methods = 0, n = 0, has_graph = 0;
  if (!in.Int(4, &version) || version != kVersion) return bad("unsupported version ", version);
  if (!in.Int(4, &methods) || methods == 0 || methods > 64 || !in.Has(methods * 8)) {
    return bad("bad method count ", methods);
  }
  RankingState state;
  state.scales.resize(methods);
  for (double& s : state.scales) {
    if (!in.Double(&s) || !std::isfinite(s) || !(s > 0)) return bad("bad scale");
  }
  // Each model takes at least 16 bytes: bound n before allocating.
  if (!in.Int(8, &n) || n > in.left() / 16) return bad("bad model count ", n);
  state.model_ids.resize(n);
  state.ordinals.resize(n);
  state.labels.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (!in.Text(&state.model_ids[i]) || !in.Int(8, &state.ordinals[i]) ||
        !in.Text(&state.labels[i])) {
      return bad("model ", i, " of ", n, " is cut short");
    }
  }
  if (!in.Int(1, &has_graph) || has_graph > 1) return bad("bad graph flag");
  if (has_graph == 1) {
    uint64_t size = 0;
    absl::string_view graph_bytes;
    if (!in.Int(8, &size) || !in.Bytes(size, &graph_bytes)) return bad("graph cut short");
    MESHSEEK_ASSIGN_OR_RETURN(NeighborGraph graph, NeighborGraph::Parse(graph_bytes));
    if (graph.size() != n) return bad("a graph of ", graph.size(), " nodes for ", n, " models");
    state.graph = std::move(graph);
  }
  if (in.left() != 0) return bad(in.left(), " bytes after the end");
  return state;
}

absl::StatusOr<Ranking> Ranking::Make(std::string build,
                                      RankingState state,
                                      const CollectionOptions& options) {
  if (state.scales.size() != options.methods.size()) {
    return absl::DataLossError(absl::StrCat(
        "ranking state of ", state.scales.size(), " methods for ", options.MethodName()));
  }
  if (options.rerank.enabled() &&
      (!state.graph.has_value() ||
       static_cast<std::size_t>(state.graph->k()) <
           std::min<std::size_t>(options.rerank.graph_k(), state.model_ids.size()))) {
    return absl::DataLossError("ranking state without the neighbour graph re-ranking needs");
  }
  Ranking ranking;
  ranking.build = std::move(build);
  ranking.graph_k = options.rerank.enabled() ? options.rerank.graph_k() : 0;
  MESHSEEK_ASSIGN_OR_RETURN(ranking.factors, FusionFactors(options.weights, state.scales));
  for (uint32_t i = 0; i < state.model_ids.size(); ++i) ranking.node_of[state.model_ids[i]] = i;
  ranking.state = std::move(state);
  return ranking;
}

absl::StatusOr<std::vector<float>> Ranking::RankRow(
    const std::vector<absl::Span<const float>>& part_rows,
    std::optional<uint32_t> self,
    const CollectionOptions& options) const {
  const std::size_t n = state.model_ids.size();
  if (part_rows.size() != factors.size()) {
    return absl::InternalError(
        absl::StrCat(part_rows.size(), " rows for ", factors.size(), " methods"));
  }
  for (const absl::Span<const float>& row : part_rows) {
    if (row.size() != n) {
      return absl::FailedPreconditionError(absl::StrCat("a row of ",
                                                        row.size(),
                                                        " distances for the ",
                                                        n,
                                                        " models of build ",
                                                        build,
                                                        "; build again"));
    }
  }
  std::vector<float> fused(n);
  FuseRows(part_rows, factors, absl::MakeSpan(fused));
  if (!options.rerank.enabled()) return fused;
  return RerankRow(*state.graph, fused, self, options.rerank);
}

absl::StatusOr<RankingJoin> Ranking::PlanJoin(
    const std::string& model_id,
    uint64_t ordinal,
    const std::string& label,
    const std::vector<std::vector<IndexShards::Scored>>& part_distances) const {
  if (node_of.contains(model_id)) {
    return absl::AlreadyExistsError(absl::StrCat("model ", model_id, " is ranked already"));
  }
  if (part_distances.size() != factors.size()) {
    return absl::InternalError(
        absl::StrCat(part_distances.size(), " parts for ", factors.size(), " methods"));
  }
  RankingJoin join{model_id, ordinal, label, {}};
  if (!state.graph.has_value()) return join;
  const std::size_t n = state.model_ids.size();
  std::vector<uint8_t> answered;
  const std::vector<std::vector<float>> rows = NodeRows(node_of, n, part_distances, &answered);
  std::vector<absl::Span<const float>> spans(rows.begin(), rows.end());
  std::vector<float> fused(n);
  FuseRows(spans, factors, absl::MakeSpan(fused));
  join.graph = state.graph->PlanJoin(fused, graph_k);
  return join;
}

absl::Status Ranking::Apply(const RankingJoin& join) {
  if (node_of.contains(join.model_id)) {
    return absl::DataLossError(absl::StrCat("ranking join of ", join.model_id, ", ranked already"));
  }
  if (state.graph.has_value()) {
    if (absl::Status s = state.graph->ApplyJoin(join.graph); !s.ok()) {
      return absl::DataLossError(absl::StrCat("ranking join of ", join.model_id, ": ", s.message()));
    }
  } else if (!join.graph.list.empty() || !join.graph.entered.empty()) {
    return absl::DataLossError(
        absl::StrCat("ranking join of ", join.model_id, " changes a graph the state has not"));
  }
  node_of[join.model_id] = static_cast<uint32_t>(state.model_ids.size());
  state.model_ids.push_back(join.model_id);
  state.ordinals.push_back(join.ordinal);
  state.labels.push_back(join.label);
  return absl::OkStatus();
}

absl::StatusOr<std::vector<v1::ScoredModel>> Ranking::Query(
    const std::vector<std::vector<IndexShards::Scored>>& part_distances,
    const CollectionOptions& options,
    std::size_t top_k) const {
  const std::size_t n = state.model_ids.size();
  std::vector<uint8_t> answered;
  const std::vector<std::vector<float>> rows = NodeRows(node_of, n, part_distances, &answered);
  std::vector<absl::Span<const float>> spans(rows.begin(), rows.end());
  MESHSEEK_ASSIGN_OR_RETURN(const std::vector<float> ranked, RankRow(spans, std::nullopt, options));
  std::vector<uint32_t> nodes;
  for (uint32_t i = 0; i < n; ++i) {
    if (answered[i] == part_distances.size()) nodes.push_back(i);  // removed ones are not
  }
  const auto before = [&](uint32_t a, uint32_t b) {
    return std::make_tuple(ranked[a], state.ordinals[a], std::cref(state.model_ids[a])) <
           std::make_tuple(ranked[b], state.ordinals[b], std::cref(state.model_ids[b]));
  };
  const std::size_t k = std::min(top_k, nodes.size());
  std::partial_sort(nodes.begin(), nodes.begin() + k, nodes.end(), before);
  std::vector<v1::ScoredModel> results(k);
  for (std::size_t r = 0; r < k; ++r) {
    const uint32_t i = nodes[r];
    results[r].set_model_id(state.model_ids[i]);
    results[r].set_label(state.labels[i]);
    results[r].set_distance(ranked[i]);
    results[r].set_ordinal(state.ordinals[i]);
  }
  return results;
}

std::vector<IndexShards::Part> IndexParts(const CollectionPlan& plan) {
  std::vector<IndexShards::Part> parts;
  for (const CollectionInfo& part : plan.parts) {
    parts.push_back({part.name, part.options.kl.epsilon});
  }
  return parts;
}

namespace {

// Each part's distance scale over the sample rows (fusion.h): whole rows up
// to kScaleColumns models, in the order ScaleSampleRows lists them; above,
// their exact distances to the sampled columns, 32 rows a call.
absl::StatusOr<std::vector<double>> EstimateScales(IndexShards* index,
                                                   const std::vector<IndexShards::Part>& parts,
                                                   const IndexShards::PartModels& models) {
  const std::size_t n = models.size();
  std::vector<std::size_t> sample = ScaleSampleRows(n);
  std::vector<DistanceScale> scales(parts.size());
  if (n <= kScaleColumns) {
    std::size_t seen = 0;
    MESHSEEK_RETURN_IF_ERROR(index->ForEachDistanceRow(
        parts,
        [&](const IndexShards::Row& row) -> absl::Status {
          for (std::size_t p = 0; p < parts.size(); ++p) scales[p].AddRow(sample[seen], row.distances[p]);
          ++seen;
          return absl::OkStatus();
        },
        &sample));
  } else {
    const std::vector<std::size_t> columns = ScaleSampleColumns(n);
    std::vector<std::string> column_ids;
    absl::flat_hash_map<std::string, std::size_t> column_of;
    for (std::size_t c : columns) {
      column_of[models.models[0][c].model_id()] = column_ids.size();
      column_ids.push_back(models.models[0][c].model_id());
    }
    constexpr std::size_t kRowsPerCall = 32;
    for (std::size_t p = 0; p < parts.size(); ++p) {
      for (std::size_t begin = 0; begin < sample.size(); begin += kRowsPerCall) {
        const std::size_t end = std::min(sample.size(), begin + kRowsPerCall);
        std::vector<std::string> ids;
        for (std::size_t r = begin; r < end; ++r) ids.push_back(models.models[0][sample[r]].model_id());
        MESHSEEK_ASSIGN_OR_RETURN(
            const auto got,
            index->PairDistances(parts[p], ids,
                                 std::vector<std::vector<std::string>>(ids.size(), column_ids)));
        for (std::size_t r = begin; r < end; ++r) {
          // A model removed since the export is left out (+inf: skipped).
          std::vector<float> row(columns.size(), std::numeric_limits<float>::infinity());
          for (const IndexShards::Scored& s : got[r - begin]) row[column_of.at(s.model_id)] = s.distance;
          const auto self = std::lower_bound(columns.begin(), columns.end(), sample[r]);
          scales[p].AddRow(self != columns.end() && *self == sample[r] ? self - columns.begin()
                                                                       : columns.size(),
                           row);
        }
      }
    }
  }
  std::vector<double> out;
  for (const DistanceScale& s : scales) out.push_back(s.Scale());
  return out;
}

}  // namespace

absl::StatusOr<RankingState> ComputeRankingState(IndexShards* index,
                                                 const CollectionPlan& plan,
                                                 const RankingGraphOptions& graph_options) {
  const std::vector<IndexShards::Part> parts = IndexParts(plan);
  const CollectionOptions& options = plan.options;
  RankingState state;
  // Pass 1: the models (ids only), and each method's scale.
  MESHSEEK_ASSIGN_OR_RETURN(const IndexShards::PartModels models,
                            index->ExportParts(parts, /*signatures=*/false));
  const std::size_t n = models.size();
  MESHSEEK_ASSIGN_OR_RETURN(state.scales, EstimateScales(index, parts, models));
  MESHSEEK_ASSIGN_OR_RETURN(const std::vector<double> factors,
                            FusionFactors(options.weights, state.scales));
  for (const v1::IndexedModel& m : models.models[0]) {
    state.model_ids.push_back(m.model_id());
    state.ordinals.push_back(m.ordinal());
    state.labels.push_back(m.label());
  }
  if (!options.rerank.enabled()) return state;
  // Pass 2: the graph of the fused rows, from candidates above the exact
  // graph's size (fused_candidates.h).
  if (n > graph_options.exact_graph_models) {
    MESHSEEK_ASSIGN_OR_RETURN(state.graph,
                              ApproximateNeighborGraph(index, plan, models, factors,
                                                       options.rerank.graph_k(), graph_options));
    return state;
  }
  MESHSEEK_ASSIGN_OR_RETURN(state.graph, NeighborGraph::Create(n, options.rerank.graph_k()));
  std::vector<float> fused(n);
  std::size_t i = 0;
  MESHSEEK_RETURN_IF_ERROR(
      index->ForEachDistanceRow(parts, [&](const IndexShards::Row& row) -> absl::Status {
        if (row.distances.front().size() != n || i >= n ||
            row.model->model_id() != state.model_ids[i]) {
          return absl::AbortedError("the collection changed during its build; build again");
        }
        FuseRows(row.distances, factors, absl::MakeSpan(fused));
        state.graph->SetRow(static_cast<uint32_t>(i++), fused);
        return absl::OkStatus();
      }));
  if (i != n) {
    return absl::AbortedError("the collection changed during its build; build again");
  }
  return state;
}

}  // namespace meshseek
