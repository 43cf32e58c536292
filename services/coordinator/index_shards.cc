#include "services/coordinator/index_shards.h"

#include <algorithm>
#include <tuple>

#include "absl/container/flat_hash_map.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "common/base/hash.h"
#include "common/base/parallel.h"
#include "common/base/status_macros.h"

namespace meshseek {
namespace {

bool Before(const v1::IndexedModel& a, const v1::IndexedModel& b) {
  return std::make_tuple(a.ordinal(), std::cref(a.model_id())) <
         std::make_tuple(b.ordinal(), std::cref(b.model_id()));
}

}  // namespace

absl::StatusOr<std::vector<std::string>> IndexShards::ParseTargets(const std::string& targets) {
  std::vector<std::string> out = absl::StrSplit(targets, ',');
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (out[i].empty()) {
      return absl::InvalidArgumentError(
          absl::StrCat("index shard ", i, " of '", targets, "' has an empty target"));
    }
  }
  return out;
}

IndexShards::IndexShards(const std::vector<std::string>& targets,
                         const rpc::ChannelOptions& channel,
                         absl::Duration call_deadline,
                         const rpc::RetryOptions& retry,
                         const std::atomic<bool>* stop)
    : call_deadline_(call_deadline), retry_(retry), stop_(stop) {
  rpc::ChannelOptions options = channel;
  options.retry_service = "meshseek.v1.Index";
  for (const std::string& target : targets) {
    shards_.push_back(v1::Index::NewStub(rpc::MakeChannel(target, options)));
  }
}

std::size_t IndexShards::ShardOf(const std::string& model_id) const {
  return Fnv1a64(model_id) % shards_.size();
}

absl::Status IndexShards::Add(const v1::AddModelRequest& request) {
  v1::AddModelResponse response;
  return rpc::CallWithRetry(shards_[ShardOf(request.model_id())].get(),
                            &v1::Index::Stub::AddModel, request, &response, call_deadline_,
                            retry_, stop_);
}

absl::StatusOr<bool> IndexShards::Remove(const std::string& collection,
                                         const std::string& model_id) {
  v1::RemoveModelRequest request;
  request.set_collection(collection);
  request.set_model_id(model_id);
  v1::RemoveModelResponse response;
  MESHSEEK_RETURN_IF_ERROR(rpc::CallWithRetry(shards_[ShardOf(model_id)].get(),
                                              &v1::Index::Stub::RemoveModel, request, &response,
                                              call_deadline_, retry_, stop_));
  return response.removed();
}

template <typename Response, typename Request, typename Method>
absl::StatusOr<std::vector<std::optional<Response>>> IndexShards::AskEveryShard(
    Method method, const Request& request) {
  std::vector<Response> answers(shards_.size());
  std::vector<absl::Status> errors(shards_.size());
  ParallelFor(shards_.size(), static_cast<int>(shards_.size()), [&](std::size_t s) {
    errors[s] = rpc::CallWithRetry(
        shards_[s].get(), method, request, &answers[s], call_deadline_, retry_, stop_);
  });
  std::vector<std::optional<Response>> found(shards_.size());
  std::size_t not_found = 0;
  for (std::size_t s = 0; s < shards_.size(); ++s) {
    if (errors[s].code() == absl::StatusCode::kNotFound) {
      ++not_found;
    } else if (!errors[s].ok()) {
      return absl::Status(errors[s].code(),
                          absl::StrCat("index shard ", s, ": ", errors[s].message()));
    } else {
      found[s] = std::move(answers[s]);
    }
  }
  if (not_found == shards_.size()) return errors[0];
  return found;
}

absl::StatusOr<std::vector<v1::ScoredModel>> IndexShards::Search(const v1::SearchRequest& request) {
  MESHSEEK_ASSIGN_OR_RETURN(std::vector<std::optional<v1::SearchResponse>> answers,
                            AskEveryShard<v1::SearchResponse>(&v1::Index::Stub::Search, request));
  std::vector<v1::ScoredModel> merged;
  for (std::optional<v1::SearchResponse>& answer : answers) {
    if (!answer.has_value()) continue;
    for (v1::ScoredModel& m : *answer->mutable_results()) merged.push_back(std::move(m));
  }
  std::sort(merged.begin(), merged.end(), [](const v1::ScoredModel& a, const v1::ScoredModel& b) {
    return std::make_tuple(a.distance(), a.ordinal(), std::cref(a.model_id())) <
           std::make_tuple(b.distance(), b.ordinal(), std::cref(b.model_id()));
  });
  if (merged.size() > request.top_k()) merged.resize(request.top_k());
  return merged;
}

