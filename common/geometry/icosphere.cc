#include "common/geometry/icosphere.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

namespace meshseek {
namespace {

struct Subdivided {
  std::vector<Vec3d> vertices;
  std::vector<Triangle> triangles;
};

Subdivided Subdivide(int levels) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  Subdivided s;
  s.vertices = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (auto& p : s.vertices) p = Normalized(p);
  s.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                 {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                 {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                 {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  levels = std::clamp(levels, 0, 8);
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
    auto midpoint = [&](uint32_t a, uint32_t b) {
      const auto key = std::make_pair(std::min(a, b), std::max(a, b));
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      s.vertices.push_back(Normalized((s.vertices[a] + s.vertices[b]) * 0.5));
      const auto index = static_cast<uint32_t>(s.vertices.size() - 1);
      mid[key] = index;
      return index;
    };
    std::vector<Triangle> next;
    next.reserve(4 * s.triangles.size());
    for (const Triangle& tri : s.triangles) {
      const uint32_t a = midpoint(tri[0], tri[1]), b = midpoint(tri[1], tri[2]),
                     c = midpoint(tri[2], tri[0]);
      next.push_back({tri[0], a, c});
      next.push_back({tri[1], b, a});
      next.push_back({tri[2], c, b});
      next.push_back({a, b, c});
    }
    s.triangles = std::move(next);
  }
  return s;
}

}  // namespace

TriangleMesh Icosphere(int levels, double radius) {
  Subdivided s = Subdivide(levels);
  TriangleMesh mesh;
  mesh.vertices.reserve(s.vertices.size());
  for (const Vec3d& p : s.vertices) mesh.vertices.emplace_back(p * radius);
  mesh.triangles = std::move(s.triangles);
  return mesh;
}

std::vector<Vec3d> IcosphereDirections(int levels) { return Subdivide(levels).vertices; }

}  // namespace meshseek
