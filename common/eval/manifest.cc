#include "common/eval/manifest.h"

#include <cstddef>
#include <filesystem>
#include <unordered_map>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/string_view.h"
#include "common/base/file_io.h"
#include "common/base/status_macros.h"

namespace meshseek {
namespace {

constexpr absl::string_view kUtf8Bom = "\xEF\xBB\xBF";

bool IsBlank(char c) { return c == ' ' || c == '\t'; }

// Splits one CSV line into fields (see manifest.h for the dialect). Errors
// carry no location; the caller adds it.
absl::StatusOr<std::vector<std::string>> SplitCsvLine(absl::string_view line) {
  std::vector<std::string> fields;
  std::size_t i = 0;
  const std::size_t n = line.size();
  while (true) {
    while (i < n && IsBlank(line[i])) ++i;
    std::string field;
    if (i < n && line[i] == '"') {
      const std::size_t open = i++;
      bool closed = false;
      while (i < n) {
        if (line[i] == '"') {
          if (i + 1 < n && line[i + 1] == '"') {
            field.push_back('"');
            i += 2;
            continue;
          }
          ++i;
          closed = true;
          break;
        }
        field.push_back(line[i++]);
      }
      if (!closed) {
        return absl::InvalidArgumentError(
            absl::StrCat("unterminated quoted field starting at column ", open + 1));
      }
      while (i < n && IsBlank(line[i])) ++i;
      if (i < n && line[i] != ',') {
        return absl::InvalidArgumentError(absl::StrCat(
            "unexpected '", line.substr(i, 1), "' after quoted field at column ", i + 1));
      }
    } else {
      std::size_t end = line.find(',', i);
      if (end == absl::string_view::npos) end = n;
      const absl::string_view raw = absl::StripTrailingAsciiWhitespace(line.substr(i, end - i));
      // A stray quote usually means a mangled quoted field; reading it
      // literally would silently change an id or a path.
      if (absl::StrContains(raw, '"')) {
        return absl::InvalidArgumentError(
            absl::StrCat("quote inside unquoted field '",
                         raw,
                         "' (quote the whole field, doubling inner quotes)"));
      }
      field = std::string(raw);
      i = end;
    }
    fields.push_back(std::move(field));
    if (i >= n) break;
    ++i;  // the comma
  }
  return fields;
}

std::string QuoteCsvField(const std::string& field) {
  const bool needs_quotes = field.find_first_of(",\"") != std::string::npos ||
                            IsBlank(field.front()) || IsBlank(field.back());
  if (!needs_quotes) return field;
  std::string quoted = "\"";
  for (const char c : field) {
    if (c == '"') quoted.push_back('"');
    quoted.push_back(c);
  }
  quoted.push_back('"');
  return quoted;
}

}  // namespace

absl::StatusOr<std::vector<ManifestEntry>> ReadManifest(const std::string& path) {
  MESHSEEK_ASSIGN_OR_RETURN(const std::string text, ReadFileToString(path, kMaxManifestBytes));
  return ParseManifest(text, path);
}

absl::StatusOr<std::vector<ManifestEntry>> ParseManifest(absl::string_view text,
                                                         const std::string& path) {
  absl::string_view contents = text;
  absl::ConsumePrefix(&contents, kUtf8Bom);
  const std::string folder = std::filesystem::path(path).parent_path().string();

  auto error = [&path](int line, absl::string_view message) {
    return absl::InvalidArgumentError(absl::StrCat(path, ":", line, ": ", message));
  };

  std::vector<ManifestEntry> entries;
  std::unordered_map<std::string, int> line_of_id;
  int id_col = -1, class_col = -1, path_col = -1;
  std::size_t num_columns = 0;
  int line_no = 0;
  int header_line = 0;
  for (absl::string_view line : absl::StrSplit(contents, '\n')) {
    ++line_no;
    absl::ConsumeSuffix(&line, "\r");
    if (absl::StripAsciiWhitespace(line).empty()) continue;
    auto fields_or = SplitCsvLine(line);
    if (!fields_or.ok()) return error(line_no, fields_or.status().message());
    std::vector<std::string>& fields = *fields_or;

    if (num_columns == 0) {  // the header
      for (std::size_t c = 0; c < fields.size(); ++c) {
        const std::string name = absl::AsciiStrToLower(fields[c]);
        int* col = nullptr;
        if (name == "id") col = &id_col;
        if (name == "class") col = &class_col;
        if (name == "path") col = &path_col;
        if (col == nullptr) continue;
        if (*col >= 0) return error(line_no, absl::StrCat("column '", name, "' appears twice"));
        *col = static_cast<int>(c);
      }
      if (id_col < 0 || class_col < 0 || path_col < 0) {
        return error(line_no,
                     absl::StrCat("header '", line, "' must name the columns id, class and path"));
      }
      num_columns = fields.size();
      header_line = line_no;
      continue;
    }

    if (fields.size() != num_columns) {
      return error(line_no,
                   absl::StrCat("expected ",
                                num_columns,
                                " fields as in the header, got ",
                                fields.size(),
                                " in '",
                                line,
                                "'"));
    }
    ManifestEntry entry;
    entry.id = std::move(fields[id_col]);
    entry.label = std::move(fields[class_col]);
    entry.line = line_no;
    const std::string& file = fields[path_col];
    if (entry.id.empty()) return error(line_no, "empty id");
    if (entry.label.empty()) {
      return error(line_no, absl::StrCat("empty class for id '", entry.id, "'"));
    }
    if (file.empty()) return error(line_no, absl::StrCat("empty path for id '", entry.id, "'"));
    const auto [it, inserted] = line_of_id.emplace(entry.id, line_no);
    if (!inserted) {
      return error(line_no,
                   absl::StrCat("duplicate id '", entry.id, "' (first on line ", it->second, ")"));
    }
    entry.path = folder.empty() || std::filesystem::path(file).is_absolute()
                     ? file
                     : (std::filesystem::path(folder) / file).string();
    entries.push_back(std::move(entry));
  }
  if (num_columns == 0) {
    return absl::InvalidArgumentError(
        absl::StrCat(path, ":1: no header (expected a line naming the columns id,class,path)"));
  }
  if (entries.empty()) return error(header_line, "header but no models");
  return entries;
}

absl::Status WriteManifest(const std::string& path, const std::vector<ManifestEntry>& entries) {
  std::string text = "id,class,path\n";
  std::unordered_map<std::string, std::size_t> index_of_id;
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const ManifestEntry& e = entries[i];
    for (const std::string* field : {&e.id, &e.label, &e.path}) {
      if (field->empty() || field->find_first_of("\r\n") != std::string::npos) {
        return absl::InvalidArgumentError(
            absl::StrCat(path,
                         ": entry ",
                         i,
                         " (id '",
                         e.id,
                         "', class '",
                         e.label,
                         "', path '",
                         e.path,
                         "') has an empty field or a line break in a field"));
      }
    }
    const auto [it, inserted] = index_of_id.emplace(e.id, i);
    if (!inserted) {
      return absl::InvalidArgumentError(absl::StrCat(
          path, ": entries ", it->second, " and ", i, " have the same id '", e.id, "'"));
    }
    absl::StrAppend(
        &text, QuoteCsvField(e.id), ",", QuoteCsvField(e.label), ",", QuoteCsvField(e.path), "\n");
  }
  return WriteStringToFile(path, text);
}

}  // namespace meshseek
