#include "services/coordinator/coordinator_service.h"

#include <filesystem>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/time/clock.h"
#include "common/base/logging.h"
#include "common/base/parallel.h"
#include "common/base/status_macros.h"
#include "common/rpc/convert.h"
#include "common/rpc/status.h"

namespace meshseek {
namespace {

enum ModelState : int64_t { kPending = 0, kExtracted = 1, kFailed = 2 };

constexpr std::size_t kTrainChunkBytes = 4 << 20;

absl::Status CheckName(const std::string& what, const std::string& name, std::size_t max_size,
                       bool identifier_chars) {
  if (name.empty() || name.size() > max_size) {
    return absl::InvalidArgumentError(
        absl::StrCat(what, " must have 1 to ", max_size, " characters, got '", name, "'"));
  }
  for (char c : name) {
    const bool ok = identifier_chars ? (std::isalnum(static_cast<unsigned char>(c)) || c == '.' ||
                                        c == '_' || c == '-')
                                     : (static_cast<unsigned char>(c) >= 0x20 && c != 0x7f);
    if (!ok) {
      return absl::InvalidArgumentError(absl::StrCat(what, " '", name, "' has a character not in ",
                                                     identifier_chars ? "[A-Za-z0-9._-]" : "printable text"));
    }
  }
  return absl::OkStatus();
}

// FNV-1a 64 of the stored mesh: tells a retried ingest from a different model
// under the same id.
std::string Fingerprint(const std::string& bytes) {
  uint64_t h = 1469598103934665603ull;
  for (unsigned char c : bytes) h = (h ^ c) * 1099511628211ull;
  return absl::StrCat(absl::Hex(h, absl::kZeroPad16));
}

absl::Status Prefixed(const absl::Status& status, const std::string& prefix) {
  return absl::Status(status.code(), absl::StrCat(prefix, status.message()));
}

}  // namespace

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
  return absl::OkStatus();
}

CoordinatorService::CoordinatorService(const CoordinatorOptions& options) : options_(options) {
  retry_.attempts = options.call_attempts;
  rpc::ChannelOptions channel;
  channel.max_message_bytes = options.max_message_bytes;
  auto connect = [&](const std::string& target, const char* service) {
    channel.retry_service = service;
    return rpc::MakeChannel(target, channel);
  };
  resample_ = v1::Resample::NewStub(connect(options.resample_target, "meshseek.v1.Resample"));
  extract_ = v1::Extract::NewStub(connect(options.extract_target, "meshseek.v1.Extract"));
  codebook_ = v1::Codebook::NewStub(connect(options.codebook_target, "meshseek.v1.Codebook"));
  index_ = std::make_unique<IndexShards>(*IndexShards::ParseTargets(options.index_target), channel,
                                         options.call_deadline, retry_, &stop_);
}

absl::StatusOr<std::unique_ptr<CoordinatorService>> CoordinatorService::Create(
    const CoordinatorOptions& options) {
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  std::unique_ptr<CoordinatorService> service(new CoordinatorService(options));
  MESHSEEK_RETURN_IF_ERROR(service->Open());
  service->StartBackground();
  return service;
}

CoordinatorService::~CoordinatorService() { Stop(); }

absl::Status CoordinatorService::Open() {
  std::error_code error;
  std::filesystem::create_directories(options_.data_dir, error);
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(db_, Database::Open(options_.data_dir + "/coordinator.db"));
  MESHSEEK_RETURN_IF_ERROR(db_->Execute(R"sql(
    CREATE TABLE IF NOT EXISTS collections (
      name TEXT PRIMARY KEY, params BLOB NOT NULL, codebook_id TEXT NOT NULL DEFAULT '');
    CREATE TABLE IF NOT EXISTS models (
      collection TEXT NOT NULL, model_id TEXT NOT NULL, ordinal INTEGER NOT NULL,
      label TEXT NOT NULL, mesh BLOB NOT NULL, fingerprint TEXT NOT NULL,
      state INTEGER NOT NULL, error TEXT NOT NULL DEFAULT '', features BLOB,
      feature_count INTEGER NOT NULL DEFAULT 0, job_id TEXT NOT NULL,
      indexed_codebook TEXT NOT NULL DEFAULT '',
      PRIMARY KEY (collection, model_id));
    CREATE INDEX IF NOT EXISTS models_by_state ON models (state);
    CREATE TABLE IF NOT EXISTS jobs (
      seq INTEGER PRIMARY KEY AUTOINCREMENT, id TEXT UNIQUE, kind TEXT NOT NULL,
      collection TEXT NOT NULL, state INTEGER NOT NULL, message TEXT NOT NULL DEFAULT '',
      total INTEGER NOT NULL DEFAULT 0, stream_open INTEGER NOT NULL DEFAULT 0);
    CREATE TABLE IF NOT EXISTS settings (key TEXT PRIMARY KEY, value INTEGER NOT NULL);
    -- Streams do not survive a restart; their models do.
    UPDATE jobs SET stream_open = 0;
  )sql"));
  // Models are placed on index shards by hash modulo their number: another
  // number would look for every model on the wrong shard.
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement shards,
      db_->Prepare("INSERT INTO settings (key, value) VALUES ('index_shards', ?) "
                   "ON CONFLICT (key) DO UPDATE SET value = value RETURNING value"));
  shards.Bind(1, static_cast<int64_t>(index_->size()));
  MESHSEEK_ASSIGN_OR_RETURN(const bool stored, shards.Step());
  if (stored && shards.ColumnInt(0) != static_cast<int64_t>(index_->size())) {
    return absl::FailedPreconditionError(absl::StrCat(
        "coordinator: ", options_.data_dir, " was used with ", shards.ColumnInt(0),
        " index shards, --index lists ", index_->size(),
        "; models would be looked for on the wrong shards"));
  }
  MESHSEEK_ASSIGN_OR_RETURN(Statement count,
                            db_->Prepare("SELECT COUNT(*) FROM models WHERE state = 0"));
  MESHSEEK_ASSIGN_OR_RETURN(const bool row, count.Step());
  pending_ = row ? count.ColumnInt(0) : 0;
  if (pending_ > 0) MESHSEEK_LOG(INFO) << "coordinator: resuming " << pending_ << " pending models";
  return absl::OkStatus();
}

