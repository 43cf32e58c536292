// Surface checks shared by the synth tests (header-only; tests only).
#ifndef MESHSEEK_COMMON_SYNTH_TEST_CHECKS_H_
#define MESHSEEK_COMMON_SYNTH_TEST_CHECKS_H_

#include <cstdint>
#include <map>
#include <utility>

#include "common/geometry/mesh.h"

namespace meshseek {
namespace synth_testing {

// Directed edges used more than once, or (when `closed`) without their
// reverse. 0 means a consistently oriented manifold surface (closed if
// `closed`): every edge joins two triangles that traverse it in opposite
// directions.
inline int OrientationErrors(const TriangleMesh& mesh, bool closed) {
  std::map<std::pair<uint32_t, uint32_t>, int> uses;
  for (const Triangle& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) ++uses[{t[k], t[(k + 1) % 3]}];
  }
  int errors = 0;
  for (const auto& [edge, count] : uses) {
    if (count > 1) ++errors;
    if (closed && uses.count({edge.second, edge.first}) == 0) ++errors;
  }
  return errors;
}

// Volume enclosed by a closed, outward-oriented surface (divergence theorem).
inline double SignedVolume(const TriangleMesh& mesh) {
  double volume = 0;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto c = mesh.Corners(t);
    volume += Dot(c[0], Cross(c[1], c[2])) / 6;
  }
  return volume;
}

// Vertices - edges + faces; 2 for a sphere, 0 for a torus, 2 - 2g for genus g.
inline long EulerCharacteristic(const TriangleMesh& mesh) {
  std::map<std::pair<uint32_t, uint32_t>, int> edges;
  for (const Triangle& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      edges[std::minmax(t[k], t[(k + 1) % 3])] = 1;
    }
  }
  return static_cast<long>(mesh.vertices.size()) - static_cast<long>(edges.size()) +
         static_cast<long>(mesh.triangles.size());
}

}  // namespace synth_testing
}  // namespace meshseek

#endif  // MESHSEEK_COMMON_SYNTH_TEST_CHECKS_H_
