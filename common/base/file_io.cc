#include "common/base/file_io.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "absl/strings/str_cat.h"

namespace meshseek {

absl::StatusOr<std::string> ReadFileToString(const std::string& path, uint64_t max_bytes) {
  // A folder opens like a file on Linux and then reads as empty, which would
  // surface as a misleading "empty file" error downstream.
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    return absl::InvalidArgumentError(absl::StrCat(path, ": is a folder, not a file"));
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    return absl::NotFoundError(
        absl::StrCat(path, ": cannot open file (", std::strerror(errno), ")"));
  }
  if (max_bytes != std::numeric_limits<uint64_t>::max()) {
    // The size is checked first, and the read is capped too: a pipe or a file
    // that grows while it is read has no trustworthy size.
    const uint64_t size = std::filesystem::file_size(path, ec);
    if (!ec && size > max_bytes) {
      return absl::ResourceExhaustedError(
          absl::StrCat(path, ": ", size, " bytes, more than the limit of ", max_bytes));
    }
    std::string contents;
    char buffer[1 << 16];
    while (in.read(buffer, sizeof buffer) || in.gcount() > 0) {
      if (contents.size() + static_cast<uint64_t>(in.gcount()) > max_bytes) {
        return absl::ResourceExhaustedError(
            absl::StrCat(path, ": more than the limit of ", max_bytes, " bytes"));
      }
      contents.append(buffer, static_cast<std::size_t>(in.gcount()));
    }
    if (in.bad()) return absl::DataLossError(absl::StrCat(path, ": read failed"));
    return contents;
  }
  std::ostringstream contents;
  contents << in.rdbuf();
  // rdbuf() insertion sets failbit on an empty file; only badbit means an I/O error.
  if (in.bad()) return absl::DataLossError(absl::StrCat(path, ": read failed"));
  return contents.str();
}

absl::Status WriteStringToFile(const std::string& path, absl::string_view contents) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) {
    return absl::PermissionDeniedError(
        absl::StrCat(path, ": cannot create file (", std::strerror(errno), ")"));
  }
  out.write(contents.data(), static_cast<std::streamsize>(contents.size()));
  out.close();
  if (!out) return absl::DataLossError(absl::StrCat(path, ": write failed"));
  return absl::OkStatus();
}

}  // namespace meshseek
