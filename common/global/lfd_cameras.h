// The camera geometry of the Light Field Descriptor (Chen, Tian, Shen &
// Ouhyoung, "On visual similarity based 3D model retrieval", Eurographics
// 2003): where the cameras of a light field sit, which rotations of the
// camera system map it onto itself, and how the ten light fields of a model
// are turned against each other.
//
// A light field is 20 orthographic cameras on the vertices of a regular
// dodecahedron, all looking at the centre. Opposite vertices see mirror
// images of the same silhouette, and the silhouette descriptors (Zernike
// and Fourier magnitudes) are mirror invariant, so a light field is 10
// views: one direction per antipodal vertex pair (LightFieldViewDirections).
//
// Comparing two light fields means aligning their camera systems: the 60
// rotations of the icosahedral group map the dodecahedron onto itself and so
// permute the 10 antipodal pairs (ViewPermutations). Both are derived here
// from the vertex coordinates, not tabulated, and the tests check that there
// are exactly 60 distinct permutations forming a group.
//
// A model has 10 light fields from differently rotated dodecahedra, so that
// the cameras of one model's light fields come closer to those of another's
// whatever their relative orientation (LightFieldRotations).
#ifndef MESHSEEK_COMMON_GLOBAL_LFD_CAMERAS_H_
#define MESHSEEK_COMMON_GLOBAL_LFD_CAMERAS_H_

#include <array>
#include <cstdint>
#include <vector>

#include "common/geometry/vec3.h"

namespace meshseek {

/// Views per light field (antipodal dodecahedron vertex pairs).
inline constexpr int kLfdViewsPerLightField = 10;
/// Light fields per model (differently rotated camera systems).
inline constexpr int kLfdLightFields = 10;
/// Rotations of the icosahedral group (the dodecahedron's rotation group).
inline constexpr int kLfdCameraRotations = 60;

/// Row-major 3x3 rotation matrix.
using Rotation3 = std::array<double, 9>;
/// perm[i] = j: the rotation carries view direction i onto +-direction j.
using ViewPermutation = std::array<uint8_t, kLfdViewsPerLightField>;

/// The 20 unit vertices of the regular dodecahedron (+-1, +-1, +-1),
/// (0, +-1/phi, +-phi), (+-1/phi, +-phi, 0), (+-phi, 0, +-1/phi), normalised.
/// Fixed order; vertex i + 10 is the antipode of vertex i.
const std::array<Vec3d, 20>& DodecahedronVertices();

/// The first 10 dodecahedron vertices: one of each antipodal pair, the
/// camera directions of the unrotated light field.
std::array<Vec3d, kLfdViewsPerLightField> LightFieldViewDirections();

/// The 60 rotations mapping the dodecahedron's vertex set onto itself,
/// identity first. Found by sending one edge (v0, v1) onto every directed
/// edge of the solid (20 vertices x 3 neighbours) and keeping the rotations
/// that map every vertex onto a vertex.
const std::vector<Rotation3>& IcosahedralRotations();

/// The permutation of the 10 view directions induced by each of
/// IcosahedralRotations(), in the same order (identity first).
const std::vector<ViewPermutation>& ViewPermutations();

/// The rotations of the 10 light fields' camera systems, identity first.
/// Chosen by farthest-point sampling in the space of camera systems (SO(3)
/// modulo the icosahedral group, where R and R g give the same cameras):
/// among 4,096 rotations drawn uniformly (Shoemake's quaternions, from a
/// std::mt19937_64 with the fixed seed 2003) each next pick maximises its
/// distance to those already picked, the distance of R and S being the
/// smallest rotation angle of R^T S g over the 60 g. Deterministic: computed
/// once, the same on every run and machine with the same libm.
const std::array<Rotation3, kLfdLightFields>& LightFieldRotations();

/// Rotation angle (radians, in [0, pi]) of R.
double RotationAngle(const Rotation3& r);

/// R * v.
Vec3d Rotate(const Rotation3& r, const Vec3d& v);

/// a * b.
Rotation3 Compose(const Rotation3& a, const Rotation3& b);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_GLOBAL_LFD_CAMERAS_H_
