#include "common/geometry/mesh.h"

#include <algorithm>
#include <limits>
#include <numeric>
#include <utility>

#include "absl/strings/str_cat.h"

namespace meshseek {
namespace {

// Union-find over vertex indices with path halving and union by rank (meshes
// list triangles in an order that makes unranked trees deep).
struct DisjointSets {
  explicit DisjointSets(std::size_t n) : parent(n), rank(n, 0) {
    std::iota(parent.begin(), parent.end(), 0u);
  }
  uint32_t Find(uint32_t v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  }
  void Union(uint32_t a, uint32_t b) {
    a = Find(a);
    b = Find(b);
    if (a == b) return;
    if (rank[a] > rank[b]) std::swap(a, b);
    parent[a] = b;
    if (rank[a] == rank[b]) ++rank[b];
  }
  std::vector<uint32_t> parent;
  std::vector<uint8_t> rank;
};

}  // namespace

MeshTopologyStats ComputeTopologyStats(const TriangleMesh& mesh) {
  MeshTopologyStats stats;
  const std::size_t nv = mesh.vertices.size();
  std::vector<bool> used(nv, false);
  DisjointSets sets(nv);
  // Edge uses are counted by bucketing every edge {a, b} (a <= b) under a, a
  // counting sort: linear, and several times faster than hashing the edges
  // (this runs on every mesh read).
  auto for_each_edge = [&mesh, nv](auto&& visit) {
    for (const Triangle& t : mesh.triangles) {
      for (int k = 0; k < 3; ++k) {
        const uint32_t a = t[k], b = t[(k + 1) % 3];
        if (a < nv && b < nv) visit(a, b);
      }
    }
  };
  std::vector<uint32_t> bucket_start(nv + 1, 0);
  for_each_edge([&](uint32_t a, uint32_t b) {
    used[a] = true;
    sets.Union(a, b);
    ++bucket_start[std::min(a, b) + 1];
  });
  std::partial_sum(bucket_start.begin(), bucket_start.end(), bucket_start.begin());
  std::vector<uint32_t> fill(bucket_start.begin(), bucket_start.end() - 1);
  std::vector<uint32_t> other_ends(bucket_start[nv]);
  for_each_edge(
      [&](uint32_t a, uint32_t b) { other_ends[fill[std::min(a, b)]++] = std::max(a, b); });
  for (std::size_t v = 0; v < nv; ++v) {
    uint32_t* const begin = other_ends.data() + bucket_start[v];
    uint32_t* const end = other_ends.data() + bucket_start[v + 1];
    if (end - begin > 16) {
      std::sort(begin, end);
    } else {  // the usual few edges per vertex: insertion sort
      for (uint32_t* i = begin + (begin != end); i < end; ++i) {
        const uint32_t key = *i;
        uint32_t* j = i;
        for (; j > begin && *(j - 1) > key; --j) *j = *(j - 1);
        *j = key;
      }
    }
    for (uint32_t* run = begin; run != end;) {
      uint32_t* next = run + 1;
      while (next != end && *next == *run) ++next;
      if (next - run == 1) ++stats.boundary_edges;
      if (next - run >= 3) ++stats.non_manifold_edges;
      run = next;
    }
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
  // Finite coordinates can still be too large to work with: every algorithm
  // stores and normalises in float, so the extent and the area must be float
  // values too (coordinates near FLT_MAX make both overflow).
  Vec3d low = Vec3d(mesh.vertices[0]), high = low;
  for (const Vec3f& p : mesh.vertices) {
    for (int k = 0; k < 3; ++k) {
      low[k] = std::min(low[k], static_cast<double>(p[k]));
      high[k] = std::max(high[k], static_cast<double>(p[k]));
    }
  }
  const Vec3d extent = high - low;
  constexpr double kFloatMax = std::numeric_limits<float>::max();
  if (!(std::max({extent.x, extent.y, extent.z}) <= kFloatMax)) {
    return absl::InvalidArgumentError(absl::StrCat("mesh bounding box extent (",
                                                   extent.x,
                                                   ", ",
                                                   extent.y,
                                                   ", ",
                                                   extent.z,
                                                   ") overflows float: coordinates too large"));
  }
  const double area = SurfaceArea(mesh);
  if (!(area <= kFloatMax)) {
    return absl::InvalidArgumentError(
        absl::StrCat("mesh total surface area ", area, " overflows float: coordinates too large"));
  }
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
