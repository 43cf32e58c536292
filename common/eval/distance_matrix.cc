#include "common/eval/distance_matrix.h"

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>

#include "absl/strings/str_cat.h"
#include "common/base/file_io.h"
#include "common/base/status_macros.h"

namespace meshseek {
namespace {

// n*n entries, or an error when that many floats cannot be addressed.
absl::StatusOr<std::size_t> EntryCount(const std::string& path, std::size_t n) {
  if (n != 0 && n > std::numeric_limits<std::size_t>::max() / sizeof(float) / n) {
    return absl::InvalidArgumentError(
        absl::StrCat(path, ": a ", n, " x ", n, " matrix is too large"));
  }
  return n * n;
}

absl::Status NanError(const std::string& path, std::size_t index, std::size_t n) {
  return absl::InvalidArgumentError(
      absl::StrCat(path, ": NaN at row ", index / n, ", column ", index % n));
}

}  // namespace

absl::Status WriteDistanceMatrix(const std::string& path,
                                 const std::vector<float>& matrix,
                                 std::size_t n) {
  MESHSEEK_ASSIGN_OR_RETURN(const std::size_t count, EntryCount(path, n));
  if (matrix.size() != count) {
    return absl::InvalidArgumentError(absl::StrCat(path,
                                                   ": got ",
                                                   matrix.size(),
                                                   " distances for a ",
                                                   n,
                                                   " x ",
                                                   n,
                                                   " matrix (expected ",
                                                   count,
                                                   ")"));
  }
  std::string bytes(count * sizeof(float), '\0');
  for (std::size_t i = 0; i < count; ++i) {
    if (std::isnan(matrix[i])) return NanError(path, i, n);
    uint32_t bits;
    std::memcpy(&bits, &matrix[i], sizeof(bits));
    for (int b = 0; b < 4; ++b) bytes[4 * i + b] = static_cast<char>((bits >> (8 * b)) & 0xFF);
  }
  return WriteStringToFile(path, bytes);
}

absl::StatusOr<std::vector<float>> ReadDistanceMatrix(const std::string& path, std::size_t n) {
  MESHSEEK_ASSIGN_OR_RETURN(const std::size_t count, EntryCount(path, n));
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) {
    return absl::NotFoundError(
        absl::StrCat(path, ": cannot open file (", std::strerror(errno), ")"));
  }
  // Check the size before reading, so that a wrong file is not read whole.
  const std::streamoff size = in.tellg();
  if (size < 0) {
    return absl::InvalidArgumentError(absl::StrCat(path, ": not a regular file"));
  }
  if (static_cast<std::size_t>(size) != count * sizeof(float)) {
    return absl::InvalidArgumentError(absl::StrCat(path,
                                                   ": expected ",
                                                   n,
                                                   " x ",
                                                   n,
                                                   " float32 = ",
                                                   count * sizeof(float),
                                                   " bytes, file has ",
                                                   size,
                                                   " bytes"));
  }
  in.seekg(0);
  std::string bytes(count * sizeof(float), '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!in) return absl::DataLossError(absl::StrCat(path, ": read failed"));
  std::vector<float> matrix(count);
  for (std::size_t i = 0; i < count; ++i) {
    uint32_t bits = 0;
    for (int b = 0; b < 4; ++b) {
      bits |= static_cast<uint32_t>(static_cast<unsigned char>(bytes[4 * i + b])) << (8 * b);
    }
    std::memcpy(&matrix[i], &bits, sizeof(bits));
    if (std::isnan(matrix[i])) return NanError(path, i, n);
  }
  return matrix;
}

}  // namespace meshseek