void CoordinatorService::StartBackground() {
  for (int i = 0; i < options_.max_in_flight; ++i) threads_.emplace_back([this] { DispatchLoop(); });
  // Resume builds that a restart interrupted.
  std::vector<std::pair<std::string, std::string>> builds;
  {
    absl::MutexLock lock(&mutex_);
    auto select = db_->Prepare("SELECT id, collection FROM jobs WHERE kind = 'build' AND state = 1");
    if (select.ok()) {
      while (select->Step().value_or(false)) {
        builds.emplace_back(select->ColumnText(0), select->ColumnText(1));
        building_.insert(select->ColumnText(1));
      }
    }
  }
  for (const auto& [job, collection] : builds) {
    MESHSEEK_LOG(INFO) << "coordinator: resuming " << job << " of collection " << collection;
    threads_.emplace_back([this, job = job, collection = collection] { RunBuild(job, collection); });
  }
}

void CoordinatorService::Stop() {
  if (stop_.exchange(true)) return;
  {
    absl::MutexLock lock(&mutex_);
    work_changed_.SignalAll();
  }
  for (std::thread& t : threads_) {
    if (t.joinable()) t.join();
  }
}

// ---------------------------------------------------------------- collections

absl::StatusOr<CoordinatorService::CollectionInfo> CoordinatorService::FindCollection(
    const std::string& name) {
  std::string params_bytes;
  CollectionInfo info;
  {
    absl::MutexLock lock(&mutex_);
    MESHSEEK_ASSIGN_OR_RETURN(
        Statement select, db_->Prepare("SELECT params, codebook_id FROM collections WHERE name = ?"));
    select.Bind(1, name);
    MESHSEEK_ASSIGN_OR_RETURN(const bool found, select.Step());
    if (!found) return absl::NotFoundError(absl::StrCat("no collection '", name, "'"));
    params_bytes = select.ColumnBlob(0);
    info.codebook_id = select.ColumnText(1);
  }
  if (!info.params.ParseFromString(params_bytes)) {
    return absl::DataLossError(absl::StrCat("collection '", name, "': stored parameters do not parse"));
  }
  MESHSEEK_ASSIGN_OR_RETURN(info.options, rpc::PipelineOptionsFromParams(info.params));
  return info;
}

grpc::Status CoordinatorService::CreateCollection(grpc::ServerContext*,
                                                  const v1::CreateCollectionRequest* request,
                                                  v1::Collection* response) {
  if (absl::Status name = CheckName("collection name", request->name(), 128, true); !name.ok()) {
    return rpc::ToGrpcStatus(name);
  }
  if (absl::StatusOr<RetrievalPipelineOptions> valid =
          rpc::PipelineOptionsFromParams(request->params());
      !valid.ok()) {
    return rpc::ToGrpcStatus(Prefixed(valid.status(), absl::StrCat("collection '", request->name(), "': ")));
  }
  {
    absl::MutexLock lock(&mutex_);
    absl::StatusOr<Statement> select = db_->Prepare("SELECT params FROM collections WHERE name = ?");
    if (!select.ok()) return rpc::ToGrpcStatus(select.status());
    select->Bind(1, request->name());
    absl::StatusOr<bool> found = select->Step();
    if (!found.ok()) return rpc::ToGrpcStatus(found.status());
    const std::string params = request->params().SerializeAsString();
    if (*found) {
      if (select->ColumnBlob(0) != params) {
        return grpc::Status(grpc::StatusCode::ALREADY_EXISTS,
                            absl::StrCat("collection '", request->name(),
                                         "' exists with other parameters"));
      }
    } else {
      absl::StatusOr<Statement> insert =
          db_->Prepare("INSERT INTO collections (name, params) VALUES (?, ?)");
      absl::Status done = insert.ok() ? insert->Bind(1, request->name()).BindBlob(2, params).Run()
                                      : insert.status();
      if (!done.ok()) return rpc::ToGrpcStatus(done);
    }
  }
  v1::GetCollectionRequest get;
  get.set_name(request->name());
  return GetCollection(nullptr, &get, response);
}

