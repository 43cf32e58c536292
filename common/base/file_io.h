// Whole-file reads and writes with errors that name the file.
#ifndef MESHSEEK_COMMON_BASE_FILE_IO_H_
#define MESHSEEK_COMMON_BASE_FILE_IO_H_

#include <cstdint>
#include <limits>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace meshseek {

// The bytes of the file at `path`. NotFound ("<path>: cannot open file (<why>)")
// when it cannot be opened, InvalidArgument when it is a folder,
// ResourceExhausted ("<path>: N bytes, more than the limit of M") when it is
// larger than `max_bytes` (checked before anything is read, so that a huge or
// endless file cannot exhaust memory), DataLoss when reading fails part-way.
absl::StatusOr<std::string> ReadFileToString(
    const std::string& path, uint64_t max_bytes = std::numeric_limits<uint64_t>::max());

// Replaces the file at `path` with `contents`. PermissionDenied when it cannot
// be created, DataLoss when writing fails (disk full).
absl::Status WriteStringToFile(const std::string& path, absl::string_view contents);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_BASE_FILE_IO_H_
