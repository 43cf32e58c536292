// Build jobs: train the codebook on every extracted model's descriptors
// (stored since extraction, or extracted again from the mesh for models an
// earlier build indexed), in ingest order (the same input as the in-process
// pipeline), then encode and index every model; for a fused collection, each member in
// turn (the models every method extracted), then, for a fused or re-ranked
// collection, its ranking state (ranking.h). The codebook id is derived from the job
// ("<collection>@<job>") and each model records the codebook it was indexed
// with, so a build interrupted by a restart resumes where it was
// (ResumeInterrupted). Failed models are left out, and the job's message
// says how many. One build per collection at a time. A build is never what
// makes a model searchable (live_index.h): after one, live indexing catches
// up with the models extracted while it ran; after a restart, with what the
// restart cut off.
#ifndef MESHSEEK_SERVICES_COORDINATOR_BUILD_RUNNER_H_
#define MESHSEEK_SERVICES_COORDINATOR_BUILD_RUNNER_H_

#include <atomic>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "services/coordinator/coordinator_options.h"
#include "services/coordinator/coordinator_store.h"
#include "services/coordinator/live_index.h"
#include "services/coordinator/workers.h"

namespace meshseek {

class BuildRunner {
 public:
  /// Not owned; all must outlive the runner. `stop` ends running builds
  /// (they resume at the next start).
  BuildRunner(CoordinatorStore* store,
              Workers* workers,
              LiveIndex* live,
              const CoordinatorOptions& options,
              const std::atomic<bool>* stop);
  ~BuildRunner();

  /// Starts a build job of `collection` and returns its id.
  /// FailedPrecondition while one runs, while models are pending, or with
  /// fewer than 2 extracted models.
  absl::StatusOr<std::string> Start(const std::string& collection);
  /// Restarts the builds a restart interrupted, and catches up live
  /// indexing of every other built collection (in the background).
  absl::Status ResumeInterrupted();
  /// Joins the build threads (after `stop` was set).
  void Join();

 private:
  void Run(const std::string& job_id, const std::string& collection);
  // Trains (unless global) and indexes one part of a collection with the
  // codebook "<part>@<job>": its extracted models, or those in `eligible`.
  absl::Status BuildPart(const std::string& job_id,
                         const CollectionInfo& part,
                         const std::optional<std::set<std::string>>& eligible);
  absl::Status Train(const std::string& codebook_id,
                     const CollectionInfo& info,
                     const std::vector<v1::LocalFeatures>& features);
  // `collection` is no longer building.
  void Done(const std::string& collection);

  CoordinatorStore* const store_;
  Workers* const workers_;
  LiveIndex* const live_;
  const CoordinatorOptions options_;
  const std::atomic<bool>* const stop_;

  absl::Mutex mutex_;
  std::set<std::string> building_ ABSL_GUARDED_BY(mutex_);
  std::vector<std::thread> threads_ ABSL_GUARDED_BY(mutex_);
};

}  // namespace meshseek

#endif  // MESHSEEK_SERVICES_COORDINATOR_BUILD_RUNNER_H_
