#include "common/geometry/mesh_io.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <utility>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "common/base/file_io.h"
#include "common/base/status_macros.h"
#include "common/geometry/mesh_readers.h"
#include "common/geometry/text_cursor.h"

namespace meshseek {
namespace {

using mesh_readers::PolygonSoup;

absl::Status Named(absl::string_view name, const absl::Status& status) {
  return absl::Status(status.code(), absl::StrCat(name, ": ", status.message()));
}

// The one conversion every reader's soup goes through (see mesh_io.h for the
// repairs), so that MeshReadReport means the same for every format.
absl::Status BuildTriangleMesh(PolygonSoup* soup, TriangleMesh* mesh, MeshReadReport* report) {
  report->file_vertices = soup->positions.size();
  report->file_faces = soup->face_ends.size();
  for (std::size_t v = 0; v < soup->positions.size(); ++v) {
    const Vec3f& p = soup->positions[v];
    if (!IsFinite(p)) {
      return absl::InvalidArgumentError(absl::StrCat(
          "vertex ", v, " has a non-finite coordinate (", p.x, ", ", p.y, ", ", p.z, ")"));
    }
  }
  mesh->vertices = std::move(soup->positions);
  const int64_t nv = static_cast<int64_t>(mesh->vertices.size());
  mesh->triangles.reserve(soup->triangles);
  std::vector<uint32_t> polygon;
  uint64_t begin = 0;
  for (std::size_t f = 0; f < soup->face_ends.size(); ++f) {
    const uint64_t end = soup->face_ends[f];
    for (uint64_t c = begin; c < end; ++c) {
      const int64_t index = soup->corners[c];
      if (index < 0 || index >= nv) {
        return absl::InvalidArgumentError(absl::StrCat("face ",
                                                       f,
                                                       " (0-based) references vertex ",
                                                       index,
                                                       ", but the file has ",
                                                       nv,
                                                       " vertices"));
      }
    }
    const int64_t* corners = soup->corners.data() + begin;
    const uint64_t n = end - begin;
    begin = end;
    if (n == 3 && corners[0] != corners[1] && corners[1] != corners[2] &&
        corners[2] != corners[0]) {
      mesh->triangles.push_back({static_cast<uint32_t>(corners[0]),
                                 static_cast<uint32_t>(corners[1]),
                                 static_cast<uint32_t>(corners[2])});
      continue;
    }
    // Remove corners equal to their predecessor (cyclically), then fan.
    polygon.clear();
    for (uint64_t k = 0; k < n; ++k) {
      const uint32_t index = static_cast<uint32_t>(corners[k]);
      if (polygon.empty() || polygon.back() != index) polygon.push_back(index);
    }
    while (polygon.size() > 1 && polygon.front() == polygon.back()) polygon.pop_back();
    if (polygon.size() < 3) {
      ++report->faces_dropped;
      continue;
    }
    if (polygon.size() != n) ++report->faces_repaired;
    if (polygon.size() > 3) ++report->polygons_triangulated;
    for (std::size_t k = 1; k + 1 < polygon.size(); ++k) {
      mesh->triangles.push_back({polygon[0], polygon[k], polygon[k + 1]});
    }
  }
  for (std::size_t t = 0; t < mesh->triangles.size(); ++t) {
    if (!(TriangleArea(*mesh, t) > 0)) ++report->zero_area_triangles;
  }
  report->topology = ComputeTopologyStats(*mesh);
  return ValidateMesh(*mesh);
}

bool IsObjKeyword(absl::string_view token) {
  for (const char* keyword :
       {"v", "vn", "vt", "vp", "f", "o", "g", "s", "usemtl", "mtllib", "l", "p"}) {
    if (token == keyword) return true;
  }
  return false;
}

}  // namespace

absl::Status MeshReadOptions::Validate() const {
  constexpr uint64_t kMaxIndexable = UINT32_MAX;
  if (max_file_bytes == 0) {
    return absl::InvalidArgumentError("MeshReadOptions.max_file_bytes = 0: must be positive");
  }
  if (max_vertices == 0 || max_vertices > kMaxIndexable) {
    return absl::InvalidArgumentError(absl::StrCat(
        "MeshReadOptions.max_vertices = ", max_vertices, ": must be in [1, ", kMaxIndexable, "]"));
  }
  if (max_triangles == 0 || max_triangles > kMaxIndexable) {
    return absl::InvalidArgumentError(absl::StrCat("MeshReadOptions.max_triangles = ",
                                                   max_triangles,
                                                   ": must be in [1, ",
                                                   kMaxIndexable,
                                                   "]"));
  }
  return absl::OkStatus();
}

absl::StatusOr<MeshFormat> MeshFormatFromPath(absl::string_view path) {
  const std::size_t dot = path.rfind('.');
  const std::string ext =
      dot == absl::string_view::npos ? "" : absl::AsciiStrToLower(path.substr(dot + 1));
  if (ext == "off") return MeshFormat::kOff;
  if (ext == "obj") return MeshFormat::kObj;
  if (ext == "ply") return MeshFormat::kPly;
  if (ext == "stl") return MeshFormat::kStl;
  return absl::InvalidArgumentError(
      absl::StrCat(path, ": unknown mesh format '", ext, "' (expected .off, .obj, .ply or .stl)"));
}

const char* MeshFormatName(MeshFormat format) {
  switch (format) {
    case MeshFormat::kOff:
      return "OFF";
    case MeshFormat::kObj:
      return "OBJ";
    case MeshFormat::kPly:
      return "PLY";
    case MeshFormat::kStl:
      return "STL";
  }
  return "?";
}

std::string MeshReadReport::Summary() const {
  std::vector<std::string> parts;
  parts.push_back(absl::StrCat(file_vertices, " vertices, ", file_faces, " faces"));
  parts.push_back(
      absl::StrCat(topology.components, " component", topology.components == 1 ? "" : "s"));
  if (polygons_triangulated)
    parts.push_back(absl::StrCat(polygons_triangulated, " polygons triangulated"));
  if (faces_repaired)
    parts.push_back(absl::StrCat(faces_repaired, " faces with repeated corners repaired"));
  if (faces_dropped)
    parts.push_back(absl::StrCat(faces_dropped, " faces dropped (< 3 distinct corners)"));
  if (zero_area_triangles)
    parts.push_back(absl::StrCat(zero_area_triangles, " zero-area triangles"));
  if (topology.boundary_edges)
    parts.push_back(absl::StrCat(topology.boundary_edges, " boundary edges"));
  if (topology.non_manifold_edges)
    parts.push_back(absl::StrCat(topology.non_manifold_edges, " non-manifold edges"));
  if (topology.unreferenced_vertices)
    parts.push_back(absl::StrCat(topology.unreferenced_vertices, " unreferenced vertices"));
  for (const std::string& note : notes) parts.push_back(note);
  return absl::StrJoin(parts, ", ");
}

std::optional<MeshFormat> DetectMeshFormat(absl::string_view bytes) {
  // Text magic first: a binary OFF or PLY body could, by chance, make the file
  // size match a binary STL's; a binary STL header that starts with "OFF" or
  // "ply" and a newline is not a real risk.
  mesh_readers::LineCursor lines(bytes);
  absl::string_view line, token;
  if (lines.Next(&line) && absl::StripAsciiWhitespace(line) == "ply") return MeshFormat::kPly;
  lines = mesh_readers::LineCursor(bytes);
  while (lines.Next(&line)) {
    mesh_readers::TokenCursor tokens(mesh_readers::StripComment(line, '#'));
    if (!tokens.Next(&token)) continue;
    mesh_readers::OffKeyword keyword;
    if (mesh_readers::ParseOffKeyword(token, &keyword)) return MeshFormat::kOff;
    break;  // `token`: the first statement's keyword, for OBJ below
  }
  if (mesh_readers::HasBinaryStlSize(bytes) || mesh_readers::LooksLikeAsciiStl(bytes)) {
    return MeshFormat::kStl;
  }
  if (!token.empty() && IsObjKeyword(token)) return MeshFormat::kObj;
  return std::nullopt;
}

absl::StatusOr<TriangleMesh> ParseMesh(absl::string_view bytes,
                                       absl::string_view name,
                                       std::optional<MeshFormat> declared,
                                       const MeshReadOptions& options,
                                       MeshReadReport* report) {
  if (const absl::Status valid = options.Validate(); !valid.ok()) return Named(name, valid);
  if (bytes.size() > options.max_file_bytes) {
    return absl::ResourceExhaustedError(absl::StrCat(name,
                                                     ": ",
                                                     bytes.size(),
                                                     " bytes, more than max_file_bytes (",
                                                     options.max_file_bytes,
                                                     ")"));
  }
  if (bytes.empty()) return absl::InvalidArgumentError(absl::StrCat(name, ": file is empty"));
  MeshReadReport local;
  MeshReadReport& rep = report ? *report : local;
  rep = MeshReadReport();
  const std::optional<MeshFormat> content = DetectMeshFormat(bytes);
  if (!content && !declared) {
    return absl::InvalidArgumentError(absl::StrCat(
        name, ": unknown mesh format (the content is not recognisably OFF, OBJ, PLY or STL)"));
  }
  rep.format = content ? *content : *declared;
  if (content && declared && *content != *declared) {
    rep.notes.push_back(absl::StrCat("content is ",
                                     MeshFormatName(*content),
                                     " although the name says ",
                                     MeshFormatName(*declared)));
  } else if (content && !declared) {
    rep.notes.push_back(absl::StrCat("content is ", MeshFormatName(*content)));
  }
  PolygonSoup soup;
  absl::Status read;
  switch (rep.format) {
    case MeshFormat::kOff:
      read = mesh_readers::ReadOff(bytes, options, &soup);
      break;
    case MeshFormat::kObj:
      read = mesh_readers::ReadObj(bytes, options, &soup);
      break;
    case MeshFormat::kPly:
      read = mesh_readers::ReadPly(bytes, options, &soup);
      break;
    case MeshFormat::kStl:
      read = mesh_readers::ReadStl(bytes, options, &soup);
      break;
  }
  if (!read.ok()) return Named(name, read);
  for (std::string& note : soup.notes) rep.notes.push_back(std::move(note));
  TriangleMesh mesh;
  const absl::Status built = BuildTriangleMesh(&soup, &mesh, &rep);
  if (!built.ok()) return Named(name, built);
  return mesh;
}

absl::StatusOr<TriangleMesh> ReadMesh(const std::string& path,
                                      MeshReadReport* report,
                                      const MeshReadOptions& options) {
  if (const absl::Status valid = options.Validate(); !valid.ok()) return Named(path, valid);
  const absl::StatusOr<MeshFormat> by_name = MeshFormatFromPath(path);
  std::error_code error;
  const uint64_t size = std::filesystem::file_size(path, error);
  if (!error && size > options.max_file_bytes) {
    return absl::ResourceExhaustedError(absl::StrCat(
        path, ": ", size, " bytes, more than max_file_bytes (", options.max_file_bytes, ")"));
  }
  // (file_size fails for what is not a regular file; ReadFileToString then
  // says why: not found, or a folder.)
  MESHSEEK_ASSIGN_OR_RETURN(const std::string bytes, ReadFileToString(path));
  if (!by_name.ok() && !DetectMeshFormat(bytes)) return by_name.status();
  return ParseMesh(bytes,
                   path,
                   by_name.ok() ? std::optional<MeshFormat>(*by_name) : std::nullopt,
                   options,
                   report);
}

namespace {

template <typename T>
void PutLe(std::ostream& out, T value) {
  static_assert(sizeof(T) == 4 || sizeof(T) == 2 || sizeof(T) == 1);
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  // meshseek targets little-endian hosts (x86-64, aarch64); keep bytes as is.
  out.write(bytes, sizeof(T));
}

void WriteOff(std::ostream& out, const TriangleMesh& mesh, bool binary) {
  if (binary) {
    out << "OFF BINARY\n";
    PutLe<uint32_t>(out, static_cast<uint32_t>(mesh.vertices.size()));
    PutLe<uint32_t>(out, static_cast<uint32_t>(mesh.triangles.size()));
    PutLe<uint32_t>(out, 0);
    for (const Vec3f& p : mesh.vertices) {
      PutLe(out, p.x);
      PutLe(out, p.y);
      PutLe(out, p.z);
    }
    for (const Triangle& t : mesh.triangles) {
      PutLe<uint32_t>(out, 3);
      for (uint32_t v : t) PutLe<uint32_t>(out, v);
    }
    return;
  }
  out << "OFF\n" << mesh.vertices.size() << ' ' << mesh.triangles.size() << " 0\n";
  for (const Vec3f& p : mesh.vertices) out << p.x << ' ' << p.y << ' ' << p.z << '\n';
  for (const Triangle& t : mesh.triangles)
    out << "3 " << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
}

void WriteObj(std::ostream& out, const TriangleMesh& mesh) {
  out << "# written by meshseek\n";
  for (const Vec3f& p : mesh.vertices) out << "v " << p.x << ' ' << p.y << ' ' << p.z << '\n';
  for (const Triangle& t : mesh.triangles) {
    out << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
  }
}

void WritePly(std::ostream& out, const TriangleMesh& mesh, bool binary) {
  out << "ply\nformat " << (binary ? "binary_little_endian" : "ascii") << " 1.0\n"
      << "comment written by meshseek\n"
      << "element vertex " << mesh.vertices.size() << "\n"
      << "property float x\nproperty float y\nproperty float z\n"
      << "element face " << mesh.triangles.size() << "\n"
      << "property list uchar int vertex_indices\nend_header\n";
  for (const Vec3f& p : mesh.vertices) {
    if (binary) {
      PutLe(out, p.x);
      PutLe(out, p.y);
      PutLe(out, p.z);
    } else {
      out << p.x << ' ' << p.y << ' ' << p.z << '\n';
    }
  }
  for (const Triangle& t : mesh.triangles) {
    if (binary) {
      PutLe<uint8_t>(out, 3);
      for (uint32_t v : t) PutLe<int32_t>(out, static_cast<int32_t>(v));
    } else {
      out << "3 " << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
    }
  }
}

void WriteStl(std::ostream& out, const TriangleMesh& mesh, bool binary) {
  if (binary) {
    std::string header = "meshseek binary STL";
    header.resize(80, ' ');
    out.write(header.data(), 80);
    PutLe<uint32_t>(out, static_cast<uint32_t>(mesh.triangles.size()));
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
      const Vec3f n(TriangleNormal(mesh, t));
      PutLe(out, n.x);
      PutLe(out, n.y);
      PutLe(out, n.z);
      for (uint32_t v : mesh.triangles[t]) {
        const Vec3f& p = mesh.vertices[v];
        PutLe(out, p.x);
        PutLe(out, p.y);
        PutLe(out, p.z);
      }
      PutLe<uint16_t>(out, 0);
    }
    return;
  }
  out << "solid meshseek\n";
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Vec3d n = TriangleNormal(mesh, t);
    out << "facet normal " << n.x << ' ' << n.y << ' ' << n.z << "\nouter loop\n";
    for (uint32_t v : mesh.triangles[t]) {
      const Vec3f& p = mesh.vertices[v];
      out << "vertex " << p.x << ' ' << p.y << ' ' << p.z << '\n';
    }
    out << "endloop\nendfacet\n";
  }
  out << "endsolid meshseek\n";
}

}  // namespace

absl::Status WriteMesh(const std::string& path,
                       const TriangleMesh& mesh,
                       const MeshWriteOptions& options) {
  MESHSEEK_ASSIGN_OR_RETURN(const MeshFormat format, MeshFormatFromPath(path));
  std::ofstream out(path, std::ios::binary);
  if (!out) {
    return absl::PermissionDeniedError(
        absl::StrCat(path, ": cannot create file (", std::strerror(errno), ")"));
  }
  out.precision(9);  // float round-trip
  switch (format) {
    case MeshFormat::kOff:
      WriteOff(out, mesh, options.binary);
      break;
    case MeshFormat::kObj:
      WriteObj(out, mesh);
      break;
    case MeshFormat::kPly:
      WritePly(out, mesh, options.binary);
      break;
    case MeshFormat::kStl:
      WriteStl(out, mesh, options.binary);
      break;
  }
  out.flush();
  if (!out) return absl::DataLossError(absl::StrCat(path, ": write failed"));
  return absl::OkStatus();
}

}  // namespace meshseek
