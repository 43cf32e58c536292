// The forward index of a KlInvertedIndex (kl_inverted_index.h): per model its
// entries, one uint32 each (word << 16 | value id, in word order), appended
// as models arrive and read back for exact distances to a few candidates,
// for a scan without postings, and to rebuild a segment.
//
// Where it lives. In memory by default. In a file for collections whose
// forward index would outgrow the service's memory (issue 37: BF-DSIFT's
// 40,000-word histograms hold about 10,600 entries a model, 42 KB, so 4.2 GB
// at 100,000 models): an unlinked temporary file in the given folder, read
// with pread, so the kernel's page cache holds what is read often and the
// process keeps only offsets. The file is derived data: the index service
// rebuilds it from its SQLite store at every start (index_service.h), so a
// kill -9 leaves nothing to check and no file behind (it was never linked).
//
// Growth: appends only. Entries of removed or replaced models stay until
// the owner rewrites the store (KlInvertedIndex does so once they outnumber
// the live ones).
//
// Thread safety: Read may run concurrently with itself; Append needs
// exclusive access. An I/O error on the file is a machine fault, not an
// input error: Read logs it and aborts, and the restarted service rebuilds
// the file from its store.
#ifndef MESHSEEK_COMMON_SEARCH_FORWARD_STORE_H_
#define MESHSEEK_COMMON_SEARCH_FORWARD_STORE_H_

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/types/span.h"

namespace meshseek {

class ForwardStore {
 public:
  /// A store in memory.
  static std::unique_ptr<ForwardStore> InMemory();
  /// A store in an unlinked temporary file in `dir` (created if missing);
  /// Internal naming the folder when it cannot be made or written.
  static absl::StatusOr<std::unique_ptr<ForwardStore>> InFile(const std::string& dir);

  ForwardStore(const ForwardStore&) = delete;
  ForwardStore& operator=(const ForwardStore&) = delete;
  ~ForwardStore();

  bool in_file() const { return fd_ >= 0; }
  /// Entries appended so far (the next offset).
  uint64_t size() const { return size_; }

  /// Appends `entries`; their offset, or Internal (disk full: nothing
  /// appended).
  absl::StatusOr<uint64_t> Append(absl::Span<const uint32_t> entries);
  /// The `count` entries at `offset` (within size()): a view of the memory,
  /// or of `buffer` where a file's entries are read.
  absl::Span<const uint32_t> Read(uint64_t offset, uint32_t count, std::vector<uint32_t>* buffer) const;

  /// Bytes the process holds (the file's are the kernel's).
  std::size_t MemoryBytes() const;
  /// Bytes of the file (0 in memory).
  uint64_t FileBytes() const { return in_file() ? size_ * sizeof(uint32_t) : 0; }

 private:
  ForwardStore() = default;

  std::vector<uint32_t> memory_;
  int fd_ = -1;
  std::string dir_;  // for messages
  uint64_t size_ = 0;
};

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_SEARCH_FORWARD_STORE_H_
