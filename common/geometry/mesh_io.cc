#include "common/geometry/mesh_io.h"

#include <OpenMesh/Core/IO/IOManager.hh>
#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/IO/importer/BaseImporter.hh>
#include <OpenMesh/Core/System/omstream.hh>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <mutex>
#include <sstream>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "common/base/file_io.h"
#include "common/base/status_macros.h"

namespace meshseek {
namespace {

namespace OM = OpenMesh;

// Receives what an OpenMesh format reader parses, unfiltered: positions and
// raw polygons (as signed indices, so that bad ones stay visible). Everything
// else readers may hand over (normals, colours, texture coordinates) is ignored.
class SoupImporter : public OM::IO::BaseImporter {
 public:
  std::vector<Vec3f> positions;
  std::vector<int64_t> corners;         // all polygon corners, concatenated
  std::vector<std::size_t> face_start;  // polygon f: corners[face_start[f] .. face_start[f+1])

  SoupImporter() { face_start.push_back(0); }

  OM::VertexHandle add_vertex(const OM::Vec3f& p) override {
    positions.emplace_back(p[0], p[1], p[2]);
    return OM::VertexHandle(static_cast<int>(positions.size()) - 1);
  }
  OM::VertexHandle add_vertex(const OM::Vec3d& p) override {
    positions.emplace_back(
        static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2]));
    return OM::VertexHandle(static_cast<int>(positions.size()) - 1);
  }
  OM::VertexHandle add_vertex() override { return add_vertex(OM::Vec3f(0, 0, 0)); }
  OM::FaceHandle add_face(const VHandles& indices) override {
    for (const OM::VertexHandle& vh : indices) corners.push_back(vh.idx());
    face_start.push_back(corners.size());
    return OM::FaceHandle(static_cast<int>(face_start.size()) - 2);
  }
  void set_point(OM::VertexHandle vh, const OM::Vec3f& p) override {
    if (vh.idx() >= 0 && static_cast<std::size_t>(vh.idx()) < positions.size()) {
      positions[vh.idx()] = Vec3f(p[0], p[1], p[2]);
    }
  }
  void reserve(unsigned int nv, unsigned int, unsigned int nf) override {
    // Headers can lie; cap what we pre-allocate on their word.
    positions.reserve(std::min(nv, 1u << 24));
    face_start.reserve(std::min(nf, 1u << 24) + 1);
  }
  size_t n_vertices() const override { return positions.size(); }
  size_t n_faces() const override { return face_start.size() - 1; }
  size_t n_edges() const override { return 0; }

  // Connectivity-level and attribute calls: only the .om format uses the
  // former, and meshseek does not read attributes.
  OM::HalfedgeHandle add_edge(OM::VertexHandle, OM::VertexHandle) override {
    return OM::HalfedgeHandle();
  }
  OM::FaceHandle add_face(OM::HalfedgeHandle) override { return OM::FaceHandle(); }
  void add_face_texcoords(OM::FaceHandle,
                          OM::VertexHandle,
                          const std::vector<OM::Vec2f>&) override {}
  void add_face_texcoords(OM::FaceHandle,
                          OM::VertexHandle,
                          const std::vector<OM::Vec3f>&) override {}
  void set_face_texindex(OM::FaceHandle, int) override {}
  void set_halfedge(OM::VertexHandle, OM::HalfedgeHandle) override {}
  void set_normal(OM::VertexHandle, const OM::Vec3f&) override {}
  void set_normal(OM::VertexHandle, const OM::Vec3d&) override {}
  void set_color(OM::VertexHandle, const OM::Vec3uc&) override {}
  void set_color(OM::VertexHandle, const OM::Vec4uc&) override {}
  void set_color(OM::VertexHandle, const OM::Vec3f&) override {}
  void set_color(OM::VertexHandle, const OM::Vec4f&) override {}
  void set_texcoord(OM::VertexHandle, const OM::Vec2f&) override {}
  void set_status(OM::VertexHandle, const OM::Attributes::StatusInfo&) override {}
  void set_next(OM::HalfedgeHandle, OM::HalfedgeHandle) override {}
  void set_face(OM::HalfedgeHandle, OM::FaceHandle) override {}
  void request_face_texcoords2D() override {}
  void set_texcoord(OM::HalfedgeHandle, const OM::Vec2f&) override {}
  void set_texcoord(OM::VertexHandle, const OM::Vec3f&) override {}
  void set_texcoord(OM::HalfedgeHandle, const OM::Vec3f&) override {}
  void set_status(OM::HalfedgeHandle, const OM::Attributes::StatusInfo&) override {}
  void set_color(OM::EdgeHandle, const OM::Vec3uc&) override {}
  void set_color(OM::EdgeHandle, const OM::Vec4uc&) override {}
  void set_color(OM::EdgeHandle, const OM::Vec3f&) override {}
  void set_color(OM::EdgeHandle, const OM::Vec4f&) override {}
  void set_status(OM::EdgeHandle, const OM::Attributes::StatusInfo&) override {}
  void set_normal(OM::FaceHandle, const OM::Vec3f&) override {}
  void set_normal(OM::FaceHandle, const OM::Vec3d&) override {}
  void set_color(OM::FaceHandle, const OM::Vec3uc&) override {}
  void set_color(OM::FaceHandle, const OM::Vec4uc&) override {}
  void set_color(OM::FaceHandle, const OM::Vec3f&) override {}
  void set_color(OM::FaceHandle, const OM::Vec4f&) override {}
  void set_status(OM::FaceHandle, const OM::Attributes::StatusInfo&) override {}
  void add_texture_information(int, std::string) override {}
};