template <typename Message, typename Method, typename Request, typename Restart, typename Take>
absl::Status IndexShards::ReadStream(std::size_t s,
                                     Method method,
                                     const Request& request,
                                     Restart&& restart,
                                     Take&& take) {
  return rpc::RetryTransient(
      [&]() -> absl::Status {
        restart();
        grpc::ClientContext context;
        rpc::SetDeadline(&context, call_deadline_);
        auto reader = (shards_[s].get()->*method)(&context, request);
        Message message;
        while (reader->Read(&message)) take(message);
        const grpc::Status done = reader->Finish();
        return absl::Status(static_cast<absl::StatusCode>(done.error_code()),
                            done.error_message());
      },
      retry_, stop_);
}

absl::StatusOr<std::vector<v1::IndexedModel>> IndexShards::Export(
    std::size_t s, const v1::ExportModelsRequest& request) {
  std::vector<v1::IndexedModel> models;
  const absl::Status status = ReadStream<v1::IndexedModel>(
      s, &v1::Index::Stub::ExportModels, request, [&] { models.clear(); },
      [&](v1::IndexedModel& model) { models.push_back(std::move(model)); });
  if (status.code() == absl::StatusCode::kNotFound) return std::vector<v1::IndexedModel>();
  if (!status.ok()) {
    return absl::Status(status.code(), absl::StrCat("index shard ", s, ": ", status.message()));
  }
  return models;
}

absl::StatusOr<std::vector<IndexShards::Scored>> IndexShards::QueryDistances(
    const v1::DistancesRequest& request) {
  MESHSEEK_ASSIGN_OR_RETURN(
      const std::vector<std::optional<v1::DistancesResponse>> answers,
      AskEveryShard<v1::DistancesResponse>(&v1::Index::Stub::Distances, request));
  std::vector<Scored> all;
  for (std::size_t s = 0; s < answers.size(); ++s) {
    if (!answers[s].has_value()) continue;
    const v1::DistancesResponse& a = *answers[s];
    if (a.distances_size() != a.model_ids_size()) {
      return absl::InternalError(absl::StrCat("index shard ",
                                              s,
                                              " answered ",
                                              a.distances_size(),
                                              " distances for ",
                                              a.model_ids_size(),
                                              " models"));
    }
    for (int j = 0; j < a.model_ids_size(); ++j) all.push_back({a.model_ids(j), a.distances(j)});
  }
  return all;
}

absl::StatusOr<IndexShards::PartModels> IndexShards::ExportParts(const std::vector<Part>& parts,
                                                                 bool signatures) {
  // Every model of every part, from every shard; the first part's in
  // (ordinal, id) order gives the rows, the others must hold the same models.
  const std::size_t p_count = parts.size();
  PartModels out;
  out.models.resize(p_count);
  for (std::size_t p = 0; p < p_count; ++p) {
    v1::ExportModelsRequest request;
    request.set_collection(parts[p].collection);
    request.set_without_signatures(!signatures);
    for (std::size_t s = 0; s < shards_.size(); ++s) {
      MESHSEEK_ASSIGN_OR_RETURN(std::vector<v1::IndexedModel> part, Export(s, request));
      for (v1::IndexedModel& m : part) out.models[p].push_back(std::move(m));
    }
    if (out.models[p].empty()) {
      return absl::NotFoundError(
          absl::StrCat("index has no models in collection '", parts[p].collection, "'"));
    }
  }
  std::sort(out.models[0].begin(), out.models[0].end(), Before);
  const std::size_t n = out.models[0].size();
  for (std::size_t i = 0; i < n; ++i) out.row_of[out.models[0][i].model_id()] = i;
  out.entry.assign(p_count, std::vector<const v1::IndexedModel*>(n));
  for (std::size_t p = 0; p < p_count; ++p) {
    std::size_t found = 0;
    for (const v1::IndexedModel& m : out.models[p]) {
      auto it = out.row_of.find(m.model_id());
      if (it == out.row_of.end()) continue;
      out.entry[p][it->second] = &m;
      ++found;
    }
    if (found != n || out.models[p].size() != n) {
      return absl::FailedPreconditionError(absl::StrCat("collections '",
                                                        parts[0].collection,
                                                        "' and '",
                                                        parts[p].collection,
                                                        "' hold ",
                                                        n,
                                                        " and ",
                                                        out.models[p].size(),
                                                        " models, ",
                                                        found,
                                                        " in common; build again"));
    }
  }
  return out;
}

