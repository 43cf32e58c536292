// The coordinator's dispatchers: `max_in_flight` threads that take PENDING
// models from the store (no in-memory queue: after a restart they simply
// continue) and run resample -> extract -> store features, and, when the
// collection has been built, encode -> index -> rank (live_index.h).
//
// Failures (CoordinatorOptions::model_attempts):
//   - a permanent error (INVALID_ARGUMENT, DATA_LOSS, FAILED_PRECONDITION:
//     the mesh is the problem, or its stored copy is damaged) marks the model
//     FAILED at once with the reason;
//   - any other error leaves it PENDING with the attempt counted and a retry
//     time (backoff doubling from retry_backoff to max_retry_backoff), in the
//     store, so a restart keeps the count; after model_attempts it is FAILED
//     with "gave up after N attempts: <last error>".
// A dispatcher with nothing to claim sleeps until the next retry time or new
// work: an idle coordinator does no work.
//
// Backpressure: ingest streams wait (WaitForRoom) while max_pending models
// are pending.
#ifndef MESHSEEK_SERVICES_COORDINATOR_DISPATCHER_H_
#define MESHSEEK_SERVICES_COORDINATOR_DISPATCHER_H_

#include <atomic>
#include <functional>
#include <thread>
#include <vector>

#include "absl/status/status.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/time.h"
#include "services/coordinator/coordinator_options.h"
#include "services/coordinator/coordinator_store.h"
#include "services/coordinator/live_index.h"
#include "services/coordinator/workers.h"

namespace meshseek {

/// Whether a model failing with `status` should be FAILED without retrying.
bool IsPermanentModelError(const absl::Status& status);

/// The wait before the attempt after `attempts` failed ones.
absl::Duration RetryBackoff(const CoordinatorOptions& options, int attempts);

class Dispatcher {
 public:
  /// Not owned; all must outlive the dispatcher. `stop` ends the loops.
  Dispatcher(CoordinatorStore* store,
             Workers* workers,
             LiveIndex* live,
             const CoordinatorOptions& options,
             const std::atomic<bool>* stop);
  ~Dispatcher();

  void Start();
  /// Wakes and joins the threads (after `stop` was set).
  void Join();

  /// `rows` model rows were stored PENDING (ingest: one per member of a
  /// fused collection) / one was deleted while PENDING (removal).
  void ModelAdded(int rows = 1);
  void PendingModelRemoved();
  /// Returns once fewer than max_pending models are pending, or when
  /// `cancelled()` or stop; true when there is room.
  bool WaitForRoom(const std::function<bool()>& cancelled);

 private:
  void Loop();
  bool Claim(ModelKey* key);
  void Process(const ModelKey& key);
  // Records a PENDING model's end: FAILED or EXTRACTED happened.
  void Ended(bool changed);

  CoordinatorStore* const store_;
  Workers* const workers_;
  LiveIndex* const live_;
  const CoordinatorOptions options_;
  const std::atomic<bool>* const stop_;

  absl::Mutex mutex_;
  // Signalled when models become pending (dispatchers wake) or stop being
  // pending (ingest streams waiting under backpressure wake).
  absl::CondVar changed_;
  std::vector<ModelKey> in_flight_ ABSL_GUARDED_BY(mutex_);
  int64_t pending_ ABSL_GUARDED_BY(mutex_) = 0;
  std::vector<std::thread> threads_;
};

}  // namespace meshseek

#endif  // MESHSEEK_SERVICES_COORDINATOR_DISPATCHER_H_