grpc::Status CoordinatorService::GetCollection(grpc::ServerContext*,
                                               const v1::GetCollectionRequest* request,
                                               v1::Collection* response) {
  absl::StatusOr<CollectionInfo> info = FindCollection(request->name());
  if (!info.ok()) return rpc::ToGrpcStatus(info.status());
  response->set_name(request->name());
  *response->mutable_params() = info->params;
  response->set_codebook_id(info->codebook_id);
  absl::MutexLock lock(&mutex_);
  absl::StatusOr<Statement> count = db_->Prepare(
      "SELECT COUNT(*), SUM(state = 1), SUM(state = 1 AND indexed_codebook = ?) "
      "FROM models WHERE collection = ?");
  if (!count.ok()) return rpc::ToGrpcStatus(count.status());
  count->Bind(1, info->codebook_id).Bind(2, request->name());
  if (absl::StatusOr<bool> row = count->Step(); !row.ok()) return rpc::ToGrpcStatus(row.status());
  response->set_models(count->ColumnInt(0));
  response->set_extracted(count->ColumnInt(1));
  response->set_indexed(info->codebook_id.empty() ? 0 : count->ColumnInt(2));
  return grpc::Status::OK;
}

// ----------------------------------------------------------------------- jobs

absl::StatusOr<std::string> CoordinatorService::NewJob(const std::string& kind,
                                                       const std::string& collection,
                                                       uint64_t total) {
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement insert,
      db_->Prepare("INSERT INTO jobs (kind, collection, state, total, stream_open) "
                   "VALUES (?, ?, 1, ?, ?)"));
  MESHSEEK_RETURN_IF_ERROR(insert.Bind(1, kind)
                               .Bind(2, collection)
                               .Bind(3, static_cast<int64_t>(total))
                               .Bind(4, int64_t{kind == "ingest"})
                               .Run());
  MESHSEEK_ASSIGN_OR_RETURN(Statement last, db_->Prepare("SELECT MAX(seq) FROM jobs"));
  MESHSEEK_RETURN_IF_ERROR(last.Run());
  const std::string id = absl::StrCat(kind, "-", last.ColumnInt(0));
  MESHSEEK_ASSIGN_OR_RETURN(Statement name, db_->Prepare("UPDATE jobs SET id = ? WHERE seq = ?"));
  MESHSEEK_RETURN_IF_ERROR(name.Bind(1, id).Bind(2, last.ColumnInt(0)).Run());
  return id;
}

absl::Status CoordinatorService::FinishJob(const std::string& job_id,
                                           v1::JobState state,
                                           const std::string& message) {
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement update, db_->Prepare("UPDATE jobs SET state = ?, message = ? WHERE id = ?"));
  return update.Bind(1, static_cast<int64_t>(state)).Bind(2, message).Bind(3, job_id).Run();
}

absl::StatusOr<v1::JobStatus> CoordinatorService::JobStatusOf(const std::string& job_id) {
  v1::JobStatus status;
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement job, db_->Prepare("SELECT kind, collection, state, message, total, stream_open "
                                  "FROM jobs WHERE id = ?"));
  job.Bind(1, job_id);
  MESHSEEK_ASSIGN_OR_RETURN(const bool found, job.Step());
  if (!found) return absl::NotFoundError(absl::StrCat("no job '", job_id, "'"));
  status.set_job_id(job_id);
  status.set_kind(job.ColumnText(0));
  status.set_collection(job.ColumnText(1));
  status.set_state(static_cast<v1::JobState>(job.ColumnInt(2)));
  status.set_message(job.ColumnText(3));
  const bool stream_open = job.ColumnInt(5) != 0;
  if (status.kind() == "ingest") {
    MESHSEEK_ASSIGN_OR_RETURN(
        Statement count, db_->Prepare("SELECT COUNT(*), SUM(state != 0), SUM(state = 2) "
                                      "FROM models WHERE job_id = ?"));
    count.Bind(1, job_id);
    MESHSEEK_RETURN_IF_ERROR(count.Run());
    status.set_total(count.ColumnInt(0));
    status.set_done(count.ColumnInt(1));
    status.set_failed(count.ColumnInt(2));
    if (status.state() == v1::JOB_STATE_RUNNING && !stream_open && status.done() == status.total()) {
      status.set_state(status.failed() > 0 ? v1::JOB_STATE_FAILED : v1::JOB_STATE_SUCCEEDED);
      status.set_message(status.failed() > 0
                             ? absl::StrCat(status.failed(), " of ", status.total(),
                                            " models failed")
                             : absl::StrCat(status.total(), " models extracted"));
      MESHSEEK_ASSIGN_OR_RETURN(
          Statement finish, db_->Prepare("UPDATE jobs SET state = ?, message = ? WHERE id = ?"));
      MESHSEEK_RETURN_IF_ERROR(finish.Bind(1, static_cast<int64_t>(status.state()))
                                   .Bind(2, status.message())
                                   .Bind(3, job_id)
                                   .Run());
    }
    if (status.failed() > 0) {
      MESHSEEK_ASSIGN_OR_RETURN(
          Statement errors, db_->Prepare("SELECT model_id, error FROM models WHERE job_id = ? "
                                         "AND state = 2 ORDER BY ordinal LIMIT 20"));
      errors.Bind(1, job_id);
      while (true) {
        MESHSEEK_ASSIGN_OR_RETURN(const bool row, errors.Step());
        if (!row) break;
        status.add_errors(absl::StrCat("model ", errors.ColumnText(0), ": ", errors.ColumnText(1)));
      }
    }
  } else {
    status.set_total(job.ColumnInt(4));
    MESHSEEK_ASSIGN_OR_RETURN(
        Statement count, db_->Prepare("SELECT COUNT(*) FROM models WHERE collection = ? "
                                      "AND indexed_codebook = ?"));
    count.Bind(1, status.collection()).Bind(2, absl::StrCat(status.collection(), "@", job_id));
    MESHSEEK_RETURN_IF_ERROR(count.Run());
    status.set_done(std::min<uint64_t>(count.ColumnInt(0), status.total()));
  }
  return status;
}

