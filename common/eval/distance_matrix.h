// Distance matrices in the Princeton Shape Benchmark's binary format
// (docs/design.md 3.1): N x N little-endian float32, row-major, entry i*N+j = the
// distance from model i (the query) to model j, smaller meaning more similar,
// in class-file / manifest order. No header: N comes from the class file.
// Emitting exactly this lets anyone's evaluator (psbTable, tools/psb_eval.py)
// check meshseek's results.
#ifndef MESHSEEK_COMMON_EVAL_DISTANCE_MATRIX_H_
#define MESHSEEK_COMMON_EVAL_DISTANCE_MATRIX_H_

#include <cstddef>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

namespace meshseek {

// Writes the n x n row-major `matrix` to `path`, little-endian whatever the
// host. Infinities are allowed (an unreachable model ranks last); NaN is not,
// since no evaluator can rank it.
// Errors: InvalidArgument when matrix.size() != n*n (both sizes named) or for a
// NaN (naming its row and column); PermissionDenied when the file cannot be
// created; DataLoss when writing fails.
absl::Status WriteDistanceMatrix(const std::string& path,
                                 const std::vector<float>& matrix,
                                 std::size_t n);

// Reads an n x n matrix written as above.
// Errors: NotFound when the file cannot be opened; DataLoss when reading
// fails; InvalidArgument when its
// size is not 4*n*n bytes ("<path>: expected 100 x 100 float32 = 40000 bytes,
// file has 39996 bytes") or when an entry is NaN ("<path>: NaN at row 3,
// column 7", 0-based).
absl::StatusOr<std::vector<float>> ReadDistanceMatrix(const std::string& path, std::size_t n);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_EVAL_DISTANCE_MATRIX_H_
