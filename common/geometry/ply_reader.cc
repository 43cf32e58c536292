// PLY (Turk's polygon file format, as in Bourke's description): a text header
// of elements and their properties, then the records in ascii,
// binary_little_endian or binary_big_endian. meshseek takes x y z from the
// "vertex" element (any scalar type, among any other properties, in any
// order) and the corner list "vertex_indices" (or "vertex_index") from the
// "face" element; every other property and element is skipped by its size.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "common/base/status_macros.h"
#include "common/geometry/mesh_readers.h"
#include "common/geometry/text_cursor.h"

namespace meshseek::mesh_readers {
namespace {

constexpr double kFloatMax = std::numeric_limits<float>::max();

enum class Scalar { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

bool ParseScalar(absl::string_view name, Scalar* type) {
  // Two names per type, in Scalar's order: PLY's original one and the sized one.
  TokenCursor names(
      "char int8 uchar uint8 short int16 ushort uint16 int int32 uint uint32 float float32 "
      "double float64");
  absl::string_view candidate;
  for (int i = 0; names.Next(&candidate); ++i) {
    if (candidate == name) {
      *type = static_cast<Scalar>(i / 2);
      return true;
    }
  }
  return false;
}

int SizeOf(Scalar type) {
  static constexpr int kBytes[] = {1, 1, 2, 2, 4, 4, 4, 8};  // in Scalar's order
  return kBytes[static_cast<int>(type)];
}

bool IsInteger(Scalar type) { return type != Scalar::kFloat32 && type != Scalar::kFloat64; }

double LoadAsDouble(const char* p, Scalar type, bool be) {
  switch (type) {
    case Scalar::kInt8:
      return ByteCursor::Load<int8_t>(p, be);
    case Scalar::kUint8:
      return ByteCursor::Load<uint8_t>(p, be);
    case Scalar::kInt16:
      return ByteCursor::Load<int16_t>(p, be);
    case Scalar::kUint16:
      return ByteCursor::Load<uint16_t>(p, be);
    case Scalar::kInt32:
      return ByteCursor::Load<int32_t>(p, be);
    case Scalar::kUint32:
      return ByteCursor::Load<uint32_t>(p, be);
    case Scalar::kFloat32:
      return ByteCursor::Load<float>(p, be);
    case Scalar::kFloat64:
      return ByteCursor::Load<double>(p, be);
  }
  return 0;
}

// Integer types only (checked when the header is read).
int64_t LoadAsInt64(const char* p, Scalar type, bool be) {
  return static_cast<int64_t>(LoadAsDouble(p, type, be));
}

struct Property {
  std::string name;
  Scalar type = Scalar::kFloat32;  // a scalar's type, or a list's item type
  bool is_list = false;
  Scalar count_type = Scalar::kUint8;  // lists only
};

// What meshseek takes from an element's records.
enum class Role { kSkip, kVertex, kFace };

struct Element {
  std::string name;
  uint64_t count = 0;
  std::vector<Property> properties;
  Role role = Role::kSkip;
  int xyz[3] = {-1, -1, -1};  // vertex: property index of x, y, z
  int corners = -1;           // face: property index of the corner list
  std::size_t line = 0;       // header line of the element, for errors

