// The codebook service: trains visual vocabularies on streamed descriptors
// (Codebook::Train, the in-process pipeline's code), stores them in SQLite
// under its data folder, and encodes descriptor sets into histograms.
//
// Training is idempotent by codebook id: a second Train of an id that exists
// answers with the stored codebook. Codebooks are immutable; they are cached
// in memory after first use and restored from the database on demand, so a
// restart loses nothing that was acknowledged.
#ifndef MESHSEEK_SERVICES_CODEBOOK_CODEBOOK_SERVICE_H_
#define MESHSEEK_SERVICES_CODEBOOK_CODEBOOK_SERVICE_H_

#include <map>
#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "common/bof/codebook.h"
#include "common/rpc/handler.h"
#include "common/store/sqlite_db.h"
#include "meshseek/v1/codebook.pb.h"

namespace meshseek {

struct CodebookServiceOptions {
  /// Folder of the database (codebook.db); created if missing.
  std::string data_dir;
  /// Threads for k-means (<= 0: all cores), and the most one encoding may
  /// use when it asks for several (EncodeRequest.threads). Results do not
  /// depend on it.
  int num_threads = 0;

  absl::Status Validate() const;
};

class CodebookService final {
 public:
  static absl::StatusOr<std::unique_ptr<CodebookService>> Create(
      const CodebookServiceOptions& options);

  absl::StatusOr<v1::CodebookInfo> Train(rpc::Reader<v1::TrainCodebookRequest> read,
                                         const rpc::CallContext& call);
  absl::StatusOr<v1::EncodeResponse> Encode(const v1::EncodeRequest& request,
                                            const rpc::CallContext& call);
  absl::StatusOr<v1::CodebookInfo> GetCodebook(const v1::GetCodebookRequest& request,
                                               const rpc::CallContext& call);

 private:
  struct Entry {
    std::shared_ptr<const Codebook> codebook;
    uint64_t training_descriptors = 0;
  };
  CodebookService(const CodebookServiceOptions& options, std::unique_ptr<Database> db)
      : options_(options), db_(std::move(db)) {}
  // The stored codebook, or NotFound naming the id.
  absl::StatusOr<Entry> Find(const std::string& id);
  static v1::CodebookInfo Describe(const std::string& id, const Entry& entry);

  const CodebookServiceOptions options_;
  absl::Mutex mutex_;
  std::unique_ptr<Database> db_ ABSL_GUARDED_BY(mutex_);
  std::map<std::string, Entry> cache_ ABSL_GUARDED_BY(mutex_);
  // Serialises training: k-means already uses every thread.
  absl::Mutex train_mutex_;
};

}  // namespace meshseek

#endif  // MESHSEEK_SERVICES_CODEBOOK_CODEBOOK_SERVICE_H_
