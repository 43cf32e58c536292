// STL, binary (an 80-byte header, a uint32 triangle count, then per triangle
// a normal, three corners as little-endian float32 and a 2-byte attribute) and
// ASCII (solid / facet normal / outer loop / vertex / endloop / endfacet /
// endsolid). STL stores every triangle's corners by value; equal positions are
// merged into one vertex (exact float equality, -0 = +0, as OpenMesh's STL
// reader did), numbered in the order first seen, so that a closed surface
// reads back connected. Normals are ignored.
#include <array>
#include <cstring>

#include "absl/container/flat_hash_map.h"
#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "common/base/status_macros.h"
#include "common/geometry/mesh_readers.h"
#include "common/geometry/text_cursor.h"

namespace meshseek::mesh_readers {
namespace {

constexpr std::size_t kHeaderBytes = 84;
constexpr std::size_t kTriangleBytes = 50;

class VertexMerger {
 public:
  VertexMerger(const MeshReadOptions& options, PolygonSoup* soup)
      : options_(options), soup_(soup) {}

  // Appends the corner at `p` to the current polygon; false when a new vertex
  // would exceed max_vertices.
  bool AddCorner(const Vec3f& p) {
    std::array<uint32_t, 3> key;
    const float normalised[3] = {p.x + 0.0f, p.y + 0.0f, p.z + 0.0f};  // -0 -> +0
    std::memcpy(key.data(), normalised, sizeof(key));
    const auto [it, inserted] =
        index_.try_emplace(key, static_cast<uint32_t>(soup_->positions.size()));
    if (inserted) {
      if (soup_->positions.size() >= options_.max_vertices) return false;
      soup_->positions.push_back(p);
    }
    soup_->corners.push_back(it->second);
    return true;
  }