absl::Status IndexShards::DistanceBlock(const Part& part,
                                        const std::vector<std::string>& ids,
                                        const absl::flat_hash_map<std::string, std::size_t>& column,
                                        std::vector<float>* block) {
  v1::DistancesRequest request;
  request.set_collection(part.collection);
  request.set_kl_epsilon(part.kl_epsilon);
  // The block's signatures, a block at a time: a large collection's
  // histograms never sit in the coordinator's memory at once.
  MESHSEEK_ASSIGN_OR_RETURN(const std::vector<v1::IndexedModel> block_models,
                            Fetch(part, ids));
  for (const v1::IndexedModel& m : block_models) {
    if (m.has_global_descriptor()) {
      *request.add_global_queries() = m.global_descriptor();
    } else {
      *request.add_queries() = m.histogram();
    }
  }
  const std::size_t n = column.size();
  const std::size_t queries = ids.size();
  block->assign(queries * n, -1.0f);
  std::size_t covered = 0;
  for (std::size_t s = 0; s < shards_.size(); ++s) {
    v1::DistancesResponse response;
    const absl::Status status = rpc::CallWithRetry(shards_[s].get(),
                                                   &v1::Index::Stub::Distances,
                                                   request,
                                                   &response,
                                                   call_deadline_,
                                                   retry_,
                                                   stop_);
    if (status.code() == absl::StatusCode::kNotFound) continue;
    if (!status.ok()) {
      return absl::Status(status.code(),
                          absl::StrCat("index shard ", s, ": ", status.message()));
    }
    const std::size_t m = static_cast<std::size_t>(response.model_ids_size());
    if (static_cast<std::size_t>(response.distances_size()) != queries * m) {
      return absl::InternalError(absl::StrCat("index shard ",
                                              s,
                                              " answered ",
                                              response.distances_size(),
                                              " distances for ",
                                              queries,
                                              " queries and ",
                                              m,
                                              " models"));
    }
    for (std::size_t j = 0; j < m; ++j) {
      auto it = column.find(response.model_ids(static_cast<int>(j)));
      // A model added after the export has no row: it waits for the
      // next evaluation.
      if (it == column.end()) continue;
      ++covered;
      for (std::size_t q = 0; q < queries; ++q) {
        (*block)[q * n + it->second] = response.distances(static_cast<int>(q * m + j));
      }
    }
  }
  if (covered != n) {
    // A model removed (or a shard emptied) between the export and now.
    return absl::AbortedError(absl::StrCat("collection '",
                                           part.collection,
                                           "' changed while its distance matrix was ",
                                           "assembled (",
                                           covered,
                                           " of ",
                                           n,
                                           " models answered); try again"));
  }
  return absl::OkStatus();
}

absl::Status IndexShards::ForEachDistanceRow(const std::vector<Part>& parts,
                                             const std::function<absl::Status(const Row&)>& fn,
                                             const std::vector<std::size_t>* only_rows) {
  // 1. Every model of every part, in row order.
  const std::size_t p_count = parts.size();
  MESHSEEK_ASSIGN_OR_RETURN(const PartModels exported, ExportParts(parts, /*signatures=*/false));
  const std::vector<std::vector<v1::IndexedModel>>& models = exported.models;
  const absl::flat_hash_map<std::string, std::size_t>& column = exported.row_of;
  const std::size_t n = exported.size();

  // 2. Blocks of rows: each shard gives the distances from the block's
  //    signatures to its own models, placed into their columns.
  std::vector<std::size_t> rows;
  if (only_rows != nullptr) {
    for (std::size_t i : *only_rows) {
      if (i >= n) {
        return absl::InvalidArgumentError(absl::StrCat("row ", i, " of ", n, " models"));
      }
    }
    rows = *only_rows;
  } else {
    rows.resize(n);
    for (std::size_t i = 0; i < n; ++i) rows[i] = i;
  }
  std::vector<std::vector<float>> blocks(p_count);
  for (std::size_t begin = 0; begin < rows.size(); begin += kMatrixBatch) {
    const std::size_t end = std::min(rows.size(), begin + kMatrixBatch);
    std::vector<std::string> ids;
    for (std::size_t r = begin; r < end; ++r) ids.push_back(models[0][rows[r]].model_id());
    for (std::size_t p = 0; p < p_count; ++p) {
      MESHSEEK_RETURN_IF_ERROR(DistanceBlock(parts[p], ids, column, &blocks[p]));
    }
    for (std::size_t r = begin; r < end; ++r) {
      const std::size_t i = rows[r];
      Row row{&models[0][i], {}};
      for (std::size_t p = 0; p < p_count; ++p) {
        float* distances = &blocks[p][(r - begin) * n];
        distances[i] = 0.0f;
        row.distances.push_back(absl::MakeConstSpan(distances, n));
      }
      MESHSEEK_RETURN_IF_ERROR(fn(row));
    }
  }
  return absl::OkStatus();
}