grpc::Status CoordinatorService::GetJob(grpc::ServerContext*,
                                        const v1::JobRequest* request,
                                        v1::JobStatus* response) {
  absl::StatusOr<v1::JobStatus> status = JobStatusOf(request->job_id());
  if (!status.ok()) return rpc::ToGrpcStatus(status.status());
  *response = *std::move(status);
  return grpc::Status::OK;
}

grpc::Status CoordinatorService::WatchJob(grpc::ServerContext* context,
                                          const v1::JobRequest* request,
                                          grpc::ServerWriter<v1::JobStatus>* writer) {
  std::string last;
  while (!context->IsCancelled() && !stop_) {
    absl::StatusOr<v1::JobStatus> status = JobStatusOf(request->job_id());
    if (!status.ok()) return rpc::ToGrpcStatus(status.status());
    const std::string now = status->SerializeAsString();
    if (now != last && !writer->Write(*status)) return grpc::Status::CANCELLED;
    last = now;
    if (status->state() != v1::JOB_STATE_RUNNING) return grpc::Status::OK;
    absl::SleepFor(absl::Milliseconds(200));
  }
  return grpc::Status(grpc::StatusCode::CANCELLED, "watch ended: the coordinator is stopping");
}

// --------------------------------------------------------------------- ingest

absl::StatusOr<v1::IngestAck> CoordinatorService::AcceptModel(const v1::IngestRequest& request,
                                                              const std::string& job_id) {
  MESHSEEK_RETURN_IF_ERROR(CheckName("model id", request.model_id(), 256, false));
  MESHSEEK_ASSIGN_OR_RETURN(const CollectionInfo info, FindCollection(request.collection()));
  (void)info;
  absl::StatusOr<TriangleMesh> mesh = rpc::MeshFromProto(request.mesh());
  if (!mesh.ok()) return Prefixed(mesh.status(), absl::StrCat("model ", request.model_id(), ": "));
  v1::Mesh stored;
  rpc::MeshToProto(*mesh, &stored);
  const std::string bytes = stored.SerializeAsString();
  const std::string fingerprint = Fingerprint(bytes);

  v1::IngestAck ack;
  ack.set_model_id(request.model_id());
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement existing, db_->Prepare("SELECT fingerprint, label, job_id FROM models "
                                       "WHERE collection = ? AND model_id = ?"));
  existing.Bind(1, request.collection()).Bind(2, request.model_id());
  MESHSEEK_ASSIGN_OR_RETURN(const bool found, existing.Step());
  if (found) {
    if (existing.ColumnText(0) != fingerprint || existing.ColumnText(1) != request.label()) {
      return absl::AlreadyExistsError(
          absl::StrCat("model ", request.model_id(), " exists in collection '",
                       request.collection(), "' with another mesh or label; remove it first"));
    }
    ack.set_job_id(existing.ColumnText(2));
    ack.set_created(false);
    return ack;
  }
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement insert,
      db_->Prepare("INSERT INTO models (collection, model_id, ordinal, label, mesh, fingerprint, "
                   "state, job_id) VALUES (?1, ?2, (SELECT COALESCE(MAX(ordinal), -1) + 1 FROM "
                   "models WHERE collection = ?1), ?3, ?4, ?5, 0, ?6)"));
  MESHSEEK_RETURN_IF_ERROR(insert.Bind(1, request.collection())
                               .Bind(2, request.model_id())
                               .Bind(3, request.label())
                               .BindBlob(4, bytes)
                               .Bind(5, fingerprint)
                               .Bind(6, job_id)
                               .Run());
  ++pending_;
  work_changed_.SignalAll();
  ack.set_job_id(job_id);
  ack.set_created(true);
  return ack;
}

grpc::Status CoordinatorService::Ingest(
    grpc::ServerContext* context,
    grpc::ServerReaderWriter<v1::IngestAck, v1::IngestRequest>* stream) {
  std::string job_id;
  v1::IngestRequest request;
  grpc::Status result = grpc::Status::OK;
  while (stream->Read(&request)) {
    if (job_id.empty()) {
      absl::StatusOr<CollectionInfo> info = FindCollection(request.collection());
      if (!info.ok()) return rpc::ToGrpcStatus(info.status());
      absl::StatusOr<std::string> job = NewJob("ingest", request.collection(), 0);
      if (!job.ok()) return rpc::ToGrpcStatus(job.status());
      job_id = *job;
    }
    // Backpressure: hold the acknowledgement while too much work waits.
    {
      absl::MutexLock lock(&mutex_);
      while (pending_ >= options_.max_pending && !context->IsCancelled() && !stop_) {
        work_changed_.WaitWithTimeout(&mutex_, absl::Milliseconds(200));
      }
    }
    if (context->IsCancelled()) {
      result = grpc::Status(grpc::StatusCode::CANCELLED, "ingest cancelled");
      break;
    }
    absl::StatusOr<v1::IngestAck> ack = AcceptModel(request, job_id);
    if (!ack.ok()) {
      result = rpc::ToGrpcStatus(ack.status());
      break;
    }
    if (!stream->Write(*ack)) {
      result = grpc::Status(grpc::StatusCode::CANCELLED, "ingest stream closed by the client");
      break;
    }
  }
  if (!job_id.empty()) {
    absl::MutexLock lock(&mutex_);
    auto close = db_->Prepare("UPDATE jobs SET stream_open = 0 WHERE id = ?");
    if (close.ok()) (void)close->Bind(1, job_id).Run();
  }
  return result;
}

