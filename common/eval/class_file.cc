#include "common/eval/class_file.h"

#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <unordered_set>

#include "absl/strings/ascii.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "absl/strings/string_view.h"
#include "common/base/file_io.h"
#include "common/base/status_macros.h"

namespace meshseek {
namespace {

// Hands out the non-blank lines of a text one at a time, split into tokens,
// remembering line numbers for error messages.
class TokenLines {
 public:
  explicit TokenLines(absl::string_view text) : lines_(absl::StrSplit(text, '\n')) {}

  // Advances to the next non-blank line; false at the end of the text.
  bool Next() {
    while (next_ < lines_.size()) {
      line_ = absl::StripAsciiWhitespace(lines_[next_++]);  // also drops a CR
      if (line_.empty()) continue;
      tokens_ = absl::StrSplit(line_, absl::ByAnyChar(" \t\r\v\f"), absl::SkipEmpty());
      line_no_ = static_cast<int>(next_);
      return true;
    }
    return false;
  }

  // Current line's number (1-based); after the end, the last non-blank line's.
  int line_no() const { return line_no_; }
  absl::string_view line() const { return line_; }
  const std::vector<absl::string_view>& tokens() const { return tokens_; }

 private:
  std::vector<absl::string_view> lines_;
  std::size_t next_ = 0;
  int line_no_ = 1;
  absl::string_view line_;
  std::vector<absl::string_view> tokens_;
};

bool ParseCount(absl::string_view token, int64_t* count) {
  return absl::ascii_isdigit(token.front()) && absl::SimpleAtoi(token, count) && *count >= 0;
}

bool IsToken(const std::string& s) {
  if (s.empty()) return false;
  for (const char c : s) {
    if (absl::ascii_isspace(static_cast<unsigned char>(c))) return false;
  }
  return true;
}

}  // namespace

absl::StatusOr<ClassFile> ReadPsbClassFile(const std::string& path) {
  MESHSEEK_ASSIGN_OR_RETURN(const std::string text, ReadFileToString(path, kMaxClassFileBytes));
  return ParsePsbClassFile(text, path);
}

absl::StatusOr<ClassFile> ParsePsbClassFile(absl::string_view text, const std::string& path) {
  TokenLines in(text);
  auto error = [&path, &in](absl::string_view message) {
    return absl::InvalidArgumentError(absl::StrCat(path, ":", in.line_no(), ": ", message));
  };

  if (!in.Next()) return error("empty file (expected 'PSB 1')");
  if (in.tokens().size() != 2 || in.tokens()[0] != "PSB" || in.tokens()[1] != "1") {
    return error(absl::StrCat("expected 'PSB 1', got '", in.line(), "'"));
  }
  if (!in.Next()) return error("file ends after 'PSB 1' (expected '<numClasses> <numModels>')");
  int64_t num_classes = 0, num_models = 0;
  if (in.tokens().size() != 2 || !ParseCount(in.tokens()[0], &num_classes) ||
      !ParseCount(in.tokens()[1], &num_models)) {
    return error(absl::StrCat("expected '<numClasses> <numModels>', got '", in.line(), "'"));
  }
  const int counts_line = in.line_no();

  ClassFile file;
  std::unordered_map<std::string, int> line_of_class;
  std::unordered_map<std::string, int> line_of_model;
  for (int64_t c = 0; c < num_classes; ++c) {
    if (!in.Next()) {
      return error(absl::StrCat(
          "file ends after ", c, " classes; line ", counts_line, " declares ", num_classes));
    }
    const std::vector<absl::string_view>& tok = in.tokens();
    int64_t count = 0;
    if (tok.size() != 3 || !ParseCount(tok[2], &count)) {
      std::string hint;
      if (tok.size() == 1 && !file.classes.empty()) {
        hint = absl::StrCat(
            " (does class '", file.classes.back().name, "' list more models than its count?)");
      }
      return error(absl::StrCat("expected class header '<name> <parent> <count>' for class ",
                                c + 1,
                                " of ",
                                num_classes,
                                ", got '",
                                in.line(),
                                "'",
                                hint));
    }
    ClassFile::Class cls;
    cls.name = std::string(tok[0]);
    cls.parent = std::string(tok[1]);
    if (cls.name == kNoParent) {
      return error("class name '0' is reserved (it means 'no parent')");
    }
    const auto [it, inserted] = line_of_class.emplace(cls.name, in.line_no());
    if (!inserted) {
      return error(absl::StrCat("class '", cls.name, "' already declared on line ", it->second));
    }
    if (cls.parent != kNoParent && line_of_class.count(cls.parent) == 0) {
      return error(absl::StrCat(
          "parent '", cls.parent, "' of class '", cls.name, "' is not declared before it"));
    }
    const int class_line = in.line_no();
    for (int64_t m = 0; m < count; ++m) {
      if (!in.Next()) {
        return error(absl::StrCat("file ends inside class '",
                                  cls.name,
                                  "' (line ",
                                  class_line,
                                  "), which declares ",
                                  count,
                                  " models, after ",
                                  m));
      }
      if (in.tokens().size() != 1) {
        return error(absl::StrCat("expected model id ",
                                  m + 1,
                                  " of ",
                                  count,
                                  " of class '",
                                  cls.name,
                                  "' (line ",
                                  class_line,
                                  "), got '",
                                  in.line(),
                                  "'"));
      }
      std::string id(in.tokens()[0]);
      const auto [mit, fresh] = line_of_model.emplace(id, in.line_no());
      if (!fresh) {
        return error(absl::StrCat("model id '", id, "' already listed on line ", mit->second));
      }
      file.model_ids.push_back(id);
      file.labels.push_back(cls.name);
      cls.model_ids.push_back(std::move(id));
    }
    file.classes.push_back(std::move(cls));
  }
  if (in.Next()) {
    return error(absl::StrCat("unexpected '",
                              in.line(),
                              "' after the ",
                              num_classes,
                              " classes declared on line ",
                              counts_line));
  }
  if (static_cast<int64_t>(file.model_ids.size()) != num_models) {
    return absl::InvalidArgumentError(absl::StrCat(path,
                                                   ":",
                                                   counts_line,
                                                   ": header declares ",
                                                   num_models,
                                                   " models, the classes list ",
                                                   file.model_ids.size()));
  }
  return file;
}

absl::Status WritePsbClassFile(const std::string& path, const ClassFile& class_file) {
  auto error = [&path](absl::string_view message) {
    return absl::InvalidArgumentError(absl::StrCat(path, ": ", message));
  };
  std::size_t num_models = 0;
  for (const ClassFile::Class& cls : class_file.classes) num_models += cls.model_ids.size();
  if ((!class_file.model_ids.empty() && class_file.model_ids.size() != num_models) ||
      (!class_file.labels.empty() && class_file.labels.size() != num_models)) {
    return error(absl::StrCat("the classes list ",
                              num_models,
                              " models but model_ids has ",
                              class_file.model_ids.size(),
                              " and labels ",
                              class_file.labels.size()));
  }

  std::string text = absl::StrCat("PSB 1\n", class_file.classes.size(), " ", num_models, "\n");
  std::unordered_set<std::string> classes_so_far;
  std::unordered_set<std::string> models_so_far;
  std::size_t k = 0;  // index into the flattened views
  for (std::size_t c = 0; c < class_file.classes.size(); ++c) {
    const ClassFile::Class& cls = class_file.classes[c];
    const std::string parent = cls.parent.empty() ? kNoParent : cls.parent;
    if (!IsToken(cls.name) || cls.name == kNoParent) {
      return error(absl::StrCat("class ",
                                c,
                                " has the invalid name '",
                                cls.name,
                                "' (empty, whitespace, or the reserved '0')"));
    }
    if (!IsToken(parent)) {
      return error(absl::StrCat("class '", cls.name, "' has the invalid parent '", parent, "'"));
    }
    if (parent != kNoParent && classes_so_far.count(parent) == 0) {
      return error(absl::StrCat(
          "parent '", parent, "' of class '", cls.name, "' is not a class declared before it"));
    }
    if (!classes_so_far.insert(cls.name).second) {
      return error(absl::StrCat("class '", cls.name, "' appears twice"));
    }
    absl::StrAppend(&text, "\n", cls.name, " ", parent, " ", cls.model_ids.size(), "\n");
    for (const std::string& id : cls.model_ids) {
      if (!IsToken(id)) {
        return error(absl::StrCat("class '", cls.name, "' has the invalid model id '", id, "'"));
      }
      if (!models_so_far.insert(id).second) {
        return error(absl::StrCat("model id '", id, "' appears twice"));
      }
      if ((!class_file.model_ids.empty() && class_file.model_ids[k] != id) ||
          (!class_file.labels.empty() && class_file.labels[k] != cls.name)) {
        return error(absl::StrCat("model ",
                                  k,
                                  " is '",
                                  id,
                                  "' of class '",
                                  cls.name,
                                  "' in the class list but '",
                                  class_file.model_ids.empty() ? id : class_file.model_ids[k],
                                  "' of class '",
                                  class_file.labels.empty() ? cls.name : class_file.labels[k],
                                  "' in model_ids/labels"));
      }
      absl::StrAppend(&text, id, "\n");
      ++k;
    }
  }
  return WriteStringToFile(path, text);
}

absl::StatusOr<ClassFile> MakeFlatClassFile(const std::vector<std::string>& model_ids,
                                            const std::vector<std::string>& labels) {
  if (model_ids.size() != labels.size()) {
    return absl::InvalidArgumentError(
        absl::StrCat("got ", model_ids.size(), " model ids and ", labels.size(), " labels"));
  }
  ClassFile file;
  std::unordered_map<std::string, std::size_t> class_index;
  for (std::size_t i = 0; i < labels.size(); ++i) {
    if (labels[i].empty()) {
      return absl::InvalidArgumentError(
          absl::StrCat("model ", i, " ('", model_ids[i], "') has an empty label"));
    }
    const auto [it, inserted] = class_index.emplace(labels[i], file.classes.size());
    if (inserted) {
      file.classes.push_back({labels[i], kNoParent, {}});
    } else if (it->second + 1 != file.classes.size()) {
      return absl::InvalidArgumentError(absl::StrCat(
          "model ",
          i,
          " ('",
          model_ids[i],
          "') of class '",
          labels[i],
          "' is separated from the earlier models of its class; a class file would reorder it"));
    }
    file.classes.back().model_ids.push_back(model_ids[i]);
  }
  file.model_ids = model_ids;
  file.labels = labels;
  return file;
}

}  // namespace meshseek
