// Local features between a model's extraction and its indexing, one file a
// model beside coordinator.db, not rows in it (docs/design.md "Bounded
// storage").
//
// Why files. BF-DSIFT alone makes about 3.2 MB a model. As SQLite blobs,
// freeing them after a build (`UPDATE models SET features = NULL`, then
// `PRAGMA incremental_vacuum` to give the pages back) rewrote every row and
// relocated the database's pages: measured on McGill's 255 models, the
// default fusion's build spent about 120 s of its 294 s there, on one core,
// holding the store's lock (bench/results/services_ratio.txt). A file is
// unlinked in microseconds and its reads go to the page cache, not through
// 4 KB database pages.
//
// A cache, not a record. Every feature set can be extracted again from the
// stored mesh (Workers::FeaturesOf does, for models whose features a build
// freed), so these files carry nothing that durability depends on:
//   - a write is a temporary file renamed into place, without fsync; a kill
//     leaves the old file or the new one, never a mixture;
//   - a file that is absent, cut short, of another model (a hash collision),
//     or whose checksum fails reads as absent (Get: nullopt), and the build
//     extracts that model again. Nothing is ever taken from a damaged file.
//
// Layout: <dir>/<hh>/<16 hex digits>, the digits FNV-1a 64 of
// "<collection>\0<model_id>" and hh its first two (256 folders, so that a
// folder holds at most a few thousand files at 100,000 models a member). A
// file is
//   "MSF1" | u32 key length | u64 payload length | u32 CRC-32 of key and
//   payload | key | payload (serialized v1::LocalFeatures)
// with integers little-endian.
//
// Thread-safe: every call works on its own files (a temporary name is
// unique to its thread and call); two writers of one model leave one
// complete file of either.
#ifndef MESHSEEK_SERVICES_COORDINATOR_FEATURE_FILES_H_
#define MESHSEEK_SERVICES_COORDINATOR_FEATURE_FILES_H_

#include <cstdint>
#include <optional>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace meshseek {

class FeatureFiles {
 public:
  /// Payloads above this are refused by Put and not read by Get: far above
  /// any method's features (BF-DSIFT's are about 3.2 MB a model) and below
  /// what the extract service may send (its message limit).
  static constexpr uint64_t kMaxPayloadBytes = uint64_t{1} << 30;

  /// Creates `dir` if needed; PermissionDenied when it cannot.
  static absl::StatusOr<FeatureFiles> Open(std::string dir);

  /// Stores `payload` as the features of (collection, model_id), replacing
  /// any. PermissionDenied / DataLoss (disk full) naming the file.
  absl::Status Put(absl::string_view collection,
                   absl::string_view model_id,
                   absl::string_view payload) const;
  /// The stored payload; nullopt when there is none or it is not intact.
  std::optional<std::string> Get(absl::string_view collection, absl::string_view model_id) const;
  /// Removes the model's file; none is not an error.
  void Remove(absl::string_view collection, absl::string_view model_id) const;

  const std::string& dir() const { return dir_; }
  /// The file that holds (collection, model_id): for tests and operators.
  std::string PathOf(absl::string_view collection, absl::string_view model_id) const;

 private:
  explicit FeatureFiles(std::string dir) : dir_(std::move(dir)) {}

  std::string dir_;
};

}  // namespace meshseek

#endif  // MESHSEEK_SERVICES_COORDINATOR_FEATURE_FILES_H_
