// Princeton Shape Benchmark class files ("PSB 1" format, docs/design.md 3.1), the
// ground truth that the PSB tools and tools/psb_eval.py read:
//
//   PSB 1
//   <numClasses> <numModels>
//
//   <name> <parent or 0> <count>
//   <model id>          (count lines)
//   ...
//
// Classes with 0 models are nodes of the hierarchy (e.g. "aircraft 0 0", then
// "airplane aircraft 0"); a parent is declared before its children. A model
// belongs to the class whose block lists it, and that class is its label for
// retrieval. The order of the ids through the file is the row/column order of
// the distance matrix. A class named "-1" is misc: its models stay in the
// database but are never queries.
#ifndef MESHSEEK_COMMON_EVAL_CLASS_FILE_H_
#define MESHSEEK_COMMON_EVAL_CLASS_FILE_H_

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace meshseek {

// Name of the misc class, whose models are never queries (psbTable's rule).
inline constexpr char kMiscClass[] = "-1";
// The parent written for a top-level class.
inline constexpr char kNoParent[] = "0";

struct ClassFile {
  struct Class {
    std::string name;    // unique, no whitespace; "-1" is misc
    std::string parent;  // name of a class declared earlier, or "0" (kNoParent) for none
    std::vector<std::string> model_ids;  // in file order; empty for hierarchy nodes
  };
  std::vector<Class> classes;  // in file order, parents before children

  // Flattened views, one entry per model in file order (= distance-matrix
  // order): the model id and the name of the class that lists it.
  std::vector<std::string> model_ids;
  std::vector<std::string> labels;
};

// Largest class file ReadPsbClassFile reads (a million models take about
// 10 MB); a wrong path cannot fill memory.
inline constexpr uint64_t kMaxClassFileBytes = uint64_t{256} << 20;

// Reads a "PSB 1" class file. Whitespace separates tokens, blank lines are
// skipped and CRLF line ends are tolerated; otherwise the layout must be as
// above, one class header or one model id per line.
// Errors (messages start with "<path>:<line>: " and quote the bad value):
//   NotFound         the file cannot be opened;
//   ResourceExhausted the file is larger than kMaxClassFileBytes;
//   InvalidArgument  a first line other than "PSB 1"; a bad counts line; a
//                    bad class header (not 3 tokens, count not a non-negative
//                    integer, name "0", name declared twice, parent not
//                    declared before); a model line that is not one token; a
//                    model id listed twice (naming both lines); fewer classes
//                    or models than the header says (truncated file), or
//                    content after the last class.
absl::StatusOr<ClassFile> ReadPsbClassFile(const std::string& path);
// The same from the file's text held in memory; `path` names it in errors.
absl::StatusOr<ClassFile> ParsePsbClassFile(absl::string_view text, const std::string& path);

// Writes `class_file` in "PSB 1" format from `classes` (an empty parent is
// written as "0"). If `model_ids` or `labels` is non-empty it must equal the
// flattening of `classes`, so that a caller cannot believe in a matrix order
// the file does not have.
// Errors: InvalidArgument for anything ReadPsbClassFile would reject (empty
// name or id, whitespace in a name or id, class "0", duplicate class or model,
// undeclared parent) or a flattened view that disagrees, naming the class or
// model; PermissionDenied when the file cannot be created; DataLoss when
// writing fails.
absl::Status WritePsbClassFile(const std::string& path, const ClassFile& class_file);

// Builds a flat class file (every parent "0") from per-model ids and labels,
// as listed in a manifest, keeping the model order. Because a class file lists
// a class's models together, the models of each class must be contiguous;
// otherwise the file's order would differ from the manifest's.
// Errors: InvalidArgument when the sizes differ, when a class's models are not
// contiguous (naming the model index and class), or for an empty label.
absl::StatusOr<ClassFile> MakeFlatClassFile(const std::vector<std::string>& model_ids,
                                            const std::vector<std::string>& labels);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_EVAL_CLASS_FILE_H_
