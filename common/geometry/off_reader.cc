// OFF, ASCII and binary, after Geomview's specification (geomview.org, "OFF
// files"): an optional keyword [ST][C][N][4][n]OFF [BINARY], then [dimension]
// vertex, face and edge counts, vertex records, and face records
// "n i1 .. in [colour]". ASCII records are one per line.
#include <algorithm>
#include <array>

#include "absl/strings/str_cat.h"
#include "absl/strings/strip.h"
#include "common/base/status_macros.h"
#include "common/geometry/mesh_readers.h"
#include "common/geometry/text_cursor.h"

namespace meshseek::mesh_readers {
namespace {

struct OffHeader {
  OffKeyword keyword;
  bool binary = false;
  uint64_t vertices = 0;
  uint64_t faces = 0;
  std::size_t body_offset = 0;  // first byte after the header
  std::size_t body_line = 1;    // number of the first line after the header (ASCII)
};

// The next line with something on it once its '#' comment is removed.
bool NextContentLine(LineCursor* lines, absl::string_view* line) {
  while (lines->Next(line)) {
    *line = StripComment(*line, '#');
    if (!TokenCursor(*line).Done()) return true;
  }
  return false;
}

absl::Status ReadHeader(absl::string_view bytes, OffHeader* header) {
  LineCursor lines(bytes);
  absl::string_view line;
  if (!NextContentLine(&lines, &line)) {
    return LineError(std::max<std::size_t>(lines.line_number(), 1),
                     "the file ends before the OFF header keyword");
  }
  TokenCursor tokens(line);
  absl::string_view keyword;
  tokens.Next(&keyword);
  if (!ParseOffKeyword(keyword, &header->keyword)) {
    // Geomview makes the keyword optional: a file may start with the counts.
    int64_t first_count = 0;
    absl::string_view token;
    if (TokenCursor(keyword).NextInt64(&first_count, &token) != NumberParse::kOk) {
      return LineError(lines.line_number(),
                       absl::StrCat("expected the OFF header keyword ([ST][C][N][4][n]OFF), found ",
                                    QuoteToken(keyword)));
    }
    tokens = TokenCursor(line);
  } else {
    const TokenCursor after_keyword = tokens;
    absl::string_view word;
    if (tokens.Next(&word) && word == "BINARY") {
      if (!tokens.Done()) {
        return LineError(lines.line_number(),
                         absl::StrCat("unexpected ", QuoteToken(tokens.Rest()), " after BINARY"));
      }
      header->binary = true;
      header->body_offset = lines.offset();  // binary data starts after the newline
      return absl::OkStatus();
    }
    tokens = after_keyword;
  }
  // The counts may follow the keyword on its line or come on the next lines.
  auto next_count = [&](absl::string_view what, uint64_t* count) -> absl::Status {
    if (tokens.Done()) {
      if (!NextContentLine(&lines, &line)) {
        return LineError(lines.line_number(), absl::StrCat("the file ends before the ", what));
      }
      tokens = TokenCursor(line);
    }
    int64_t value = 0;
    absl::string_view token;
    if (tokens.NextInt64(&value, &token) != NumberParse::kOk || value < 0) {
      return LineError(lines.line_number(),
                       absl::StrCat("expected the ", what, ", found ", QuoteToken(token)));
    }
    *count = static_cast<uint64_t>(value);
    return absl::OkStatus();
  };
  if (header->keyword.dimension) {
    uint64_t dimension = 0;
    MESHSEEK_RETURN_IF_ERROR(next_count("dimension", &dimension));
    if (dimension != 3) {
      return LineError(lines.line_number(),
                       absl::StrCat("nOFF dimension ", dimension, ": only 3-D meshes are read"));
    }
  }
  MESHSEEK_RETURN_IF_ERROR(next_count("vertex count", &header->vertices));
  MESHSEEK_RETURN_IF_ERROR(next_count("face count", &header->faces));
  if (!tokens.Done()) {  // the edge count: optional, and unused
    uint64_t edges = 0;
    MESHSEEK_RETURN_IF_ERROR(next_count("edge count", &edges));
    if (!tokens.Done()) {
      return LineError(lines.line_number(),
                       absl::StrCat("unexpected ", QuoteToken(tokens.Rest()), " after the counts"));
    }
  }
  header->body_offset = lines.offset();
  header->body_line = lines.line_number() + 1;
  return absl::OkStatus();
}

absl::Status ReadAsciiBody(absl::string_view bytes,
                           const OffHeader& header,
                           const MeshReadOptions& options,
                           PolygonSoup* soup) {
  const uint64_t nv = header.vertices, nf = header.faces;
  const int coordinates = header.keyword.homogeneous ? 4 : 3;
  const absl::string_view body = bytes.substr(header.body_offset);
  // A vertex line holds at least its one-digit coordinates, each followed by
  // a space or the newline; a face line at least its corner count and newline.
  // The last line needs no newline.
  const uint64_t needed = SaturatingAdd(SaturatingMul(nv, 2 * coordinates), SaturatingMul(nf, 2));
  MESHSEEK_RETURN_IF_ERROR(
      CheckDeclaredSize(absl::StrCat(nv, " vertices and ", nf, " faces"),
                        needed == 0 || needed == UINT64_MAX ? needed : needed - 1,
                        body.size()));
  if (nv > options.max_vertices) return VertexLimitError("header", nv, options);
  // Reserve for the records the bytes can hold, faces counted as triangle
  // lines ("3 a b c\n", 8 bytes at least): a header cannot make the reader
  // reserve more than a few times the file's size.
  soup->positions.reserve(nv);
  soup->face_ends.reserve(std::min<uint64_t>(nf, body.size() / 8));
  soup->corners.reserve(std::min<uint64_t>(SaturatingMul(nf, 3), body.size() / 8 * 3));

  LineCursor lines(body, header.body_line);
  absl::string_view line, token;
  for (uint64_t v = 0; v < nv; ++v) {
    if (!NextContentLine(&lines, &line)) {
      return LineError(
          lines.line_number(),
          absl::StrCat("the file ends after ", v, " of the ", nv, " declared vertices"));
    }
    TokenCursor tokens(line);
    std::array<float, 4> p = {0, 0, 0, 1};
    for (int k = 0; k < coordinates; ++k) {
      const NumberParse parsed = tokens.NextFloat(&p[k], &token);
      if (parsed != NumberParse::kOk) {
        return CoordinateError(
            lines.line_number(), parsed, token, coordinates == 4 ? "x y z w" : "x y z");
      }
    }
    if (p[3] != 1) {
      if (p[3] == 0) return LineError(lines.line_number(), "homogeneous coordinate w is 0");
      p = {p[0] / p[3], p[1] / p[3], p[2] / p[3], 1};
    }
    soup->positions.emplace_back(p[0], p[1], p[2]);  // colours, normals, texcoords ignored
  }
  for (uint64_t f = 0; f < nf; ++f) {
    if (!NextContentLine(&lines, &line)) {
      return LineError(lines.line_number(),
                       absl::StrCat("the file ends after ", f, " of the ", nf, " declared faces"));
    }
    TokenCursor tokens(line);
    int64_t corners = 0;
    if (tokens.NextInt64(&corners, &token) != NumberParse::kOk || corners < 0) {
      return LineError(
          lines.line_number(),
          absl::StrCat("expected the corner count of face ", f, ", found ", QuoteToken(token)));
    }
    for (int64_t k = 0; k < corners; ++k) {
      int64_t index = 0;
      const NumberParse parsed = tokens.NextInt64(&index, &token);
      if (parsed == NumberParse::kMissing) {
        return LineError(
            lines.line_number(),
            absl::StrCat("face ", f, " declares ", corners, " corners, but the line has ", k));
      }
      if (parsed != NumberParse::kOk) {
        return LineError(
            lines.line_number(),
            absl::StrCat("face ", f, ": expected a vertex index, found ", QuoteToken(token)));
      }
      soup->corners.push_back(index);
    }
    if (!soup->EndFace(options.max_triangles)) {
      return TriangleLimitError(
          absl::StrCat("line ", lines.line_number()), soup->triangles, options);
    }
  }
  while (lines.Next(&line)) {
    TokenCursor tokens(StripComment(line, '#'));
    if (!tokens.Done()) {
      return LineError(
          lines.line_number(),
          absl::StrCat(
              "unexpected ", QuoteToken(tokens.Rest()), " after the ", nf, " declared faces"));
    }
  }
  return absl::OkStatus();
}

// Binary faces: n, n indices, and in Geomview's form a colour count (0 to 4)
// and that many values. Returns the offset after the last face.
absl::Status ReadBinaryFaces(ByteCursor in,
                             uint64_t nf,
                             bool colour_counts,
                             const MeshReadOptions& options,
                             PolygonSoup* soup,
                             std::size_t* end) {
  for (uint64_t f = 0; f < nf; ++f) {
    if (!in.Has(4)) {
      return ByteError(in.offset(),
                       absl::StrCat("the file ends after ", f, " of the ", nf, " declared faces"));
    }
    const uint32_t corners = in.Read<uint32_t>();
    if (!in.Has(SaturatingMul(corners, 4))) {
      return ByteError(in.offset() - 4,
                       absl::StrCat("face ",
                                    f,
                                    " declares ",
                                    corners,
                                    " corners, but only ",
                                    in.remaining(),
                                    " bytes follow"));
    }
    for (uint32_t k = 0; k < corners; ++k) soup->corners.push_back(in.Read<uint32_t>());
    if (!soup->EndFace(options.max_triangles)) {
      return TriangleLimitError(absl::StrCat("byte ", in.offset()), soup->triangles, options);
    }
    if (colour_counts) {
      const int32_t colours = in.Has(4) ? in.Read<int32_t>() : -1;
      if (colours < 0 || colours > 4 || !in.Has(4 * colours)) {
        return ByteError(in.offset(), absl::StrCat("face ", f, ": bad colour count"));
      }
      in.Skip(4 * colours);
    }
  }
  *end = in.offset();
  return absl::OkStatus();
}

absl::Status ReadBinaryBody(absl::string_view bytes,
                            const OffHeader& header,
                            const MeshReadOptions& options,
                            PolygonSoup* soup) {
  const OffKeyword& kw = header.keyword;
  const std::size_t start = header.body_offset;
  const std::size_t counts_bytes = kw.dimension ? 16 : 12;
  const uint64_t vertex_bytes = 4 * ((kw.homogeneous ? 4 : 3) + (kw.normals ? 3 : 0) +
                                     (kw.colours ? 4 : 0) + (kw.texcoords ? 2 : 0));
  if (bytes.size() - start < counts_bytes) {
    return ByteError(start, "the file ends inside the OFF BINARY counts");
  }
  // meshseek's (and OpenMesh's) writer uses little-endian; Geomview's own
  // form is big-endian. Take the byte order whose counts fit the file.
  const uint64_t available = bytes.size() - start - counts_bytes;
  auto read_counts = [&](bool big_endian, uint64_t* nv, uint64_t* nf) {
    const char* counts = bytes.data() + start + (kw.dimension ? 4 : 0);
    *nv = ByteCursor::Load<uint32_t>(counts, big_endian);
    *nf = ByteCursor::Load<uint32_t>(counts + 4, big_endian);
    return SaturatingAdd(SaturatingMul(*nv, vertex_bytes), SaturatingMul(*nf, 4));
  };
  uint64_t nv = 0, nf = 0;
  bool big_endian = false;
  if (const uint64_t needed = read_counts(false, &nv, &nf); needed > available) {
    uint64_t nv_be = 0, nf_be = 0;
    if (read_counts(true, &nv_be, &nf_be) > available) {
      return ByteError(
          start,
          CheckDeclaredSize(absl::StrCat(nv, " vertices and ", nf, " faces"), needed, available)
              .message());
    }
    big_endian = true;
    nv = nv_be;
    nf = nf_be;
  }
  ByteCursor in(bytes, start, big_endian);
  if (kw.dimension && in.Read<uint32_t>() != 3) {
    return ByteError(start, "nOFF dimension is not 3: only 3-D meshes are read");
  }
  in.Skip(12);
  if (big_endian) soup->notes.push_back("big-endian OFF BINARY (Geomview)");
  if (nv > options.max_vertices) return VertexLimitError("header", nv, options);
  soup->positions.reserve(nv);
  for (uint64_t v = 0; v < nv; ++v) {
    const char* p = in.here();
    float x = ByteCursor::Load<float>(p, big_endian),
          y = ByteCursor::Load<float>(p + 4, big_endian),
          z = ByteCursor::Load<float>(p + 8, big_endian);
    if (kw.homogeneous) {
      const float w = ByteCursor::Load<float>(p + 12, big_endian);
      if (w == 0) return ByteError(in.offset(), absl::StrCat("vertex ", v, ": w is 0"));
      x /= w, y /= w, z /= w;
    }
    soup->positions.emplace_back(x, y, z);
    in.Skip(vertex_bytes);
  }
  // Faces with or without Geomview's per-face colour counts: the form the
  // byte order suggests first, then the other. One that reads exactly to the
  // end of the file wins; failing that, the first form if it reads at all
  // (the bytes after it are ignored, and noted).
  soup->face_ends.reserve(std::min<uint64_t>(nf, in.remaining() / 16));  // 16: a triangle
  const bool colour_counts[2] = {big_endian, !big_endian};
  absl::Status read[2];
  std::size_t end[2] = {0, 0};
  auto read_faces = [&](int form) {
    soup->corners.clear();
    soup->face_ends.clear();
    soup->triangles = 0;
    read[form] = ReadBinaryFaces(in, nf, colour_counts[form], options, soup, &end[form]);
    return read[form].ok();
  };
  for (int form = 0; form < 2; ++form) {
    if (read_faces(form) && end[form] == bytes.size()) return absl::OkStatus();
  }
  if (read[0].ok() && read_faces(0)) {
    soup->notes.push_back(absl::StrCat(bytes.size() - end[0], " bytes after the faces ignored"));
    return absl::OkStatus();
  }
  return read[0];
}

}  // namespace

bool ParseOffKeyword(absl::string_view token, OffKeyword* keyword) {
  if (!absl::ConsumeSuffix(&token, "OFF")) return false;
  OffKeyword k;
  k.texcoords = absl::ConsumePrefix(&token, "ST");
  k.colours = absl::ConsumePrefix(&token, "C");
  k.normals = absl::ConsumePrefix(&token, "N");
  k.homogeneous = absl::ConsumePrefix(&token, "4");
  k.dimension = absl::ConsumePrefix(&token, "n");
  if (!token.empty()) return false;
  *keyword = k;
  return true;
}

absl::Status ReadOff(absl::string_view bytes, const MeshReadOptions& options, PolygonSoup* soup) {
  OffHeader header;
  MESHSEEK_RETURN_IF_ERROR(ReadHeader(bytes, &header));
  return header.binary ? ReadBinaryBody(bytes, header, options, soup)
                       : ReadAsciiBody(bytes, header, options, soup);
}

}  // namespace meshseek::mesh_readers
