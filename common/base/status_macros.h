// Status propagation helpers. Abseil 20220623 has absl::Status/StatusOr but not
// the RETURN_IF_ERROR / ASSIGN_OR_RETURN macros, so meshseek defines its own.
#ifndef MESHSEEK_COMMON_BASE_STATUS_MACROS_H_
#define MESHSEEK_COMMON_BASE_STATUS_MACROS_H_

#include <utility>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"

// Returns the status from the enclosing function if `expr` is not OK.
#define MESHSEEK_RETURN_IF_ERROR(expr)           \
  do {                                           \
    const ::absl::Status _meshseek_st = (expr);  \
    if (!_meshseek_st.ok()) return _meshseek_st; \
  } while (false)

#define MESHSEEK_STATUS_CONCAT_INNER_(a, b) a##b
#define MESHSEEK_STATUS_CONCAT_(a, b) MESHSEEK_STATUS_CONCAT_INNER_(a, b)

// `MESHSEEK_ASSIGN_OR_RETURN(auto x, F());` declares/assigns `x` from the
// StatusOr returned by F(), or returns its status from the enclosing function.
#define MESHSEEK_ASSIGN_OR_RETURN(lhs, expr) \
  MESHSEEK_ASSIGN_OR_RETURN_IMPL_(MESHSEEK_STATUS_CONCAT_(_meshseek_statusor_, __LINE__), lhs, expr)

#define MESHSEEK_ASSIGN_OR_RETURN_IMPL_(statusor, lhs, expr) \
  auto statusor = (expr);                                    \
  if (!statusor.ok()) return std::move(statusor).status();   \
  lhs = std::move(statusor).value()

namespace meshseek {

/// `status` with `prefix` before its message (same code), so an error names
/// where it happened: Prefixed(s, "model m1: "). OK stays OK.
inline absl::Status Prefixed(const absl::Status& status, absl::string_view prefix) {
  if (status.ok()) return status;
  return absl::Status(status.code(), absl::StrCat(prefix, status.message()));
}

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_BASE_STATUS_MACROS_H_