absl::StatusOr<std::vector<std::vector<v1::QueryModel>>> IndexShards::QueriesPerShard(
    const Part& part, const std::vector<std::string>& model_ids) {
  std::vector<std::vector<v1::QueryModel>> queries(shards_.size(),
                                                   std::vector<v1::QueryModel>(model_ids.size()));
  for (std::vector<v1::QueryModel>& shard : queries) {
    for (std::size_t i = 0; i < model_ids.size(); ++i) shard[i].set_model_id(model_ids[i]);
  }
  if (shards_.size() == 1) return queries;  // every model is held where it is asked
  // Each model whole from its own shard, for the others.
  MESHSEEK_ASSIGN_OR_RETURN(std::vector<v1::IndexedModel> whole, Fetch(part, model_ids));
  for (std::size_t i = 0; i < model_ids.size(); ++i) {
    for (std::size_t s = 0; s < shards_.size(); ++s) {
      if (s != ShardOf(model_ids[i])) *queries[s][i].mutable_model() = whole[i];
    }
  }
  return queries;
}

absl::StatusOr<std::vector<v1::IndexedModel>> IndexShards::Fetch(
    const Part& part, const std::vector<std::string>& model_ids) {
  std::vector<v1::ExportModelsRequest> requests(shards_.size());
  for (v1::ExportModelsRequest& request : requests) request.set_collection(part.collection);
  for (const std::string& id : model_ids) requests[ShardOf(id)].add_model_ids(id);
  absl::flat_hash_map<std::string, v1::IndexedModel> found;
  for (std::size_t s = 0; s < shards_.size(); ++s) {
    if (requests[s].model_ids().empty()) continue;
    MESHSEEK_ASSIGN_OR_RETURN(std::vector<v1::IndexedModel> got, Export(s, requests[s]));
    for (v1::IndexedModel& m : got) found[m.model_id()] = std::move(m);
  }
  if (found.empty() && !model_ids.empty()) {
    return absl::NotFoundError(
        absl::StrCat("index has no models in collection '", part.collection, "'"));
  }
  std::vector<v1::IndexedModel> models(model_ids.size());
  for (std::size_t i = 0; i < model_ids.size(); ++i) {
    const auto it = found.find(model_ids[i]);
    if (it == found.end()) {
      return absl::AbortedError(absl::StrCat("model '", model_ids[i], "' of collection '",
                                             part.collection,
                                             "' was removed while its build ran; build again"));
    }
    models[i] = it->second;
  }
  return models;
}

namespace {

// A shard's list as Scored, appended to `out`.
void AppendScored(const v1::NeighborList& list, std::vector<IndexShards::Scored>* out) {
  for (int j = 0; j < list.neighbor_ids_size() && j < list.distances_size(); ++j) {
    out->push_back({list.neighbor_ids(j), list.distances(j)});
  }
}

}  // namespace

