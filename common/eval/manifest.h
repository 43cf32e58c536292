// Data-set manifests: the CSV list of models (id, class, mesh file) that every
// meshseek data set in data/ carries (docs/design.md 3.1).
//
//   id,class,path
//   m1298,F117,db/12/m1298/m1298.off
//
// The order of the rows is the order of the models everywhere downstream (the
// rows and columns of the distance matrix), so readers keep it exactly.
//
// Accepted input, deliberately lenient where spreadsheets and editors differ
// and strict where a mistake would silently change the benchmark:
//   - the first non-blank line is the header; it must name the columns `id`,
//     `class` and `path` (any order, each once); other columns are ignored;
//   - CRLF line ends, a UTF-8 byte-order mark and blank lines are tolerated;
//   - a field may be double-quoted ("a,b" or "say ""x"""), and spaces around a
//     field are removed; quoted fields cannot span lines;
//   - every row has as many fields as the header; id, class and path are
//     non-empty; ids are unique.
// A class named "-1" is misc (kMiscClass in class_file.h): such models stay in
// the database but are never queries.
#ifndef MESHSEEK_COMMON_EVAL_MANIFEST_H_
#define MESHSEEK_COMMON_EVAL_MANIFEST_H_

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace meshseek {

// One model of a data set.
struct ManifestEntry {
  std::string id;     // unique model id, e.g. "m1298"
  std::string label;  // class name (the `class` column); "-1" is misc
  // Mesh file. ReadManifest resolves a relative path against the manifest's
  // folder (absolute paths are kept); WriteManifest writes it as given.
  std::string path;
  int line = 0;  // 1-based line in the manifest it was read from (0: not read from a file)
};

// Largest manifest ReadManifest reads: a million models take about 50 MB, and
// the limit keeps a wrong path (a mesh archive, /dev/zero) from filling memory.
inline constexpr uint64_t kMaxManifestBytes = uint64_t{256} << 20;

// Reads the manifest at `path`, rows in file order.
// Errors (each message starts with "<path>:<line>: " and quotes the bad value):
//   NotFound         the file cannot be opened;
//   ResourceExhausted the file is larger than kMaxManifestBytes;
//   InvalidArgument  no header, a header without id/class/path or with a
//                    repeated column, a row with the wrong number of fields, an
//                    unterminated quote, an empty id/class/path, a duplicate id
//                    (naming both lines), no rows at all.
absl::StatusOr<std::vector<ManifestEntry>> ReadManifest(const std::string& path);

// The same from the manifest's text held in memory: `path` names it in errors
// and its folder resolves relative paths, as in ReadManifest.
absl::StatusOr<std::vector<ManifestEntry>> ParseManifest(absl::string_view text,
                                                         const std::string& path);

// Writes `entries` as "id,class,path" rows (LF line ends) with each path as
// given; fields holding a comma, a quote or outer spaces are quoted, so that
// ReadManifest reads the same strings back.
// Errors: InvalidArgument for an entry ReadManifest would reject (empty field,
// a line break in a field, duplicate id; the message names the entry index),
// PermissionDenied when the file cannot be created, DataLoss when writing fails.
absl::Status WriteManifest(const std::string& path, const std::vector<ManifestEntry>& entries);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_EVAL_MANIFEST_H_
