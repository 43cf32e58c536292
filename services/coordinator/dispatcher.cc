#include "services/coordinator/dispatcher.h"

#include <algorithm>

#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "common/base/logging.h"

namespace meshseek {
namespace {

// Longest sleep of an idle dispatcher: new work signals it; this only bounds
// how long a missed signal could delay it.
constexpr absl::Duration kIdleWait = absl::Seconds(10);

}  // namespace

bool IsPermanentModelError(const absl::Status& status) {
  switch (status.code()) {
    case absl::StatusCode::kInvalidArgument:
    case absl::StatusCode::kDataLoss:
    case absl::StatusCode::kFailedPrecondition:
      return true;
    default:
      return false;
  }
}

absl::Duration RetryBackoff(const CoordinatorOptions& options, int attempts) {
  absl::Duration wait = options.retry_backoff;
  for (int i = 1; i < attempts && wait < options.max_retry_backoff; ++i) wait *= 2;
  return std::min(wait, options.max_retry_backoff);
}

Dispatcher::Dispatcher(CoordinatorStore* store,
                       Workers* workers,
                       LiveIndex* live,
                       const CoordinatorOptions& options,
                       const std::atomic<bool>* stop)
    : store_(store), workers_(workers), live_(live), options_(options), stop_(stop) {}

Dispatcher::~Dispatcher() { Join(); }

void Dispatcher::Start() {
  {
    absl::MutexLock lock(&mutex_);
    pending_ = static_cast<int64_t>(store_->PendingCount());
    if (pending_ > 0) MESHSEEK_LOG(INFO) << "coordinator: resuming " << pending_ << " pending models";
  }
  for (int i = 0; i < options_.max_in_flight; ++i) threads_.emplace_back([this] { Loop(); });
}

void Dispatcher::Join() {
  {
    absl::MutexLock lock(&mutex_);
    changed_.SignalAll();
  }
  for (std::thread& t : threads_) {
    if (t.joinable()) t.join();
  }
  threads_.clear();
}

void Dispatcher::ModelAdded(int rows) {
  absl::MutexLock lock(&mutex_);
  pending_ += rows;
  changed_.SignalAll();
}

void Dispatcher::PendingModelRemoved() { Ended(true); }

void Dispatcher::Ended(bool changed) {
  absl::MutexLock lock(&mutex_);
  if (changed) --pending_;
  changed_.SignalAll();
}

bool Dispatcher::WaitForRoom(const std::function<bool()>& cancelled) {
  absl::MutexLock lock(&mutex_);
  while (pending_ >= options_.max_pending) {
    if (cancelled() || *stop_) return false;
    changed_.WaitWithTimeout(&mutex_, absl::Milliseconds(200));
  }
  return true;
}

void Dispatcher::Loop() {
  while (!*stop_) {
    ModelKey key;
    if (!Claim(&key)) continue;
    Process(key);
    absl::MutexLock lock(&mutex_);
    in_flight_.erase(std::find(in_flight_.begin(), in_flight_.end(), key));
    changed_.SignalAll();
  }
}

bool Dispatcher::Claim(ModelKey* key) {
  absl::MutexLock lock(&mutex_);
  absl::Duration wait = kIdleWait;
  if (pending_ > static_cast<int64_t>(in_flight_.size())) {
    const absl::Time now = absl::Now();
    absl::StatusOr<std::vector<ModelKey>> claimable = store_->ClaimablePending(now, in_flight_, 1);
    if (claimable.ok() && !claimable->empty()) {
      *key = std::move(claimable->front());
      in_flight_.push_back(*key);
      return true;
    }
    if (!claimable.ok()) {
      MESHSEEK_LOG(ERROR) << "coordinator: cannot read pending models: " << claimable.status();
      wait = absl::Seconds(1);
    } else if (absl::StatusOr<std::optional<absl::Time>> next = store_->NextRetry(now);
               next.ok() && next->has_value()) {
      // Everything claimable is in backoff: sleep until the first is due.
      wait = std::clamp(**next - now, absl::Milliseconds(1), kIdleWait);
    }
  }
  if (!*stop_) changed_.WaitWithTimeout(&mutex_, wait);
  return false;
}

void Dispatcher::Process(const ModelKey& key) {
  // Models live in collections of one method (a fused collection's members).
  absl::StatusOr<CollectionPlan> plan = LoadCollectionPlan(store_, key.collection);
  absl::StatusOr<CollectionInfo> info = plan.ok() ? OnlyPart(*plan) : plan.status();
  absl::StatusOr<std::optional<PendingModel>> pending = store_->LoadPending(key);
  if (!pending.ok()) {
    MESHSEEK_LOG(ERROR) << "coordinator: model " << key.model_id << ": " << pending.status();
    return;
  }
  if (!pending->has_value()) return;  // removed meanwhile
  const PendingModel& model = **pending;
  const int attempt = model.attempts + 1;
  absl::StatusOr<v1::LocalFeatures> features = absl::UnknownError("not extracted");
  v1::Mesh mesh;
  if (!info.ok()) {
    features = info.status();
  } else if (!mesh.ParseFromString(model.mesh)) {
    features = absl::DataLossError("the stored mesh does not parse (damaged database?)");
  } else {
    features = workers_->Extract(mesh, *info, key.model_id);
  }
  if (*stop_ && !features.ok()) return;  // cut short by the shutdown: not the model's fault
  if (features.ok()) {
    // What reads them (training, encoding) needs the descriptors only: the
    // keypoints, a quarter of BF-DSIFT's bytes, are not kept.
    features->clear_positions();
    features->clear_views();
    features->clear_ups();
    features->clear_scales();
    features->clear_levels();
    absl::StatusOr<bool> changed =
        store_->MarkExtracted(key, features->SerializeAsString(), features->count());
    if (!changed.ok()) {
      MESHSEEK_LOG(ERROR) << "coordinator: model " << key.model_id << ": " << changed.status();
      return;
    }
    Ended(*changed);
  } else if (IsPermanentModelError(features.status()) || attempt >= options_.model_attempts) {
    const std::string reason =
        IsPermanentModelError(features.status())
            ? features.status().ToString()
            : absl::StrCat("gave up after ", attempt, " attempts: ", features.status().ToString());
    MESHSEEK_LOG(WARNING) << "coordinator: model " << key.model_id << " FAILED: " << reason;
    absl::StatusOr<bool> changed = store_->MarkFailed(key, attempt, reason);
    if (!changed.ok()) {
      MESHSEEK_LOG(ERROR) << "coordinator: model " << key.model_id << ": " << changed.status();
      return;
    }
    Ended(*changed);
    return;
  } else {
    const absl::Duration wait = RetryBackoff(options_, attempt);
    MESHSEEK_LOG(WARNING) << "coordinator: model " << key.model_id << " attempt " << attempt
                          << " of " << options_.model_attempts << " failed, retried in "
                          << absl::FormatDuration(wait) << ": " << features.status();
    if (absl::Status s = store_->ScheduleRetry(key, attempt, absl::Now() + wait,
                                               features.status().ToString());
        !s.ok()) {
      MESHSEEK_LOG(ERROR) << "coordinator: model " << key.model_id << ": " << s;
    }
    return;
  }
  // A built collection: searchable now, without a build (live_index.h).
  if (absl::Status live = live_->ModelExtracted(key, *features, model.ordinal, model.label);
      !live.ok()) {
    MESHSEEK_LOG(WARNING) << "coordinator: model " << key.model_id
                          << " extracted but not yet searchable (retried at the next start or "
                             "build): "
                          << live;
  }
}

}  // namespace meshseek