// OpenMesh's readers are process-wide singletons with per-read member state,
// and they report through the global omerr() stream.
std::mutex& OpenMeshMutex() {
  static std::mutex mu;
  return mu;
}

bool IsBinaryFile(const std::string& head, MeshFormat format) {
  switch (format) {
    case MeshFormat::kPly:
      return absl::StrContains(head, "format binary");
    case MeshFormat::kOff:
      return absl::StartsWith(head, "OFF BINARY") || absl::StrContains(head, "OFF BINARY");
    case MeshFormat::kStl:
      return !absl::StartsWith(absl::StripLeadingAsciiWhitespace(head), "solid") ||
             head.find('\0') != std::string::npos;
    case MeshFormat::kObj:
      return false;
  }
  return false;
}

// OpenMesh's ASCII readers parse numbers with iostreams, which fail on "nan"
// and "inf" and then go on with stale values. Before handing an ASCII file to
// them, look for a non-finite number on a coordinate line (OBJ "v", STL
// "vertex", or a line of plain numbers as in OFF and PLY bodies) so the error
// can name the line.
absl::Status CheckAsciiNumbers(const std::string& path) {
  MESHSEEK_ASSIGN_OR_RETURN(const std::string text, ReadFileToString(path));
  std::size_t line_no = 0;
  std::vector<absl::string_view> tokens;
  for (absl::string_view line : absl::StrSplit(text, '\n')) {
    ++line_no;
    // Only a token with one of these letters can be non-finite ("nan",
    // "inf", "1e999"); most lines have none and are skipped without parsing.
    if (line.find_first_of("nNiIeE") == absl::string_view::npos) continue;
    tokens = absl::StrSplit(line, absl::ByAnyChar(" \t\r"), absl::SkipEmpty());
    if (tokens.empty()) continue;
    const std::size_t first = (tokens[0] == "v" || tokens[0] == "vertex") ? 1 : 0;
    bool all_numbers = first < tokens.size();
    absl::string_view bad;
    for (std::size_t k = first; k < tokens.size() && all_numbers; ++k) {
      const std::string token(tokens[k]);
      char* end = nullptr;
      errno = 0;
      const double value = std::strtod(token.c_str(), &end);
      if (end == token.c_str() || *end != '\0') {
        all_numbers = false;
      } else if (bad.empty() &&
                 (!std::isfinite(value) || (errno == ERANGE && std::abs(value) > 1))) {
        bad = tokens[k];
      }
    }
    if (all_numbers && !bad.empty()) {
      return absl::InvalidArgumentError(
          absl::StrCat("line ", line_no, ": non-finite coordinate '", bad, "'"));
    }
  }
  return absl::OkStatus();
}

}  // namespace

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
  return absl::StrJoin(parts, ", ");
}

