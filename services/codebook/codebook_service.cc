#include "services/codebook/codebook_service.h"

#include <filesystem>

#include "absl/strings/str_cat.h"
#include "common/base/parallel.h"
#include "common/base/status_macros.h"
#include "common/features/sift_descriptor.h"
#include "common/wire/convert.h"

namespace meshseek {

absl::Status CodebookServiceOptions::Validate() const {
  if (data_dir.empty()) return absl::InvalidArgumentError("codebook: --data_dir is required");
  return absl::OkStatus();
}

absl::StatusOr<std::unique_ptr<CodebookService>> CodebookService::Create(
    const CodebookServiceOptions& options) {
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  std::error_code error;
  std::filesystem::create_directories(options.data_dir, error);
  MESHSEEK_ASSIGN_OR_RETURN(std::unique_ptr<Database> db,
                            Database::Open(options.data_dir + "/codebook.db"));
  MESHSEEK_RETURN_IF_ERROR(
      db->Execute("CREATE TABLE IF NOT EXISTS codebooks (id TEXT PRIMARY KEY, "
                  "training_descriptors INTEGER NOT NULL, data BLOB NOT NULL)"));
  return std::unique_ptr<CodebookService>(new CodebookService(options, std::move(db)));
}

v1::CodebookInfo CodebookService::Describe(const std::string& id, const Entry& entry) {
  v1::CodebookInfo info;
  info.set_codebook_id(id);
  info.set_size(static_cast<uint32_t>(entry.codebook->size()));
  info.set_dimension(static_cast<uint32_t>(entry.codebook->dim()));
  info.set_training_descriptors(entry.training_descriptors);
  return info;
}

absl::StatusOr<CodebookService::Entry> CodebookService::Find(const std::string& id) {
  absl::MutexLock lock(&mutex_);
  if (auto it = cache_.find(id); it != cache_.end()) return it->second;
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement select,
      db_->Prepare("SELECT training_descriptors, data FROM codebooks WHERE id = ?"));
  select.Bind(1, id);
  MESHSEEK_ASSIGN_OR_RETURN(const bool found, select.Step());
  if (!found) return absl::NotFoundError(absl::StrCat("no codebook '", id, "'"));
  MESHSEEK_ASSIGN_OR_RETURN(Codebook codebook, Codebook::Deserialize(select.ColumnBlob(1)));
  Entry entry{std::make_shared<const Codebook>(std::move(codebook)),
              static_cast<uint64_t>(select.ColumnInt(0))};
  cache_[id] = entry;
  return entry;
}

absl::StatusOr<v1::CodebookInfo> CodebookService::Train(
    rpc::Reader<v1::TrainCodebookRequest> read, const rpc::CallContext& call) {
  v1::TrainCodebookRequest first;
  if (!read(&first)) return absl::InvalidArgumentError("train: empty request stream");
  const std::string id = first.codebook_id();
  if (id.empty()) return absl::InvalidArgumentError("train: codebook_id is empty");
  // Every later error names the codebook.
  const std::string where = absl::StrCat("train ", id, ": ");
  auto fail = [&where](const absl::Status& status) { return Prefixed(status, where); };
  absl::MutexLock training(&train_mutex_);
  if (absl::StatusOr<Entry> existing = Find(id); existing.ok()) {
    v1::TrainCodebookRequest rest;
    while (read(&rest)) {
    }
    return Describe(id, *existing);
  }
  const std::size_t dim = first.dimension();
  if (dim == 0 || dim > kMaxDescriptorDimension) {
    return fail(absl::InvalidArgumentError(absl::StrCat(
        "descriptor dimension ", dim, ", expected 1 to ", kMaxDescriptorDimension)));
  }
  std::string descriptors = first.descriptors();
  v1::TrainCodebookRequest chunk;
  for (int index = 1; read(&chunk); ++index) {
    if (chunk.dimension() != 0 && chunk.dimension() != dim) {
      return fail(absl::InvalidArgumentError(absl::StrCat(
          "chunk ", index, " has dimension ", chunk.dimension(), ", the first had ", dim)));
    }
    descriptors += chunk.descriptors();
  }
  // A stream also ends when its client dies (a coordinator killed mid-build):
  // that is a cut-off sample, and a codebook trained on it and stored under
  // the build's id would be what the resumed build finds and uses.
  if (call.cancelled()) {
    return fail(absl::CancelledError("the stream was cut off; nothing trained"));
  }
  if (descriptors.size() % dim != 0) {
    return fail(absl::InvalidArgumentError(absl::StrCat(
        descriptors.size(), " descriptor bytes are not a multiple of ", dim)));
  }
  // The same k-means options as the in-process pipeline's
  // TrainCollectionCodebook: the collection's.
  absl::StatusOr<RetrievalPipelineOptions> params = wire::PipelineOptionsFromParams(first.params());
  if (!params.ok()) return fail(absl::InvalidArgumentError(params.status().message()));
  KMeansOptions kmeans = params->kmeans;
  kmeans.num_threads = options_.num_threads;
  kmeans.sampled_from = first.sampled_from();
  const std::size_t count = descriptors.size() / dim;
  absl::StatusOr<Codebook> codebook = Codebook::Train(
      reinterpret_cast<const uint8_t*>(descriptors.data()), count, dim, kmeans);
  if (!codebook.ok()) return fail(codebook.status());
  // What the codebook was trained from: the whole set when a sample was sent.
  Entry entry{std::make_shared<const Codebook>(*std::move(codebook)),
              first.sampled_from() > 0 ? first.sampled_from() : count};
  {
    absl::MutexLock lock(&mutex_);
    MESHSEEK_ASSIGN_OR_RETURN(
        Statement insert,
        db_->Prepare("INSERT OR REPLACE INTO codebooks (id, training_descriptors, data) "
                     "VALUES (?, ?, ?)"));
    MESHSEEK_RETURN_IF_ERROR(insert.Bind(1, id)
                                 .Bind(2, static_cast<int64_t>(count))
                                 .BindBlob(3, entry.codebook->Serialize())
                                 .Run());
    cache_[id] = entry;
  }
  return Describe(id, entry);
}

absl::StatusOr<v1::EncodeResponse> CodebookService::Encode(const v1::EncodeRequest& request,
                                                           const rpc::CallContext&) {
  MESHSEEK_ASSIGN_OR_RETURN(const Entry entry, Find(request.codebook_id()));
  MESHSEEK_ASSIGN_OR_RETURN(const LocalFeatures features, wire::FeaturesFromProto(request.features()));
  std::vector<float> histogram;  // empty: a model without features
  if (features.size() > 0) {
    MESHSEEK_ASSIGN_OR_RETURN(
        histogram,
        entry.codebook->Encode(features.descriptors.data(), features.size(), features.dimension,
                               CappedThreads(request.threads(), options_.num_threads)));
  }
  v1::EncodeResponse response;
  wire::HistogramToProto(histogram, entry.codebook->size(), response.mutable_histogram());
  return response;
}

absl::StatusOr<v1::CodebookInfo> CodebookService::GetCodebook(
    const v1::GetCodebookRequest& request, const rpc::CallContext&) {
  MESHSEEK_ASSIGN_OR_RETURN(const Entry entry, Find(request.codebook_id()));
  return Describe(request.codebook_id(), entry);
}

}  // namespace meshseek
