#include "common/geometry/mesh.h"

#include <algorithm>
#include <numeric>
#include <unordered_map>
#include <utility>

#include "absl/strings/str_cat.h"

namespace meshseek {
namespace {

// Union-find over vertex indices with path halving.
struct DisjointSets {
  explicit DisjointSets(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  uint32_t Find(uint32_t v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  }
  void Union(uint32_t a, uint32_t b) { parent[Find(a)] = Find(b); }
  std::vector<uint32_t> parent;
};

}  // namespace

MeshTopologyStats ComputeTopologyStats(const TriangleMesh& mesh) {
  MeshTopologyStats stats;
  const std::size_t nv = mesh.vertices.size();
  std::vector<bool> used(nv, false);
  DisjointSets sets(nv);
  std::unordered_map<uint64_t, uint32_t> edge_uses;
  edge_uses.reserve(mesh.triangles.size() * 2);
  for (const Triangle& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = t[k], b = t[(k + 1) % 3];
      if (a >= nv || b >= nv) continue;
      used[a] = true;
      sets.Union(a, b);
      const uint64_t key = (static_cast<uint64_t>(std::min(a, b)) << 32) | std::max(a, b);
      ++edge_uses[key];
    }
  }
  for (const auto& [key, uses] : edge_uses) {
    if (uses == 1) ++stats.boundary_edges;
    if (uses >= 3) ++stats.non_manifold_edges;
  }
  for (std::size_t v = 0; v < nv; ++v) {
    if (!used[v]) {
      ++stats.unreferenced_vertices;
    } else if (sets.Find(static_cast<uint32_t>(v)) == v) {
      ++stats.components;
    }
  }
  return stats;
}

double TriangleArea(const TriangleMesh& mesh, std::size_t t) {
  const auto c = mesh.Corners(t);
  return 0.5 * Norm(Cross(c[1] - c[0], c[2] - c[0]));
}

Vec3d TriangleNormal(const TriangleMesh& mesh, std::size_t t) {
  const auto c = mesh.Corners(t);
  return Normalized(Cross(c[1] - c[0], c[2] - c[0]));
}

double SurfaceArea(const TriangleMesh& mesh) {
  double area = 0;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) area += TriangleArea(mesh, t);
  return area;
}

absl::Status ValidateMesh(const TriangleMesh& mesh) {
  if (mesh.triangles.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat("mesh has no faces (", mesh.vertices.size(), " vertices)"));
  }
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    if (!IsFinite(mesh.vertices[v])) {
      return absl::InvalidArgumentError(absl::StrCat("vertex ",
                                                     v,
                                                     " has a non-finite coordinate (",
                                                     mesh.vertices[v].x,
                                                     ", ",
                                                     mesh.vertices[v].y,
                                                     ", ",
                                                     mesh.vertices[v].z,
                                                     ")"));
    }
  }
  const std::size_t nv = mesh.vertices.size();
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (const uint32_t idx : mesh.triangles[t]) {
      if (idx >= nv) {
        return absl::InvalidArgumentError(absl::StrCat(
            "triangle ", t, " references vertex ", idx, " but the mesh has ", nv, " vertices"));
      }
    }
  }
  const double area = SurfaceArea(mesh);
  if (!(area > 0)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "mesh has zero total surface area (", mesh.triangles.size(), " degenerate faces)"));
  }
  return absl::OkStatus();
}

void TransformMesh(const std::array<double, 9>& r,
                   double scale,
                   const Vec3d& translation,
                   TriangleMesh* mesh) {
  for (Vec3f& p : mesh->vertices) {
    const Vec3d q(p);
    const Vec3d rq(r[0] * q.x + r[1] * q.y + r[2] * q.z,
                   r[3] * q.x + r[4] * q.y + r[5] * q.z,
                   r[6] * q.x + r[7] * q.y + r[8] * q.z);
    p = Vec3f(rq * scale + translation);
  }
}

}  // namespace meshseek