absl::StatusOr<std::vector<std::vector<IndexShards::Scored>>> IndexShards::Neighbors(
    const Part& part, const std::vector<std::string>& model_ids, uint32_t count,
    uint32_t candidates) {
  if (model_ids.size() > kMaxGraphBatch) {
    return absl::InternalError(absl::StrCat(model_ids.size(), " neighbour queries in one call"));
  }
  MESHSEEK_ASSIGN_OR_RETURN(std::vector<std::vector<v1::QueryModel>> queries,
                            QueriesPerShard(part, model_ids));
  std::vector<std::vector<Scored>> merged(model_ids.size());
  std::size_t answered = 0;
  for (std::size_t s = 0; s < shards_.size(); ++s) {
    v1::NeighborsRequest request;
    request.set_collection(part.collection);
    request.set_kl_epsilon(part.kl_epsilon);
    request.set_count(count);
    request.set_candidates(candidates);
    for (v1::QueryModel& q : queries[s]) *request.add_queries() = std::move(q);
    std::vector<std::vector<Scored>> lists;
    const absl::Status status = ReadStream<v1::NeighborLists>(
        s, &v1::Index::Stub::Neighbors, request, [&] { lists.clear(); },
        [&](v1::NeighborLists& batch) {
          for (const v1::NeighborList& list : batch.lists()) AppendScored(list, &lists.emplace_back());
        });
    if (status.code() == absl::StatusCode::kNotFound && shards_.size() > 1) continue;
    if (!status.ok()) {
      return absl::Status(status.code(), absl::StrCat("index shard ", s, ": ", status.message()));
    }
    if (lists.size() != model_ids.size()) {
      return absl::InternalError(absl::StrCat("index shard ", s, " answered ", lists.size(),
                                              " neighbour lists for ", model_ids.size(),
                                              " queries"));
    }
    ++answered;
    for (std::size_t i = 0; i < lists.size(); ++i) {
      merged[i].insert(merged[i].end(), lists[i].begin(), lists[i].end());
    }
  }
  if (answered == 0) {
    return absl::NotFoundError(
        absl::StrCat("index has no models in collection '", part.collection, "'"));
  }
  if (answered > 1) {  // each shard's list is in order: merge them, the first shard's first on ties
    for (std::vector<Scored>& list : merged) {
      std::stable_sort(list.begin(), list.end(),
                       [](const Scored& a, const Scored& b) { return a.distance < b.distance; });
      if (list.size() > count) list.resize(count);
    }
  }
  return merged;
}

absl::StatusOr<std::vector<std::vector<IndexShards::Scored>>> IndexShards::PairDistances(
    const Part& part,
    const std::vector<std::string>& model_ids,
    const std::vector<std::vector<std::string>>& targets) {
  if (model_ids.size() > kMaxGraphBatch || targets.size() != model_ids.size()) {
    return absl::InternalError(absl::StrCat(model_ids.size(), " pair rows for ", targets.size(),
                                            " target lists"));
  }
  MESHSEEK_ASSIGN_OR_RETURN(std::vector<std::vector<v1::QueryModel>> queries,
                            QueriesPerShard(part, model_ids));
  std::vector<std::vector<Scored>> merged(model_ids.size());
  for (std::size_t s = 0; s < shards_.size(); ++s) {
    v1::PairDistancesRequest request;
    request.set_collection(part.collection);
    request.set_kl_epsilon(part.kl_epsilon);
    for (std::size_t i = 0; i < model_ids.size(); ++i) {
      v1::PairRow* row = request.add_rows();
      *row->mutable_query() = std::move(queries[s][i]);
      for (const std::string& id : targets[i]) {
        if (shards_.size() == 1 || ShardOf(id) == s) row->add_model_ids(id);
      }
    }
    v1::PairDistancesResponse response;
    const absl::Status status =
        rpc::CallWithRetry(shards_[s].get(), &v1::Index::Stub::PairDistances, request, &response,
                           call_deadline_, retry_, stop_);
    if (status.code() == absl::StatusCode::kNotFound && shards_.size() > 1) continue;
    if (!status.ok()) {
      return absl::Status(status.code(), absl::StrCat("index shard ", s, ": ", status.message()));
    }
    if (static_cast<std::size_t>(response.rows_size()) != model_ids.size()) {
      return absl::InternalError(absl::StrCat("index shard ", s, " answered ", response.rows_size(),
                                              " rows for ", model_ids.size()));
    }
    for (std::size_t i = 0; i < model_ids.size(); ++i) {
      AppendScored(response.rows(static_cast<int>(i)), &merged[i]);
    }
  }
  return merged;
}

}  // namespace meshseek