absl::StatusOr<TriangleMesh> ReadMesh(const std::string& path, MeshReadReport* report) {
  auto with_path = [&path](const absl::Status& st) {
    return absl::Status(st.code(), absl::StrCat(path, ": ", st.message()));
  };
  MESHSEEK_ASSIGN_OR_RETURN(const MeshFormat format, MeshFormatFromPath(path));
  std::string head;
  {
    std::ifstream probe(path, std::ios::binary);
    if (!probe) {
      return absl::NotFoundError(
          absl::StrCat(path, ": cannot open file (", std::strerror(errno), ")"));
    }
    head.resize(512);
    probe.read(head.data(), static_cast<std::streamsize>(head.size()));
    head.resize(static_cast<std::size_t>(probe.gcount()));
    if (head.empty()) return absl::InvalidArgumentError(absl::StrCat(path, ": file is empty"));
  }
  if (!IsBinaryFile(head, format)) {
    const absl::Status numbers = CheckAsciiNumbers(path);
    if (!numbers.ok()) return with_path(numbers);
  }

  SoupImporter importer;
  {
    std::lock_guard<std::mutex> lock(OpenMeshMutex());
    static const bool silenced = [] {
      ::omerr().disconnect(std::cerr);
      ::omlog().disable();
      ::omout().disable();
      return true;
    }();
    (void)silenced;
    std::ostringstream messages;
    ::omerr().connect(messages);
    OM::IO::Options options;
    const bool ok = OM::IO::IOManager().read(path, importer, options);
    ::omerr().flush();
    ::omerr().disconnect(messages);
    if (!ok) {
      std::string detail(absl::StripAsciiWhitespace(messages.str()));
      return absl::InvalidArgumentError(absl::StrCat(path,
                                                     ": OpenMesh could not parse the file as ",
                                                     MeshFormatName(format),
                                                     detail.empty() ? "" : " (",
                                                     detail,
                                                     detail.empty() ? "" : ")"));
    }
  }

  MeshReadReport local;
  MeshReadReport& rep = report ? *report : local;
  rep = MeshReadReport();
  rep.file_vertices = importer.positions.size();
  rep.file_faces = importer.face_start.size() - 1;

  TriangleMesh mesh;
  mesh.vertices = std::move(importer.positions);
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    if (!IsFinite(mesh.vertices[v])) {
      const Vec3f& p = mesh.vertices[v];
      return absl::InvalidArgumentError(absl::StrCat(
          path, ": vertex ", v, " has a non-finite coordinate (", p.x, ", ", p.y, ", ", p.z, ")"));
    }
  }
  const int64_t nv = static_cast<int64_t>(mesh.vertices.size());
  mesh.triangles.reserve(rep.file_faces);
  std::vector<uint32_t> polygon;
  for (std::size_t f = 0; f + 1 < importer.face_start.size(); ++f) {
    polygon.clear();
    const std::size_t begin = importer.face_start[f], end = importer.face_start[f + 1];
    for (std::size_t c = begin; c < end; ++c) {
      const int64_t idx = importer.corners[c];
      if (idx < 0 || idx >= nv) {
        return absl::InvalidArgumentError(absl::StrCat(path,
                                                       ": face ",
                                                       f,
                                                       " (0-based) references vertex ",
                                                       idx,
                                                       ", but the file has ",
                                                       nv,
                                                       " vertices"));
      }
      polygon.push_back(static_cast<uint32_t>(idx));
    }
    // Remove corners equal to their predecessor (cyclically).
    const std::size_t corners_in = polygon.size();
    std::vector<uint32_t> cleaned;
    cleaned.reserve(polygon.size());
    for (std::size_t k = 0; k < polygon.size(); ++k) {
      if (!cleaned.empty() && cleaned.back() == polygon[k]) continue;
      cleaned.push_back(polygon[k]);
    }
    while (cleaned.size() > 1 && cleaned.front() == cleaned.back()) cleaned.pop_back();
    if (cleaned.size() < 3) {
      ++rep.faces_dropped;
      continue;
    }
    if (cleaned.size() != corners_in) ++rep.faces_repaired;
    if (cleaned.size() > 3) ++rep.polygons_triangulated;
    for (std::size_t k = 1; k + 1 < cleaned.size(); ++k) {
      mesh.triangles.push_back({cleaned[0], cleaned[k], cleaned[k + 1]});
    }
  }
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    if (!(TriangleArea(mesh, t) > 0)) ++rep.zero_area_triangles;
  }
  rep.topology = ComputeTopologyStats(mesh);
  const absl::Status valid = ValidateMesh(mesh);
  if (!valid.ok()) return with_path(valid);
  return mesh;
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