  // Bytes a record takes at least: a binary record its scalars and list
  // counts; an ascii one a digit and a separator per value.
  uint64_t MinRecordBytes(bool binary) const {
    uint64_t bytes = 0;
    for (const Property& p : properties) {
      bytes += binary ? SizeOf(p.is_list ? p.count_type : p.type) : 2;
    }
    return bytes;
  }
  // 0, 1 or 2 if property p is the vertex's x, y or z; else -1.
  int AxisOf(std::size_t p) const {
    for (int k = 0; k < 3 && role == Role::kVertex; ++k) {
      if (static_cast<int>(p) == xyz[k]) return k;
    }
    return -1;
  }
  bool HasLists() const {
    return std::any_of(
        properties.begin(), properties.end(), [](const Property& p) { return p.is_list; });
  }
};

struct Header {
  enum Encoding { kNone, kAscii, kLittleEndian, kBigEndian } encoding = kNone;
  std::vector<Element> elements;
  std::size_t body_offset = 0;
  std::size_t body_line = 0;
};

// Decides what meshseek takes from `element` and checks those properties.
absl::Status AssignRole(Element* element) {
  if (element->name == "vertex") {
    element->role = Role::kVertex;
    for (int k = 0; k < 3; ++k) {
      const char* axis = k == 0 ? "x" : (k == 1 ? "y" : "z");
      for (std::size_t p = 0; p < element->properties.size(); ++p) {
        if (element->properties[p].name == axis) element->xyz[k] = static_cast<int>(p);
      }
      if (element->xyz[k] < 0 || element->properties[element->xyz[k]].is_list) {
        return LineError(element->line,
                         absl::StrCat("element vertex has no scalar property ", axis));
      }
    }
  } else if (element->name == "face") {
    element->role = Role::kFace;
    for (std::size_t p = 0; p < element->properties.size() && element->corners < 0; ++p) {
      const Property& property = element->properties[p];
      if (property.name == "vertex_indices" || property.name == "vertex_index") {
        if (!property.is_list || !IsInteger(property.type)) {
          return LineError(
              element->line,
              absl::StrCat("face property ", property.name, " is not a list of integers"));
        }
        element->corners = static_cast<int>(p);
      }
    }
    if (element->corners < 0) {
      return LineError(element->line, "element face has no vertex_indices list");
    }
  }
  return absl::OkStatus();
}

absl::Status ReadHeader(absl::string_view bytes, Header* header) {
  LineCursor lines(bytes);
  absl::string_view line, keyword, token;
  if (!lines.Next(&line) || absl::StripAsciiWhitespace(line) != "ply") {
    return LineError(1, "expected the PLY magic 'ply'");
  }
  while (lines.Next(&line)) {
    const std::size_t n = lines.line_number();
    TokenCursor tokens(line);
    if (!tokens.Next(&keyword) || keyword == "comment" || keyword == "obj_info") continue;
    if (keyword == "end_header") {
      if (header->encoding == Header::kNone) return LineError(n, "the header has no format line");
      header->body_offset = lines.offset();
      header->body_line = n + 1;
      for (Element& element : header->elements) MESHSEEK_RETURN_IF_ERROR(AssignRole(&element));
      return absl::OkStatus();
    }
    if (keyword == "format") {
      tokens.Next(&token);
      if (token == "ascii") {
        header->encoding = Header::kAscii;
      } else if (token == "binary_little_endian") {
        header->encoding = Header::kLittleEndian;
      } else if (token == "binary_big_endian") {
        header->encoding = Header::kBigEndian;
      } else {
        return LineError(n, absl::StrCat("unknown PLY format ", QuoteToken(token)));
      }
    } else if (keyword == "element") {
      Element element;
      absl::string_view name;
      int64_t count = -1;
      if (!tokens.Next(&name) || tokens.NextInt64(&count, &token) != NumberParse::kOk ||
          count < 0) {
        return LineError(n, "expected 'element <name> <count>'");
      }
      element.name = std::string(name);
      element.count = static_cast<uint64_t>(count);
      element.line = n;
      header->elements.push_back(std::move(element));
    } else if (keyword == "property") {
      if (header->elements.empty()) return LineError(n, "property before any element");
      Property property;
      bool typed = tokens.Next(&token);
      if (typed && token == "list") {
        property.is_list = true;
        typed = tokens.Next(&token) && ParseScalar(token, &property.count_type) &&
                IsInteger(property.count_type) && tokens.Next(&token);
      }
      if (!typed || !ParseScalar(token, &property.type) || !tokens.Next(&token)) {
        return LineError(n,
                         absl::StrCat("expected 'property <type> <name>' or 'property list "
                                      "<integer type> <type> <name>', found ",
                                      QuoteToken(line)));
      }
      property.name = std::string(token);
      header->elements.back().properties.push_back(std::move(property));
    } else {
      return LineError(n, absl::StrCat("unexpected ", QuoteToken(keyword), " in the PLY header"));
    }
  }
  return LineError(lines.line_number(), "the PLY header has no end_header line");
}

absl::Status ReadAsciiBody(absl::string_view bytes,
                           const Header& header,
                           const MeshReadOptions& options,
                           PolygonSoup* soup) {
  LineCursor lines(bytes.substr(header.body_offset), header.body_line);
  absl::string_view line, token;
  for (const Element& element : header.elements) {
    if (element.properties.empty()) continue;  // records of nothing take no lines
    for (uint64_t r = 0; r < element.count; ++r) {
      do {
        if (!lines.Next(&line)) {
          return LineError(lines.line_number(),
                           absl::StrCat("the file ends after ",
                                        r,
                                        " of the ",
                                        element.count,
                                        " declared ",
                                        element.name,
                                        " records"));
        }
      } while (TokenCursor(line).Done());
      const std::size_t n = lines.line_number();
      TokenCursor tokens(line);
      float xyz[3] = {0, 0, 0};
      for (std::size_t p = 0; p < element.properties.size(); ++p) {
        const Property& property = element.properties[p];
        int64_t items = 1;
        if (property.is_list) {
          if (tokens.NextInt64(&items, &token) != NumberParse::kOk || items < 0) {
            return LineError(n,
                             absl::StrCat("expected the item count of list ",
                                          property.name,
                                          ", found ",
                                          QuoteToken(token)));
          }
        }
        const bool is_corners =
            element.role == Role::kFace && static_cast<int>(p) == element.corners;
        const int axis = element.AxisOf(p);
        for (int64_t i = 0; i < items; ++i) {
          NumberParse parsed = NumberParse::kOk;
          if (axis >= 0 && property.type == Scalar::kFloat32) {
            parsed = tokens.NextFloat(&xyz[axis], &token);
          } else if (axis >= 0 && property.type == Scalar::kFloat64) {
            double value = 0;
            parsed = tokens.NextDouble(&value, &token);
            if (parsed == NumberParse::kOk && !(std::abs(value) <= kFloatMax)) {
              parsed = NumberParse::kNonFinite;  // beyond float, as meshes are stored
            }
            xyz[axis] = static_cast<float>(value);
          } else if (axis >= 0 || is_corners) {
            int64_t value = 0;
            parsed = tokens.NextInt64(&value, &token);
            if (axis >= 0) xyz[axis] = static_cast<float>(value);
            if (is_corners) soup->corners.push_back(value);
          } else if (!tokens.Next(&token)) {
            parsed = NumberParse::kMissing;
          }
          if (parsed == NumberParse::kMissing) {
            return LineError(
                n,
                absl::StrCat(
                    element.name, " record ", r, " ends before its property ", property.name));
          }
          if (parsed != NumberParse::kOk) {
            if (axis >= 0) return CoordinateError(n, parsed, token);
            return LineError(
                n,
                absl::StrCat(
                    "expected an integer for ", property.name, ", found ", QuoteToken(token)));
          }
        }
      }
      if (!tokens.Done()) {
        return LineError(n,
                         absl::StrCat("unexpected ",
                                      QuoteToken(tokens.Rest()),
                                      " after the ",
                                      element.properties.size(),
                                      " properties of element ",
                                      element.name));
      }
      if (element.role == Role::kVertex) {
        if (soup->positions.size() >= options.max_vertices) {
          return VertexLimitError(absl::StrCat("line ", n), soup->positions.size() + 1, options);
        }
        soup->positions.emplace_back(xyz[0], xyz[1], xyz[2]);
      } else if (element.role == Role::kFace && !soup->EndFace(options.max_triangles)) {
        return TriangleLimitError(absl::StrCat("line ", n), soup->triangles, options);
      }
    }
  }
  while (lines.Next(&line)) {
    if (!TokenCursor(line).Done()) {
      return LineError(
          lines.line_number(),
          absl::StrCat(
              "unexpected ", QuoteToken(TokenCursor(line).Rest()), " after the last element"));
    }
  }
  return absl::OkStatus();
}

absl::Status ReadBinaryBody(absl::string_view bytes,
                            const Header& header,
                            const MeshReadOptions& options,
                            PolygonSoup* soup) {
  const bool be = header.encoding == Header::kBigEndian;
  ByteCursor in(bytes, header.body_offset, be);
  for (const Element& element : header.elements) {
    const uint64_t fixed = element.MinRecordBytes(/*binary=*/true);
    auto truncated = [&element](uint64_t r, std::size_t record_start) {
      return ByteError(
          record_start,
          absl::StrCat(
              "the file ends inside ", element.name, " record ", r, " (of ", element.count, ")"));
    };
    if (!element.HasLists() && element.role != Role::kVertex) {
      // Counts were checked against the bytes present, but not every element
      // before this one had a fixed size.
      if (!in.Has(SaturatingMul(element.count, fixed))) {
        return ByteError(in.offset(), absl::StrCat("the file ends inside element ", element.name));
      }
      in.Skip(element.count * fixed);
      continue;
    }
    for (uint64_t r = 0; r < element.count; ++r) {
      const std::size_t record_start = in.offset();
      float xyz[3] = {0, 0, 0};
      for (std::size_t p = 0; p < element.properties.size(); ++p) {
        const Property& property = element.properties[p];
        uint64_t items = 1;
        if (property.is_list) {
          const int count_size = SizeOf(property.count_type);
          if (!in.Has(count_size)) return truncated(r, record_start);
          const int64_t count = LoadAsInt64(in.here(), property.count_type, be);
          if (count < 0) {
            return ByteError(
                in.offset(),
                absl::StrCat(
                    element.name, " ", r, ": list ", property.name, " has ", count, " items"));
          }
          in.Skip(count_size);
          items = static_cast<uint64_t>(count);
        }
        const int item_size = SizeOf(property.type);
        if (!in.Has(SaturatingMul(items, item_size))) return truncated(r, record_start);
        if (element.role == Role::kFace && static_cast<int>(p) == element.corners) {
          for (uint64_t i = 0; i < items; ++i) {
            soup->corners.push_back(LoadAsInt64(in.here(), property.type, be));
            in.Skip(item_size);
          }
          continue;
        }
        if (const int axis = element.AxisOf(p); axis >= 0) {
          xyz[axis] = property.type == Scalar::kFloat32
                          ? ByteCursor::Load<float>(in.here(), be)
                          : static_cast<float>(LoadAsDouble(in.here(), property.type, be));
        }
        in.Skip(items * item_size);
      }
      if (element.role == Role::kVertex) {
        if (soup->positions.size() >= options.max_vertices) {
          return VertexLimitError(
              absl::StrCat("byte ", record_start), soup->positions.size() + 1, options);
        }
        soup->positions.emplace_back(xyz[0], xyz[1], xyz[2]);
      } else if (element.role == Role::kFace && !soup->EndFace(options.max_triangles)) {
        return TriangleLimitError(absl::StrCat("byte ", record_start), soup->triangles, options);
      }
    }
  }
  if (in.remaining() > 0) {
    soup->notes.push_back(absl::StrCat(in.remaining(), " bytes after the last element ignored"));
  }
  return absl::OkStatus();
}

}  // namespace

absl::Status ReadPly(absl::string_view bytes, const MeshReadOptions& options, PolygonSoup* soup) {
  Header header;
  MESHSEEK_RETURN_IF_ERROR(ReadHeader(bytes, &header));
  const bool binary = header.encoding != Header::kAscii;
  const uint64_t available = bytes.size() - header.body_offset;
  uint64_t needed = 0, vertices = 0, faces = 0;
  std::vector<std::string> declared;
  for (const Element& element : header.elements) {
    needed = SaturatingAdd(needed, SaturatingMul(element.count, element.MinRecordBytes(binary)));
    declared.push_back(absl::StrCat(element.count, " ", element.name));
    if (element.role == Role::kVertex) vertices = SaturatingAdd(vertices, element.count);
    if (element.role == Role::kFace) faces = SaturatingAdd(faces, element.count);
  }
  if (!binary && needed > 0 && needed < UINT64_MAX) --needed;  // the last line needs no newline
  MESHSEEK_RETURN_IF_ERROR(CheckDeclaredSize(
      absl::StrCat(absl::StrJoin(declared, ", "), " records"), needed, available));
  if (vertices > options.max_vertices) return VertexLimitError("header", vertices, options);
  // Faces counted as triangles of at least 8 bytes (binary: a count and three
  // 16-bit indices; ascii "3 a b c\n"), so that a header cannot make the
  // reader reserve more than a few times the file's size.
  soup->positions.reserve(vertices);
  soup->face_ends.reserve(std::min<uint64_t>(faces, available / 8));
  return binary ? ReadBinaryBody(bytes, header, options, soup)
                : ReadAsciiBody(bytes, header, options, soup);
}

}  // namespace meshseek::mesh_readers