// ---------------------------------------------------------------- dispatchers

void CoordinatorService::DispatchLoop() {
  while (!stop_) {
    ModelKey key;
    if (!ClaimPending(&key)) continue;
    const absl::Status status = ProcessModel(key);
    absl::MutexLock lock(&mutex_);
    in_flight_.erase(key);
    if (!status.ok()) {
      // Transient (workers unreachable): try again later, maybe elsewhere.
      MESHSEEK_LOG(WARNING) << "coordinator: model " << key.model_id << " will be retried: "
                            << status;
      retry_after_[key] = absl::Now() + absl::Seconds(2);
    }
  }
}

bool CoordinatorService::ClaimPending(ModelKey* key) {
  absl::MutexLock lock(&mutex_);
  const absl::Time now = absl::Now();
  for (auto it = retry_after_.begin(); it != retry_after_.end();) {
    it = it->second <= now ? retry_after_.erase(it) : std::next(it);
  }
  if (pending_ > static_cast<int64_t>(in_flight_.size() + retry_after_.size())) {
    auto select = db_->Prepare("SELECT collection, model_id FROM models WHERE state = 0 "
                               "ORDER BY rowid LIMIT ?");
    if (select.ok()) {
      select->Bind(1, static_cast<int64_t>(in_flight_.size() + retry_after_.size() + 1));
      while (select->Step().value_or(false)) {
        ModelKey candidate{select->ColumnText(0), select->ColumnText(1)};
        if (in_flight_.count(candidate) || retry_after_.count(candidate)) continue;
        in_flight_.insert(candidate);
        *key = std::move(candidate);
        return true;
      }
    }
  }
  work_changed_.WaitWithTimeout(&mutex_, absl::Milliseconds(500));
  return false;
}

absl::StatusOr<v1::LocalFeatures> CoordinatorService::ExtractOnWorkers(
    const v1::Mesh& mesh, const CollectionInfo& info, const std::string& model_id) {
  v1::ExtractRequest request;
  *request.mutable_mesh()->mutable_mesh() = mesh;
  *request.mutable_params() = info.params;
  request.set_model_id(model_id);
  if (info.options.extractor.method == FeatureMethod::kRldSift) {
    v1::ResampleRequest resample;
    *resample.mutable_mesh()->mutable_mesh() = mesh;
    resample.set_num_samples(info.options.extractor.rld.num_samples);
    resample.set_neighbors(info.options.extractor.rld.neighbors);
    v1::ResampleResponse resampled;
    MESHSEEK_RETURN_IF_ERROR(rpc::CallWithRetry(resample_.get(), &v1::Resample::Stub::Resample,
                                                resample, &resampled, options_.extract_deadline,
                                                retry_, &stop_));
    *request.mutable_resampled() = std::move(*resampled.mutable_graph());
  }
  v1::ExtractResponse response;
  MESHSEEK_RETURN_IF_ERROR(rpc::CallWithRetry(extract_.get(), &v1::Extract::Stub::Extract, request,
                                              &response, options_.extract_deadline, retry_, &stop_));
  return std::move(*response.mutable_features());
}

absl::StatusOr<v1::SparseHistogram> CoordinatorService::EncodeOnCodebook(
    const std::string& codebook_id, const v1::LocalFeatures& features) {
  v1::EncodeRequest request;
  request.set_codebook_id(codebook_id);
  *request.mutable_features() = features;
  v1::EncodeResponse response;
  MESHSEEK_RETURN_IF_ERROR(rpc::CallWithRetry(codebook_.get(), &v1::Codebook::Stub::Encode, request,
                                              &response, options_.call_deadline, retry_, &stop_));
  return std::move(*response.mutable_histogram());
}

absl::Status CoordinatorService::AddToIndex(const std::string& collection,
                                            const std::string& model_id,
                                            uint64_t ordinal,
                                            const std::string& label,
                                            const v1::SparseHistogram& histogram) {
  v1::AddModelRequest request;
  request.set_collection(collection);
  request.set_model_id(model_id);
  request.set_ordinal(ordinal);
  request.set_label(label);
  *request.mutable_histogram() = histogram;
  return index_->Add(request);
}

