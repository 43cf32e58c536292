// Area-uniform quasi-random sampling of a triangle mesh surface (the seed
// paper's sec. 3.1; docs/design.md 2.1). Used for DLD-SIFT feature points, for the
// dense point set behind local frames, and for RLD-SIFT's remeshing.
//
// One point per area A/N: triangles are visited in order and get
// q_i = floor(area_i / s + r_{i-1}) points, the remainder r_i carried on
// (error diffusion), so sample density is uniform per area whatever the
// tessellation. Floating-point round-off can leave N-1 points; the last
// triangle with positive area takes the missing one so exactly N come out.
// Positions come from one 2-D Sobol sequence continued across all triangles,
// mapped with P = (1 - sqrt(u1)) t1 + sqrt(u1) (1 - u2) t2 + sqrt(u1) u2 t3
// (Osada et al.), which is uniform on the triangle. Zero-area triangles get no
// points. Fully deterministic.
#ifndef MESHSEEK_COMMON_GEOMETRY_SURFACE_SAMPLER_H_
#define MESHSEEK_COMMON_GEOMETRY_SURFACE_SAMPLER_H_

#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "common/geometry/mesh.h"

namespace meshseek {

// Points on a surface with the unit normal and index of the triangle each
// lies on (parallel arrays).
struct SurfacePoints {
  std::vector<Vec3f> positions;
  std::vector<Vec3f> normals;
  std::vector<uint32_t> faces;

  std::size_t size() const { return positions.size(); }
};

// Exactly `count` points (count >= 1). Errors if the mesh has no area or
// `count` is not positive. The mesh is assumed valid (ValidateMesh).
absl::StatusOr<SurfacePoints> SampleSurface(const TriangleMesh& mesh, int64_t count);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_GEOMETRY_SURFACE_SAMPLER_H_