 private:
  const MeshReadOptions& options_;
  PolygonSoup* soup_;
  absl::flat_hash_map<std::array<uint32_t, 3>, uint32_t> index_;
};

absl::Status ReadBinary(absl::string_view bytes,
                        const MeshReadOptions& options,
                        PolygonSoup* soup) {
  if (bytes.size() < kHeaderBytes) {
    return ByteError(bytes.size(), "the file ends inside the 84-byte binary STL header");
  }
  const uint64_t triangles = ByteCursor::Load<uint32_t>(bytes.data() + 80, false);
  const uint64_t available = bytes.size() - kHeaderBytes;
  MESHSEEK_RETURN_IF_ERROR(CheckDeclaredSize(
      absl::StrCat(triangles, " triangles"), triangles * kTriangleBytes, available));
  if (triangles > options.max_triangles) {
    return TriangleLimitError("header", triangles, options);
  }
  soup->corners.reserve(3 * triangles);
  soup->face_ends.reserve(triangles);
  VertexMerger merger(options, soup);
  for (uint64_t t = 0; t < triangles; ++t) {
    const std::size_t offset = kHeaderBytes + t * kTriangleBytes;
    for (int k = 0; k < 3; ++k) {
      const char* p = bytes.data() + offset + 12 * (k + 1);
      const Vec3f corner(ByteCursor::Load<float>(p, false),
                         ByteCursor::Load<float>(p + 4, false),
                         ByteCursor::Load<float>(p + 8, false));
      if (!IsFinite(corner)) {
        return ByteError(offset,
                         absl::StrCat("triangle ",
                                      t,
                                      " has a non-finite coordinate (",
                                      corner.x,
                                      ", ",
                                      corner.y,
                                      ", ",
                                      corner.z,
                                      ")"));
      }
      if (!merger.AddCorner(corner)) {
        return VertexLimitError(absl::StrCat("byte ", offset), soup->positions.size() + 1, options);
      }
    }
    soup->EndFace(options.max_triangles);
  }
  if (const uint64_t extra = available - triangles * kTriangleBytes; extra > 0) {
    soup->notes.push_back(absl::StrCat(extra, " bytes after the STL triangles ignored"));
  }
  return absl::OkStatus();
}

absl::Status ReadAscii(absl::string_view bytes, const MeshReadOptions& options, PolygonSoup* soup) {
  LineCursor lines(bytes);
  absl::string_view line, keyword, token;
  VertexMerger merger(options, soup);
  bool in_facet = false;
  while (lines.Next(&line)) {
    const std::size_t n = lines.line_number();
    TokenCursor tokens(line);
    if (!tokens.Next(&keyword)) continue;
    if (keyword == "vertex") {
      if (!in_facet) return LineError(n, "vertex outside a facet");
      float p[3];
      for (float& c : p) {
        const NumberParse parsed = tokens.NextFloat(&c, &token);
        if (parsed != NumberParse::kOk) return CoordinateError(n, parsed, token);
      }
      if (!merger.AddCorner(Vec3f(p[0], p[1], p[2]))) {
        return VertexLimitError(absl::StrCat("line ", n), soup->positions.size() + 1, options);
      }
    } else if (keyword == "facet") {
      if (in_facet) return LineError(n, "facet inside a facet (missing endfacet)");
      in_facet = true;  // the normal is ignored
    } else if (keyword == "endfacet") {
      if (!in_facet) return LineError(n, "endfacet without facet");
      in_facet = false;
      if (!soup->EndFace(options.max_triangles)) {
        return TriangleLimitError(absl::StrCat("line ", n), soup->triangles, options);
      }
    } else if (keyword == "solid" || keyword == "endsolid" || keyword == "outer" ||
               keyword == "endloop") {
      if (in_facet && (keyword == "solid" || keyword == "endsolid")) {
        return LineError(n, absl::StrCat(keyword, " inside a facet (missing endfacet)"));
      }
    } else {
      return LineError(n, absl::StrCat("unexpected ", QuoteToken(keyword), " in ASCII STL"));
    }
  }
  if (in_facet) return LineError(lines.line_number(), "the file ends inside a facet");
  return absl::OkStatus();
}

bool StartsWithSolid(absl::string_view bytes) {
  const absl::string_view text = absl::StripLeadingAsciiWhitespace(bytes);
  return absl::StartsWith(text, "solid") &&
         (text.size() == 5 || absl::ascii_isspace(static_cast<unsigned char>(text[5])));
}

}  // namespace

bool HasBinaryStlSize(absl::string_view bytes) {
  if (bytes.size() < kHeaderBytes) return false;
  const uint64_t triangles = ByteCursor::Load<uint32_t>(bytes.data() + 80, false);
  return kHeaderBytes + triangles * kTriangleBytes == bytes.size();
}

bool LooksLikeAsciiStl(absl::string_view bytes) {
  if (!StartsWithSolid(bytes)) return false;
  LineCursor lines(absl::StripLeadingAsciiWhitespace(bytes));
  absl::string_view line, token;
  lines.Next(&line);  // "solid [name]"
  while (lines.Next(&line)) {
    if (TokenCursor(line).Next(&token)) return token == "facet" || token == "endsolid";
  }
  return false;
}

absl::Status ReadStl(absl::string_view bytes, const MeshReadOptions& options, PolygonSoup* soup) {
  // A binary header may begin with "solid" too; the size decides first. A
  // file that begins with "solid" and has no control bytes early on is text.
  if (HasBinaryStlSize(bytes)) return ReadBinary(bytes, options, soup);
  bool text = StartsWithSolid(bytes);
  for (std::size_t i = 0; text && i < std::min<std::size_t>(bytes.size(), 1024); ++i) {
    const unsigned char c = static_cast<unsigned char>(bytes[i]);
    text = c >= 0x20 || c == '\t' || c == '\n' || c == '\r';
  }
  return text ? ReadAscii(bytes, options, soup) : ReadBinary(bytes, options, soup);
}

}  // namespace meshseek::mesh_readers