absl::Status CoordinatorService::ProcessModel(const ModelKey& key) {
  absl::StatusOr<CollectionInfo> info = FindCollection(key.collection);
  if (!info.ok()) return absl::OkStatus();  // removed meanwhile
  v1::Mesh mesh;
  uint64_t ordinal = 0;
  std::string label;
  {
    absl::MutexLock lock(&mutex_);
    MESHSEEK_ASSIGN_OR_RETURN(
        Statement select, db_->Prepare("SELECT mesh, ordinal, label FROM models WHERE "
                                       "collection = ? AND model_id = ? AND state = 0"));
    select.Bind(1, key.collection).Bind(2, key.model_id);
    MESHSEEK_ASSIGN_OR_RETURN(const bool found, select.Step());
    if (!found) return absl::OkStatus();
    if (!mesh.ParseFromString(select.ColumnBlob(0))) {
      return absl::DataLossError(absl::StrCat("model ", key.model_id, ": stored mesh does not parse"));
    }
    ordinal = static_cast<uint64_t>(select.ColumnInt(1));
    label = select.ColumnText(2);
  }
  absl::StatusOr<v1::LocalFeatures> features = ExtractOnWorkers(mesh, *info, key.model_id);
  if (!features.ok() && rpc::IsTransient(features.status())) return features.status();
  {
    absl::MutexLock lock(&mutex_);
    MESHSEEK_ASSIGN_OR_RETURN(
        Statement update,
        db_->Prepare("UPDATE models SET state = ?, error = ?, features = ?, feature_count = ? "
                     "WHERE collection = ? AND model_id = ? AND state = 0"));
    if (features.ok()) {
      update.Bind(1, int64_t{kExtracted})
          .Bind(2, "")
          .BindBlob(3, features->SerializeAsString())
          .Bind(4, static_cast<int64_t>(features->count()));
    } else {
      update.Bind(1, int64_t{kFailed}).Bind(2, features.status().ToString()).BindBlob(3, "").Bind(4, int64_t{0});
    }
    MESHSEEK_RETURN_IF_ERROR(update.Bind(5, key.collection).Bind(6, key.model_id).Run());
    if (db_->Changes() > 0) --pending_;
    work_changed_.SignalAll();
  }
  if (!features.ok() || info->codebook_id.empty()) return absl::OkStatus();
  // A built collection: index the new model with the current codebook.
  absl::StatusOr<v1::SparseHistogram> histogram = EncodeOnCodebook(info->codebook_id, *features);
  absl::Status added = histogram.ok()
                           ? AddToIndex(key.collection, key.model_id, ordinal, label, *histogram)
                           : histogram.status();
  if (!added.ok()) {
    MESHSEEK_LOG(WARNING) << "coordinator: model " << key.model_id
                          << " extracted but not indexed (build again): " << added;
    return absl::OkStatus();
  }
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement mark, db_->Prepare("UPDATE models SET indexed_codebook = ? WHERE collection = ? "
                                   "AND model_id = ?"));
  return mark.Bind(1, info->codebook_id).Bind(2, key.collection).Bind(3, key.model_id).Run();
}

// ---------------------------------------------------------------------- build

grpc::Status CoordinatorService::Build(grpc::ServerContext*,
                                       const v1::BuildRequest* request,
                                       v1::JobStatus* response) {
  absl::StatusOr<CollectionInfo> info = FindCollection(request->collection());
  if (!info.ok()) return rpc::ToGrpcStatus(info.status());
  int64_t models = 0;
  {
    absl::MutexLock lock(&mutex_);
    if (building_.count(request->collection())) {
      return grpc::Status(grpc::StatusCode::FAILED_PRECONDITION,
                          absl::StrCat("collection '", request->collection(),
                                       "' is already being built"));
    }
    absl::StatusOr<Statement> count = db_->Prepare(
        "SELECT COUNT(*), SUM(state = 0), SUM(state = 2) FROM models WHERE collection = ?");
    if (!count.ok()) return rpc::ToGrpcStatus(count.status());
    count->Bind(1, request->collection());
    if (absl::Status s = count->Run(); !s.ok()) return rpc::ToGrpcStatus(s);
    models = count->ColumnInt(0);
    if (models < 2 || count->ColumnInt(1) > 0 || count->ColumnInt(2) > 0) {
      return grpc::Status(
          grpc::StatusCode::FAILED_PRECONDITION,
          absl::StrCat("collection '", request->collection(), "' has ", models, " models, ",
                       count->ColumnInt(1), " waiting for extraction and ", count->ColumnInt(2),
                       " failed; a build needs at least 2, all extracted (remove failed ones)"));
    }
    building_.insert(request->collection());
  }
  absl::StatusOr<std::string> job = NewJob("build", request->collection(), models);
  if (!job.ok()) {
    absl::MutexLock lock(&mutex_);
    building_.erase(request->collection());
    return rpc::ToGrpcStatus(job.status());
  }
  {
    absl::MutexLock lock(&mutex_);
    threads_.emplace_back(
        [this, job = *job, collection = request->collection()] { RunBuild(job, collection); });
  }
  v1::JobRequest get;
  get.set_job_id(*job);
  return GetJob(nullptr, &get, response);
}

