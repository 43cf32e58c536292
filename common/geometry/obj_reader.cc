// Wavefront OBJ, geometry only: "v x y z [w] [r g b]" and "f c1 c2 c3 ...",
// a corner being "i", "i/t", "i/t/n" or "i//n" with 1-based indices or
// negative ones counted back from the latest vertex. Everything else (vt, vn,
// vp, g, o, s, usemtl, mtllib, l, p, curves, unknown keywords) is skipped.
// '#' starts a comment; a line ending in '\' continues on the next one.
#include <charconv>
#include <string>

#include "absl/strings/str_cat.h"
#include "common/base/status_macros.h"
#include "common/geometry/mesh_readers.h"
#include "common/geometry/text_cursor.h"

namespace meshseek::mesh_readers {
namespace {

// One statement (a line, or lines joined by '\' continuations).
absl::Status ReadStatement(absl::string_view line,
                           std::size_t line_number,
                           const MeshReadOptions& options,
                           PolygonSoup* soup) {
  TokenCursor tokens(StripComment(line, '#'));
  absl::string_view keyword, token;
  if (!tokens.Next(&keyword)) return absl::OkStatus();
  if (keyword == "v") {
    float p[3];
    for (float& c : p) {
      const NumberParse parsed = tokens.NextFloat(&c, &token);
      if (parsed != NumberParse::kOk) return CoordinateError(line_number, parsed, token);
    }
    if (soup->positions.size() >= options.max_vertices) {
      return VertexLimitError(
          absl::StrCat("line ", line_number), soup->positions.size() + 1, options);
    }
    soup->positions.emplace_back(p[0], p[1], p[2]);
    return absl::OkStatus();
  }
  if (keyword != "f" && keyword != "fo") return absl::OkStatus();  // "fo": old name of "f"
  const int64_t defined = static_cast<int64_t>(soup->positions.size());
  while (tokens.Next(&token)) {
    int64_t index = 0;
    const char* end = token.data() + token.size();
    const char* first = token.data() + (token[0] == '+' ? 1 : 0);
    const std::from_chars_result parsed = std::from_chars(first, end, index);
    if (parsed.ec != std::errc() || (parsed.ptr != end && *parsed.ptr != '/')) {
      return LineError(line_number,
                       absl::StrCat("expected a face corner (i, i/t, i/t/n or i//n), found ",
                                    QuoteToken(token)));
    }
    if (index == 0) {
      return LineError(line_number,
                       absl::StrCat("vertex index 0 in ",
                                    QuoteToken(token),
                                    " (OBJ indices start at 1; negative ones count back)"));
    }
    // Relative indices refer to the vertices defined so far; absolute ones
    // may refer forward (checked once the whole file is read).
    soup->corners.push_back(index > 0 ? index - 1 : defined + index);
  }
  if (!soup->EndFace(options.max_triangles)) {
    return TriangleLimitError(absl::StrCat("line ", line_number), soup->triangles, options);
  }
  return absl::OkStatus();
}

}  // namespace

absl::Status ReadObj(absl::string_view bytes, const MeshReadOptions& options, PolygonSoup* soup) {
  // No header counts: memory grows with what is read, bounded by the limits
  // (and, in total, by the bytes: every vertex or corner takes some).
  LineCursor lines(bytes);
  absl::string_view line;
  std::string joined;
  while (lines.Next(&line)) {
    const std::size_t line_number = lines.line_number();
    if (!line.empty() && line.back() == '\\') {
      joined.assign(line.data(), line.size() - 1);
      for (;;) {
        absl::string_view next;
        if (!lines.Next(&next)) break;
        joined.push_back(' ');
        if (!next.empty() && next.back() == '\\') {
          joined.append(next.data(), next.size() - 1);
        } else {
          joined.append(next.data(), next.size());
          break;
        }
      }
      line = joined;
    }
    MESHSEEK_RETURN_IF_ERROR(ReadStatement(line, line_number, options, soup));
  }
  return absl::OkStatus();
}

}  // namespace meshseek::mesh_readers
