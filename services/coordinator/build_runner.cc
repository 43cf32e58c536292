#include "services/coordinator/build_runner.h"

#include <algorithm>

#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "common/base/logging.h"
#include "common/base/parallel.h"
#include "common/base/status_macros.h"
#include "common/bof/kmeans.h"
#include "common/rpc/status.h"
#include "services/coordinator/ranking.h"

namespace meshseek {
namespace {

constexpr std::size_t kTrainChunkBytes = 4 << 20;

}  // namespace

BuildRunner::BuildRunner(CoordinatorStore* store,
                         Workers* workers,
                         LiveIndex* live,
                         const CoordinatorOptions& options,
                         const std::atomic<bool>* stop)
    : store_(store), workers_(workers), live_(live), options_(options), stop_(stop) {}

BuildRunner::~BuildRunner() { Join(); }

void BuildRunner::Join() {
  std::vector<std::thread> threads;
  {
    absl::MutexLock lock(&mutex_);
    threads.swap(threads_);
  }
  for (std::thread& t : threads) {
    if (t.joinable()) t.join();
  }
}

void BuildRunner::Done(const std::string& collection) {
  absl::MutexLock lock(&mutex_);
  building_.erase(collection);
}

absl::StatusOr<std::string> BuildRunner::Start(const std::string& collection) {
  MESHSEEK_ASSIGN_OR_RETURN(const CollectionPlan plan, LoadCollectionPlan(store_, collection));
  if (plan.member) {
    return absl::InvalidArgumentError(absl::StrCat("collection '",
                                                   collection,
                                                   "' is a member of '",
                                                   collection.substr(0, collection.find('~')),
                                                   "': build that one"));
  }
  {
    absl::MutexLock lock(&mutex_);
    if (!building_.insert(collection).second) {
      return absl::FailedPreconditionError(
          absl::StrCat("collection '", collection, "' is already being built"));
    }
  }
  absl::StatusOr<ModelCounts> counts = store_->CountModels(plan.PartNames(), "");
  absl::Status ready = counts.status();
  if (counts.ok() && (counts->pending > 0 || counts->extracted < 2)) {
    ready = absl::FailedPreconditionError(absl::StrCat(
        "collection '", collection, "' has ", counts->models, " models, ", counts->pending,
        " waiting for extraction, ", counts->extracted, " extracted and ", counts->failed,
        " failed; a build needs none waiting and at least 2 extracted"));
  }
  // Work items: each model in each part.
  absl::StatusOr<std::string> job =
      ready.ok() ? store_->NewJob("build", collection, counts->extracted * plan.parts.size())
                 : ready;
  if (!job.ok()) {
    Done(collection);
    return job.status();
  }
  absl::MutexLock lock(&mutex_);
  threads_.emplace_back([this, job = *job, collection] { Run(job, collection); });
  return *job;
}

absl::Status BuildRunner::ResumeInterrupted() {
  MESHSEEK_ASSIGN_OR_RETURN(const auto builds, store_->RunningBuilds());
  MESHSEEK_ASSIGN_OR_RETURN(const std::vector<std::string> names, store_->ListCollectionNames());
  absl::MutexLock lock(&mutex_);
  for (const auto& [job, collection] : builds) {
    if (!building_.insert(collection).second) continue;
    MESHSEEK_LOG(INFO) << "coordinator: resuming " << job << " of collection " << collection;
    threads_.emplace_back([this, job = job, collection = collection] { Run(job, collection); });
  }
  // The others: what a kill cut off between extraction and ranking. A
  // resumed build catches up when it ends.
  std::vector<std::string> idle;
  for (const std::string& name : names) {
    if (building_.count(name) == 0) idle.push_back(name);
  }
  threads_.emplace_back([this, idle = std::move(idle)] {
    for (const std::string& name : idle) {
      if (*stop_) return;
      if (absl::Status s = live_->CatchUp(name); !s.ok() && !*stop_) {
        MESHSEEK_LOG(WARNING) << "coordinator: " << name << ": live indexing: " << s;
      }
    }
  });
  return absl::OkStatus();
}

absl::Status BuildRunner::Train(const std::string& codebook_id,
                                const CollectionInfo& info,
                                const std::vector<v1::LocalFeatures>& features) {
  v1::Codebook::Stub* codebook = workers_->codebook();
  return rpc::RetryTransient(
      [&]() -> absl::Status {
        {
          // Trained already by this job before a restart?
          grpc::ClientContext context;
          rpc::SetDeadline(&context, options_.call_deadline);
          v1::GetCodebookRequest get;
          get.set_codebook_id(codebook_id);
          v1::CodebookInfo existing;
          const grpc::Status found = codebook->GetCodebook(&context, get, &existing);
          if (found.ok()) return absl::OkStatus();
          if (found.error_code() != grpc::StatusCode::NOT_FOUND) return rpc::FromGrpcStatus(found);
        }
        grpc::ClientContext context;
        rpc::SetDeadline(&context, absl::Hours(2));  // k-means on a large collection
        v1::CodebookInfo trained;
        auto writer = codebook->Train(&context, &trained);
        v1::TrainCodebookRequest chunk;
        chunk.set_codebook_id(codebook_id);
        *chunk.mutable_params() = info.params;
        // One dimension per method; the codebook service checks every chunk.
        uint64_t total = 0;
        for (const v1::LocalFeatures& f : features) {
          if (f.count() > 0 && chunk.dimension() == 0) chunk.set_dimension(f.dimension());
          if (f.count() > 0 && f.dimension() != chunk.dimension()) {
            return absl::DataLossError(absl::StrCat("stored features of dimensions ",
                                                    chunk.dimension(),
                                                    " and ",
                                                    f.dimension(),
                                                    " in one collection"));
          }
          total += f.count();
        }
        // Only the rows k-means trains on (the same codebook, a quarter of
        // BF-DSIFT's bytes on the wire and in the codebook service).
        const std::vector<std::size_t> rows = KMeansTrainingRows(total, info.options.kmeans);
        if (rows.size() < total) chunk.set_sampled_from(total);
        const std::size_t dim = chunk.dimension();
        auto row = rows.begin();
        uint64_t first_row = 0;  // of the current model's features
        bool open = true;
        for (const v1::LocalFeatures& f : features) {
          const uint64_t end_row = first_row + f.count();
          if (rows.size() == total) {
            chunk.mutable_descriptors()->append(f.descriptors());
          } else {
            for (; row != rows.end() && *row < end_row; ++row) {
              chunk.mutable_descriptors()->append(f.descriptors(), (*row - first_row) * dim, dim);
            }
          }
          first_row = end_row;
          if (chunk.descriptors().size() >= kTrainChunkBytes) {
            open = open && writer->Write(chunk);
            chunk.clear_descriptors();
          }
        }
        open = open && writer->Write(chunk);
        writer->WritesDone();
        return rpc::FromGrpcStatus(writer->Finish());
      },
      workers_->retry(), stop_);
}

absl::Status BuildRunner::BuildPart(const std::string& job_id,
                                    const CollectionInfo& part,
                                    const std::optional<std::set<std::string>>& eligible) {
  const std::string codebook_id = absl::StrCat(part.name, "@", job_id);
  const absl::Time start = absl::Now();
  MESHSEEK_ASSIGN_OR_RETURN(std::vector<ExtractedModel> members,
                            store_->ExtractedModels(part.name));
  if (eligible.has_value()) {
    // A fused collection's models extracted by every method, the same in each part.
    members.erase(
        std::remove_if(members.begin(),
                       members.end(),
                       [&](const ExtractedModel& m) { return eligible->count(m.model_id) == 0; }),
        members.end());
  }
  // Read and parsed once, for training and encoding. Models indexed by an
  // earlier build have had theirs freed: extracted again from their meshes,
  // on the extract workers.
  std::vector<v1::LocalFeatures> features(members.size());
  std::vector<absl::Status> loaded(members.size());
  ParallelFor(members.size(), options_.max_in_flight, [&](std::size_t i) {
    if (*stop_) return;
    absl::StatusOr<v1::LocalFeatures> got = workers_->FeaturesOf(store_, part, members[i]);
    if (got.ok()) {
      features[i] = *std::move(got);
    } else {
      loaded[i] = got.status();
    }
  });
  if (*stop_) return absl::CancelledError("stopping");
  for (const absl::Status& s : loaded) MESHSEEK_RETURN_IF_ERROR(s);
  const absl::Time loaded_at = absl::Now();
  // 1. The codebook, unless a resumed build trained it already or the method
  // is global (then the id only names this generation of the index).
  const bool global =
      FeatureMethodInfoOf(part.options.extractor.method).kind == DescriptorKind::kGlobal;
  if (!global) {
    if (absl::Status trained = Train(codebook_id, part, features); !trained.ok()) {
      return Prefixed(trained, "codebook training: ");
    }
  }
  const absl::Time trained_at = absl::Now();
  // 2. Encode and index every model not yet indexed with this codebook.
  std::vector<absl::Status> errors(members.size());
  ParallelFor(members.size(), options_.max_in_flight, [&](std::size_t i) {
    const ExtractedModel& m = members[i];
    if (m.indexed_codebook == codebook_id || *stop_) return;
    absl::StatusOr<IndexSignature> signature = workers_->Encode(part, codebook_id, features[i]);
    errors[i] = signature.ok()
                    ? workers_->AddToIndex(part.name, m.model_id, m.ordinal, m.label, *signature)
                    : signature.status();
    if (errors[i].ok()) errors[i] = store_->MarkIndexed({part.name, m.model_id}, codebook_id);
  });
  if (*stop_) return absl::CancelledError("stopping");
  for (std::size_t i = 0; i < members.size(); ++i) {
    if (!errors[i].ok()) {
      return Prefixed(errors[i], absl::StrCat("model ", members[i].model_id, ": "));
    }
  }
  MESHSEEK_RETURN_IF_ERROR(store_->SetCodebook(part.name, codebook_id));
  MESHSEEK_LOG(INFO) << "coordinator: " << job_id << ": " << part.name << ": " << members.size()
                     << " models; features loaded in " << absl::FormatDuration(loaded_at - start)
                     << ", codebook trained in " << absl::FormatDuration(trained_at - loaded_at)
                     << ", encoded and indexed in "
                     << absl::FormatDuration(absl::Now() - trained_at);
  return absl::OkStatus();
}

void BuildRunner::Run(const std::string& job_id, const std::string& collection) {
  auto fail = [&](const absl::Status& status) {
    MESHSEEK_LOG(ERROR) << "coordinator: " << job_id << " failed: " << status;
    (void)store_->FinishJob(job_id, v1::JOB_STATE_FAILED, status.ToString());
    Done(collection);
  };
  absl::StatusOr<CollectionPlan> plan = LoadCollectionPlan(store_, collection);
  if (!plan.ok()) return fail(plan.status());
  // A fused collection indexes the models every method extracted.
  std::optional<std::set<std::string>> eligible;
  if (plan->fused()) {
    eligible.emplace();
    v1::ListCollectionModelsRequest list;
    list.set_collection(collection);
    list.set_state(v1::MODEL_STATE_EXTRACTED);
    list.set_page_size(1000);
    do {
      absl::StatusOr<v1::ListCollectionModelsResponse> page =
          store_->ListModels(list, plan->PartNames());
      if (!page.ok()) return fail(page.status());
      for (const v1::ModelInfo& m : page->models()) eligible->insert(m.model_id());
      list.set_page_token(page->next_page_token());
    } while (!list.page_token().empty());
  }
  for (const CollectionInfo& part : plan->parts) {
    const absl::Status built = BuildPart(job_id, part, eligible);
    if (*stop_) return Done(collection);  // resumed after the restart
    if (!built.ok()) {
      return fail(plan->fused() ? Prefixed(built, absl::StrCat(part.name, ": ")) : built);
    }
  }
  // 3. A rescaled collection's ranking state, from the parts just indexed.
  const std::string codebook_id = absl::StrCat(collection, "@", job_id);
  if (plan->options.rescaled()) {
    const absl::Time start = absl::Now();
    absl::StatusOr<RankingState> state =
        ComputeRankingState(workers_->index(), *plan, options_.ranking_graph);
    if (*stop_) return Done(collection);
    if (!state.ok()) return fail(Prefixed(state.status(), "ranking: "));
    if (absl::Status s = store_->SetRanking(collection, job_id, state->Serialize()); !s.ok()) {
      return fail(s);
    }
    const bool approximate = plan->options.rerank.enabled() &&
                             state->model_ids.size() > options_.ranking_graph.exact_graph_models;
    MESHSEEK_LOG(INFO) << "coordinator: " << job_id << ": ranking state of "
                       << state->model_ids.size() << " models in "
                       << absl::FormatDuration(absl::Now() - start)
                       << (approximate ? " (neighbour graph from candidates)" : "");
  }
  if (absl::Status s = store_->SetCodebook(collection, codebook_id); !s.ok()) return fail(s);
  absl::StatusOr<ModelCounts> counts = store_->CountModels(plan->PartNames(), job_id);
  const uint64_t failed = counts.ok() ? counts->failed : 0;
  const uint64_t indexed = counts.ok() ? counts->indexed : 0;
  std::string message = absl::StrCat(indexed, " models indexed with codebook ", codebook_id);
  if (plan->fused()) {
    message = absl::StrCat(
        indexed, " models indexed by ", plan->options.MethodName(), " (build ", job_id, ")");
  }
  if (failed > 0) {
    absl::StrAppend(&message, "; ", failed, " failed models left out (meshseek status --collection ",
                    collection, " lists them)");
  }
  // Indexed (and ranked): their features are not read before the next build.
  if (absl::Status s = store_->DropFeatures(plan->PartNames(), job_id); !s.ok()) return fail(s);
  (void)store_->FinishJob(job_id, v1::JOB_STATE_SUCCEEDED, message);
  Done(collection);
  // Models extracted while the build ran: indexed with the new codebooks now.
  if (absl::Status s = live_->CatchUp(collection); !s.ok() && !*stop_) {
    MESHSEEK_LOG(WARNING) << "coordinator: " << collection << ": live indexing: " << s;
  }
}

}  // namespace meshseek
