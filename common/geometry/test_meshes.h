// Small exact meshes for unit tests (header-only; tests only). Richer
// procedural shapes live in common/synth.
#ifndef MESHSEEK_COMMON_GEOMETRY_TEST_MESHES_H_
#define MESHSEEK_COMMON_GEOMETRY_TEST_MESHES_H_

#include <cmath>
#include <map>
#include <utility>

#include "common/geometry/icosphere.h"
#include "common/geometry/mesh.h"

namespace meshseek {
namespace testing_meshes {

// Axis-aligned cube [-h, h]^3, 12 outward-facing triangles, 8 shared vertices.
inline TriangleMesh Cube(float h = 1.0f) {
  TriangleMesh m;
  for (int i = 0; i < 8; ++i) {
    m.vertices.emplace_back(i & 1 ? h : -h, i & 2 ? h : -h, i & 4 ? h : -h);
  }
  m.triangles = {{0, 2, 1},
                 {1, 2, 3},
                 {4, 5, 6},
                 {5, 7, 6},
                 {0, 1, 4},
                 {1, 5, 4},
                 {2, 6, 3},
                 {3, 6, 7},
                 {0, 4, 2},
                 {2, 4, 6},
                 {1, 3, 5},
                 {3, 7, 5}};
  return m;
}

// Square [-h, h]^2 in the plane z = z0, split into (2n)^2 cells of 2 triangles.
inline TriangleMesh Plane(int n, float h = 1.0f, float z0 = 0.0f) {
  TriangleMesh m;
  const int k = 2 * n;
  for (int j = 0; j <= k; ++j) {
    for (int i = 0; i <= k; ++i) {
      m.vertices.emplace_back(-h + 2 * h * i / k, -h + 2 * h * j / k, z0);
    }
  }
  for (int j = 0; j < k; ++j) {
    for (int i = 0; i < k; ++i) {
      const uint32_t a = j * (k + 1) + i, b = a + 1, c = a + (k + 1), d = c + 1;
      m.triangles.push_back({a, b, d});
      m.triangles.push_back({a, d, c});
    }
  }
  return m;
}

// Icosphere of radius r: an icosahedron subdivided `levels` times, vertices
// projected to the sphere. 20 * 4^levels triangles.
inline TriangleMesh Icosphere(int levels, float r = 1.0f) { return meshseek::Icosphere(levels, r); }

// Copy of `mesh` in which every triangle has its own three vertices.
inline TriangleMesh ToSoup(const TriangleMesh& mesh) {
  TriangleMesh soup;
  for (const Triangle& t : mesh.triangles) {
    const uint32_t base = static_cast<uint32_t>(soup.vertices.size());
    for (uint32_t v : t) soup.vertices.push_back(mesh.vertices[v]);
    soup.triangles.push_back({base, base + 1, base + 2});
  }
  return soup;
}

// Appends `part` to `mesh` without welding.
inline void Append(const TriangleMesh& part, TriangleMesh* mesh) {
  const uint32_t base = static_cast<uint32_t>(mesh->vertices.size());
  mesh->vertices.insert(mesh->vertices.end(), part.vertices.begin(), part.vertices.end());
  for (const Triangle& t : part.triangles) {
    mesh->triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  }
}

// A lumpy closed surface with no symmetry (an icosphere subdivided `levels`
// times, bumped and stretched).
inline TriangleMesh LumpyBlob(int levels = 3) {
  TriangleMesh mesh = Icosphere(levels, 1.0f);
  for (Vec3f& v : mesh.vertices) {
    const float bump = 1.0f + 0.25f * std::sin(3 * v.x + 1) * std::cos(2 * v.y) + 0.15f * v.z * v.x;
    v = Vec3f(1.6f * v.x * bump, v.y * bump, 0.7f * v.z * bump);
  }
  return mesh;
}

// Rotation matrix (row-major) about a unit axis by `angle` radians.
inline std::array<double, 9> AxisAngle(Vec3d axis, double angle) {
  axis = Normalized(axis);
  const double c = std::cos(angle), s = std::sin(angle), C = 1 - c;
  const double x = axis.x, y = axis.y, z = axis.z;
  return {c + x * x * C,
          x * y * C - z * s,
          x * z * C + y * s,
          y * x * C + z * s,
          c + y * y * C,
          y * z * C - x * s,
          z * x * C - y * s,
          z * y * C + x * s,
          c + z * z * C};
}

}  // namespace testing_meshes
}  // namespace meshseek

#endif  // MESHSEEK_COMMON_GEOMETRY_TEST_MESHES_H_
