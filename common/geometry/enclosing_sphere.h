// Minimum enclosing sphere of a point set. Its diameter D is the scale
// reference of the seed paper: DLD-SIFT's support radius is given relative to
// it ("E = 1.0 indicates a scale identical to the enclosing sphere").
//
// Welzl's algorithm on a shuffled copy of the points (fixed seed, so the
// result is deterministic), expected linear time, with at most 4 support
// points. Degenerate supports (collinear triples, coplanar quadruples) fall
// back to the smallest sphere of a subset that contains the others.
#ifndef MESHSEEK_COMMON_GEOMETRY_ENCLOSING_SPHERE_H_
#define MESHSEEK_COMMON_GEOMETRY_ENCLOSING_SPHERE_H_

#include <vector>

#include "absl/status/statusor.h"
#include "common/geometry/mesh.h"

namespace meshseek {

struct Sphere {
  Vec3d center;
  double radius = 0;

  double diameter() const { return 2 * radius; }
};

// Smallest sphere containing every point (within a relative tolerance of
// 1e-9 of the radius). Errors on an empty or non-finite input.
absl::StatusOr<Sphere> MinimumEnclosingSphere(const std::vector<Vec3f>& points);

// Smallest sphere containing every vertex used by a triangle of `mesh`
// (unreferenced vertices do not count).
absl::StatusOr<Sphere> MinimumEnclosingSphere(const TriangleMesh& mesh);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_GEOMETRY_ENCLOSING_SPHERE_H_
