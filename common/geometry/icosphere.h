// The icosahedron and its subdivisions: each level splits every triangle into
// four at its edge midpoints, pushed onto the sphere. 12, 42, 162, 642, ...
// vertices; nearly uniform directions on the sphere (view-based descriptors
// render from them) and a sphere mesh with a known surface (tests).
#ifndef MESHSEEK_COMMON_GEOMETRY_ICOSPHERE_H_
#define MESHSEEK_COMMON_GEOMETRY_ICOSPHERE_H_

#include <vector>

#include "common/geometry/mesh.h"

namespace meshseek {

/// The icosahedron subdivided `levels` times (0 <= levels <= 8), vertices on
/// the sphere of `radius` about the origin, triangles facing outwards.
TriangleMesh Icosphere(int levels, double radius = 1.0);

/// The unit vertex directions of Icosphere(levels), in double precision.
std::vector<Vec3d> IcosphereDirections(int levels);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_GEOMETRY_ICOSPHERE_H_
