#include "common/search/forward_store.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "absl/strings/str_cat.h"
#include "common/base/logging.h"

namespace meshseek {

std::unique_ptr<ForwardStore> ForwardStore::InMemory() {
  return std::unique_ptr<ForwardStore>(new ForwardStore());
}

absl::StatusOr<std::unique_ptr<ForwardStore>> ForwardStore::InFile(const std::string& dir) {
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  // O_TMPFILE: a file that never had a name, gone with its last descriptor.
  // Where the file system lacks it (overlayfs before Linux 6.6), a named
  // temporary unlinked at once (a crash between the two leaves a
  // forward-XXXXXX file, which the index service clears at start).
  int fd = open(dir.c_str(), O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
  if (fd < 0 && (errno == EOPNOTSUPP || errno == EISDIR || errno == EINVAL)) {
    std::string name = dir + "/forward-XXXXXX";
    fd = mkostemp(name.data(), O_CLOEXEC);
    if (fd >= 0) unlink(name.c_str());
  }
  if (fd < 0) {
    return absl::InternalError(absl::StrCat("forward index: cannot make a temporary file in ", dir,
                                            ": ", std::strerror(errno)));
  }
  std::unique_ptr<ForwardStore> store(new ForwardStore());
  store->fd_ = fd;
  store->dir_ = dir;
  return store;
}

ForwardStore::~ForwardStore() {
  if (fd_ >= 0) close(fd_);
}

absl::StatusOr<uint64_t> ForwardStore::Append(absl::Span<const uint32_t> entries) {
  const uint64_t offset = size_;
  if (!in_file()) {
    memory_.insert(memory_.end(), entries.begin(), entries.end());
  } else {
    const auto* bytes = reinterpret_cast<const char*>(entries.data());
    std::size_t left = entries.size() * sizeof(uint32_t);
    off_t at = static_cast<off_t>(offset * sizeof(uint32_t));
    while (left > 0) {
      const ssize_t wrote = pwrite(fd_, bytes, left, at);
      if (wrote < 0 && errno == EINTR) continue;
      if (wrote <= 0) {
        const int why = errno;
        // Nothing appended: the size stays, so the partial bytes are overwritten next time.
        return absl::InternalError(absl::StrCat("forward index in ", dir_, ": cannot write ",
                                                left, " bytes: ", std::strerror(why)));
      }
      bytes += wrote;
      left -= static_cast<std::size_t>(wrote);
      at += wrote;
    }
  }
  size_ += entries.size();
  return offset;
}

absl::Span<const uint32_t> ForwardStore::Read(uint64_t offset, uint32_t count,
                                              std::vector<uint32_t>* buffer) const {
  if (!in_file()) return absl::MakeConstSpan(memory_.data() + offset, count);
  buffer->resize(count);
  auto* bytes = reinterpret_cast<char*>(buffer->data());
  std::size_t left = static_cast<std::size_t>(count) * sizeof(uint32_t);
  off_t at = static_cast<off_t>(offset * sizeof(uint32_t));
  while (left > 0) {
    const ssize_t got = pread(fd_, bytes, left, at);
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) {
      MESHSEEK_LOG(FATAL) << "forward index in " << dir_ << ": cannot read " << left
                          << " bytes at " << at << ": " << (got < 0 ? std::strerror(errno) : "end of file")
                          << " (a machine fault; the restarted service rebuilds the file)";
    }
    bytes += got;
    left -= static_cast<std::size_t>(got);
    at += got;
  }
  return absl::MakeConstSpan(*buffer);
}

std::size_t ForwardStore::MemoryBytes() const {
  return sizeof(*this) + memory_.capacity() * sizeof(uint32_t);
}

}  // namespace meshseek