void CoordinatorService::RunBuild(const std::string& job_id, const std::string& collection) {
  const std::string codebook_id = absl::StrCat(collection, "@", job_id);
  auto fail = [&](const absl::Status& status) {
    MESHSEEK_LOG(ERROR) << "coordinator: " << job_id << " failed: " << status;
    (void)FinishJob(job_id, v1::JOB_STATE_FAILED, status.ToString());
    absl::MutexLock lock(&mutex_);
    building_.erase(collection);
  };
  absl::StatusOr<CollectionInfo> info = FindCollection(collection);
  if (!info.ok()) return fail(info.status());
  const absl::Time start = absl::Now();
  struct Member {
    std::string model_id;
    uint64_t ordinal;
    std::string label;
    v1::LocalFeatures features;
    bool indexed;
  };
  std::vector<Member> members;
  {
    absl::MutexLock lock(&mutex_);
    auto select = db_->Prepare(
        "SELECT model_id, ordinal, label, features, indexed_codebook FROM models "
        "WHERE collection = ? AND state = 1 ORDER BY ordinal");
    if (!select.ok()) return fail(select.status());
    select->Bind(1, collection);
    while (true) {
      absl::StatusOr<bool> row = select->Step();
      if (!row.ok()) return fail(row.status());
      if (!*row) break;
      Member m{select->ColumnText(0), static_cast<uint64_t>(select->ColumnInt(1)),
               select->ColumnText(2), {}, select->ColumnText(4) == codebook_id};
      if (!m.features.ParseFromString(select->ColumnBlob(3))) {
        return fail(absl::DataLossError(
            absl::StrCat("model ", m.model_id, ": stored features do not parse")));
      }
      members.push_back(std::move(m));
    }
  }
  // 1. The codebook, unless a resumed build trained it already. Descriptors
  //    go in ingest order: the in-process pipeline's input, chunked.
  absl::Status trained = rpc::RetryTransient(
      [&]() -> absl::Status {
        {
          grpc::ClientContext context;
          rpc::SetDeadline(&context, options_.call_deadline);
          v1::GetCodebookRequest get;
          get.set_codebook_id(codebook_id);
          v1::CodebookInfo existing;
          const grpc::Status found = codebook_->GetCodebook(&context, get, &existing);
          if (found.ok()) return absl::OkStatus();
          if (found.error_code() != grpc::StatusCode::NOT_FOUND) return rpc::FromGrpcStatus(found);
        }
        grpc::ClientContext context;
        rpc::SetDeadline(&context, absl::Hours(2));  // k-means on a large collection
        v1::CodebookInfo trained_info;
        auto writer = codebook_->Train(&context, &trained_info);
        v1::TrainCodebookRequest chunk;
        chunk.set_codebook_id(codebook_id);
        chunk.set_vocabulary(info->options.kmeans.num_centroids);
        chunk.set_kmeans_points_per_centroid(info->options.kmeans.max_points_per_centroid);
        chunk.set_kmeans_iterations(info->options.kmeans.max_iterations);
        chunk.set_kmeans_assignment(KMeansAssignmentName(info->options.kmeans.assignment));
        chunk.set_seed(info->options.kmeans.seed);
        chunk.set_dimension(kSiftDimension);
        bool open = true;
        for (const Member& m : members) {
          chunk.mutable_descriptors()->append(m.features.descriptors());
          if (chunk.descriptors().size() >= kTrainChunkBytes) {
            open = open && writer->Write(chunk);
            chunk.clear_descriptors();
          }
        }
        open = open && writer->Write(chunk);
        writer->WritesDone();
        return rpc::FromGrpcStatus(writer->Finish());
      },
      retry_, &stop_);
  if (!trained.ok()) return fail(Prefixed(trained, "codebook training: "));
  const absl::Time trained_at = absl::Now();
  // 2. Encode and index every model not yet indexed with this codebook.
  std::vector<absl::Status> errors(members.size());
  ParallelFor(members.size(), options_.max_in_flight, [&](std::size_t i) {
    Member& m = members[i];
    if (m.indexed || stop_) return;
    absl::StatusOr<v1::SparseHistogram> histogram = EncodeOnCodebook(codebook_id, m.features);
    errors[i] = histogram.ok() ? AddToIndex(collection, m.model_id, m.ordinal, m.label, *histogram)
                               : histogram.status();
    if (!errors[i].ok()) return;
    absl::MutexLock lock(&mutex_);
    auto mark = db_->Prepare(
        "UPDATE models SET indexed_codebook = ? WHERE collection = ? AND model_id = ?");
    errors[i] = mark.ok() ? mark->Bind(1, codebook_id).Bind(2, collection).Bind(3, m.model_id).Run()
                          : mark.status();
  });
  if (stop_) return;  // resumed after the restart
  for (std::size_t i = 0; i < members.size(); ++i) {
    if (!errors[i].ok()) return fail(Prefixed(errors[i], absl::StrCat("model ", members[i].model_id, ": ")));
  }
  {
    absl::MutexLock lock(&mutex_);
    auto update = db_->Prepare("UPDATE collections SET codebook_id = ? WHERE name = ?");
    absl::Status done = update.ok() ? update->Bind(1, codebook_id).Bind(2, collection).Run()
                                    : update.status();
    if (!done.ok()) {
      building_.erase(collection);
      return;
    }
  }
  MESHSEEK_LOG(INFO) << "coordinator: " << job_id << ": " << members.size()
                     << " models; features loaded and codebook trained in "
                     << absl::FormatDuration(trained_at - start) << ", encoded and indexed in "
                     << absl::FormatDuration(absl::Now() - trained_at);
  (void)FinishJob(job_id, v1::JOB_STATE_SUCCEEDED,
                  absl::StrCat(members.size(), " models indexed with codebook ", codebook_id));
  absl::MutexLock lock(&mutex_);
  building_.erase(collection);
}

// ------------------------------------------------------- query, remove, eval

