// Base64 (RFC 4648, section 4: the standard alphabet with '=' padding), for
// embedding binary data in text: the evaluation report's thumbnails become
// data: URIs, so that the report is one file that opens anywhere.
#ifndef MESHSEEK_COMMON_BASE_BASE64_H_
#define MESHSEEK_COMMON_BASE_BASE64_H_

#include <string>

#include "absl/strings/string_view.h"

namespace meshseek {

/// `bytes` in base64, padded to a multiple of 4 characters, no line breaks
/// (data: URIs must not have any).
std::string Base64Encode(absl::string_view bytes);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_BASE_BASE64_H_
