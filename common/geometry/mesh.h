// The triangle mesh every algorithm in meshseek works on.
//
// A TriangleMesh is deliberately just arrays: vertex positions and triangles as
// vertex-index triples. It may be a polygon soup, have several components,
// non-manifold edges, duplicate vertices or zero-area triangles; algorithms
// that need connectivity (LD-SIFT's 1-ring) build it themselves. Validation is
// separate (ValidateMesh) so that readers can report everything at once.
#ifndef MESHSEEK_COMMON_GEOMETRY_MESH_H_
#define MESHSEEK_COMMON_GEOMETRY_MESH_H_

#include <array>
#include <cstdint>
#include <vector>

#include "absl/status/status.h"
#include "common/geometry/vec3.h"

namespace meshseek {

using Triangle = std::array<uint32_t, 3>;

struct TriangleMesh {
  std::vector<Vec3f> vertices;
  std::vector<Triangle> triangles;

  // Corner positions of triangle t, in double.
  std::array<Vec3d, 3> Corners(std::size_t t) const {
    const Triangle& tri = triangles[t];
    return {Vec3d(vertices[tri[0]]), Vec3d(vertices[tri[1]]), Vec3d(vertices[tri[2]])};
  }
};

// Connectivity facts about a mesh, computed from shared vertex indices (two
// triangles touch when they share a vertex index; coincident but distinct
// vertices do not connect, as in the file).
struct MeshTopologyStats {
  std::size_t components = 0;          // connected components of triangles
  std::size_t boundary_edges = 0;      // edges used by exactly one triangle
  std::size_t non_manifold_edges = 0;  // edges used by three or more triangles
  std::size_t unreferenced_vertices = 0;
};
MeshTopologyStats ComputeTopologyStats(const TriangleMesh& mesh);

// Area of triangle t (0 for degenerate ones).
double TriangleArea(const TriangleMesh& mesh, std::size_t t);
// Unit normal of triangle t by the right-hand rule, or zero if degenerate.
Vec3d TriangleNormal(const TriangleMesh& mesh, std::size_t t);
// Sum of triangle areas.
double SurfaceArea(const TriangleMesh& mesh);

// Checks the invariants every algorithm relies on: at least one triangle, all
// vertex indices in range, all coordinates finite, a bounding box extent and a
// total surface area that are finite in float (coordinates near FLT_MAX are
// finite but make both overflow), and positive total area. The message names
// the first offending vertex or triangle, or the overflowing quantity.
absl::Status ValidateMesh(const TriangleMesh& mesh);

// Applies p -> scale * R p + t to every vertex (R row-major 3x3). Used by tests
// and the synthetic benchmark to make rotated, scaled and moved copies.
void TransformMesh(const std::array<double, 9>& rotation,
                   double scale,
                   const Vec3d& translation,
                   TriangleMesh* mesh);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_GEOMETRY_MESH_H_