grpc::Status CoordinatorService::Query(grpc::ServerContext*,
                                       const v1::QueryRequest* request,
                                       v1::QueryResponse* response) {
  if (request->top_k() == 0) {
    return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT, "query: top_k must be at least 1");
  }
  absl::StatusOr<CollectionInfo> info = FindCollection(request->collection());
  if (!info.ok()) return rpc::ToGrpcStatus(info.status());
  if (info->codebook_id.empty()) {
    return grpc::Status(grpc::StatusCode::FAILED_PRECONDITION,
                        absl::StrCat("collection '", request->collection(), "' is not built yet"));
  }
  absl::StatusOr<TriangleMesh> mesh = rpc::MeshFromProto(request->mesh());
  if (!mesh.ok()) return rpc::ToGrpcStatus(Prefixed(mesh.status(), "query: "));
  v1::Mesh arrays;
  rpc::MeshToProto(*mesh, &arrays);
  absl::StatusOr<v1::LocalFeatures> features = ExtractOnWorkers(arrays, *info, "query");
  if (!features.ok()) return rpc::ToGrpcStatus(features.status());
  absl::StatusOr<v1::SparseHistogram> histogram = EncodeOnCodebook(info->codebook_id, *features);
  if (!histogram.ok()) return rpc::ToGrpcStatus(histogram.status());
  v1::SearchRequest search;
  search.set_collection(request->collection());
  *search.mutable_histogram() = *histogram;
  search.set_top_k(request->top_k());
  search.set_candidates(request->candidates());
  search.set_kl_epsilon(info->options.kl.epsilon);
  absl::StatusOr<std::vector<v1::ScoredModel>> found = index_->Search(search);
  if (!found.ok()) return rpc::ToGrpcStatus(found.status());
  for (v1::ScoredModel& m : *found) *response->add_results() = std::move(m);
  response->set_query_features(features->count());
  return grpc::Status::OK;
}

grpc::Status CoordinatorService::RemoveModel(grpc::ServerContext*,
                                             const v1::RemoveModelFromCollectionRequest* request,
                                             v1::RemoveModelFromCollectionResponse* response) {
  absl::StatusOr<CollectionInfo> info = FindCollection(request->collection());
  if (!info.ok()) return rpc::ToGrpcStatus(info.status());
  // The index first: a failure there leaves the model in both, and the
  // removal can simply be retried.
  absl::StatusOr<bool> removed = index_->Remove(request->collection(), request->model_id());
  if (!removed.ok()) return rpc::ToGrpcStatus(removed.status());
  absl::MutexLock lock(&mutex_);
  absl::StatusOr<Statement> erase = db_->Prepare(
      "DELETE FROM models WHERE collection = ? AND model_id = ? RETURNING state");
  if (!erase.ok()) return rpc::ToGrpcStatus(erase.status());
  erase->Bind(1, request->collection()).Bind(2, request->model_id());
  absl::StatusOr<bool> row = erase->Step();
  if (!row.ok()) return rpc::ToGrpcStatus(row.status());
  if (*row && erase->ColumnInt(0) == kPending) --pending_;
  response->set_removed(*row);
  return grpc::Status::OK;
}

grpc::Status CoordinatorService::Evaluate(grpc::ServerContext* context,
                                          const v1::EvaluateRequest* request,
                                          grpc::ServerWriter<v1::EvaluateRow>* writer) {
  v1::GetCollectionRequest get;
  get.set_name(request->collection());
  v1::Collection collection;
  grpc::Status status = GetCollection(nullptr, &get, &collection);
  if (!status.ok()) return status;
  if (collection.codebook_id().empty() || collection.indexed() != collection.models()) {
    return grpc::Status(
        grpc::StatusCode::FAILED_PRECONDITION,
        absl::StrCat("collection '", request->collection(), "' has ", collection.models(),
                     " models of which ", collection.indexed(),
                     " are indexed with its current codebook; build it first"));
  }
  absl::StatusOr<CollectionInfo> info = FindCollection(request->collection());
  if (!info.ok()) return rpc::ToGrpcStatus(info.status());
  std::map<std::string, uint32_t> feature_counts;
  {
    absl::MutexLock lock(&mutex_);
    auto select = db_->Prepare("SELECT model_id, feature_count FROM models WHERE collection = ?");
    if (!select.ok()) return rpc::ToGrpcStatus(select.status());
    select->Bind(1, request->collection());
    while (select->Step().value_or(false)) {
      feature_counts[select->ColumnText(0)] = static_cast<uint32_t>(select->ColumnInt(1));
    }
  }
  v1::EvaluateRow out;
  uint64_t rows = 0;
  const absl::Status streamed = index_->ForEachDistanceRow(
      request->collection(), info->options.kl.epsilon,
      [&](const IndexShards::Row& row) -> absl::Status {
        if (context->IsCancelled()) return absl::CancelledError("evaluate: cancelled");
        out.set_model_id(row.model->model_id());
        out.set_label(row.model->label());
        out.mutable_distances()->Assign(row.distances.begin(), row.distances.end());
        out.set_features(feature_counts[row.model->model_id()]);
        if (!writer->Write(out)) return absl::CancelledError("evaluate: client went away");
        ++rows;
        return absl::OkStatus();
      });
  if (!streamed.ok()) return rpc::ToGrpcStatus(streamed);
  if (rows != collection.models()) {
    return grpc::Status(grpc::StatusCode::FAILED_PRECONDITION,
                        absl::StrCat("index returned ", rows, " rows for ", collection.models(),
                                     " models; build again"));
  }
  return grpc::Status::OK;
}

}  // namespace meshseek
