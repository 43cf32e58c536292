// Procedural surface primitives for the synthetic benchmark.
//
// Every primitive returns a welded TriangleMesh (neighbouring triangles share
// vertex ids) whose triangles are oriented outwards by the right-hand rule, so
// a closed primitive has no boundary edge and positive signed volume.
//
// Articulated shapes are built without a CSG library, the way a modeller
// extrudes limbs from a body: quad-structured primitives report their
// VertexGrid (vertex ids in rows and columns), CutHole removes a rectangle of
// quads from the grid, and ExtrudeTube grows a tube whose first ring is the
// rim of that hole. The result stays one connected, closed, manifold surface,
// like the meshes of real articulated benchmarks. Appending parts without
// cutting (AppendMesh) instead gives overlapping multi-component models.
#ifndef MESHSEEK_COMMON_SYNTH_SHAPES_H_
#define MESHSEEK_COMMON_SYNTH_SHAPES_H_

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "common/geometry/mesh.h"
#include "common/geometry/vec3.h"

namespace meshseek {

// Vertex ids of a quad-structured surface laid out in rows and columns:
// rows[r][c] is the vertex at row r, column c; all rows have the same length.
struct VertexGrid {
  std::vector<std::vector<uint32_t>> rows;
  // Whether column num_cols() - 1 neighbours column 0 (rings of a tube or the
  // latitude circles of an ellipsoid). Rows never wrap.
  bool wrap_cols = false;

  int num_rows() const { return static_cast<int>(rows.size()); }
  int num_cols() const { return rows.empty() ? 0 : static_cast<int>(rows[0].size()); }

  // Ids of the closed rectangle of vertices rows [row, row + height] x columns
  // [col, col + width], i.e. height x width quads. Columns are taken modulo
  // num_cols() when wrapping (width must then stay below num_cols()). Returns
  // an empty vector if the rectangle does not fit.
  std::vector<uint32_t> Patch(int row, int col, int height, int width) const;

  // Adds `offset` to every id (after AppendMesh moved the part).
  void Shift(uint32_t offset);
};

// Radius of a tube as a function of the arc-length fraction t in [0, 1] along
// its path.
using RadiusProfile = std::function<double(double)>;

struct TubeOptions {
  // Vertices per ring (at least 3). ExtrudeTube ignores it when
  // keep_rim_shape is set.
  int sides = 8;
  // ExtrudeTube only: every ring repeats the shape of the rim it grows from
  // (scaled so that its mean radius is radius(t)) instead of being a circle.
  // A square hole in a box then gives a square table leg.
  bool keep_rim_shape = false;
  // Close the ends with a fan to an apex (true) or leave them open (boundary
  // loops). ExtrudeTube has no start cap: it starts at the rim.
  bool cap_start = true;
  bool cap_end = true;
  // The apex of a cap lies this many end radii beyond the end ring: 0 gives a
  // flat cap, 1 a cone as high as the tube is thick. Pointed tips (tentacles,
  // jaws) use more; a radius profile that narrows before the end rounds it.
  double cap_height = 0.5;
};

// UV ellipsoid centred at the origin with semi-axes `radii`, `rings` latitude
// bands (clamped to >= 2) and `sectors` meridians (clamped to >= 3). Vertex 0
// is the +z pole and the last vertex the -z pole. grid rows are the rings - 1
// latitude circles from +z down (row r at polar angle pi (r + 1) / rings),
// column c at azimuth 2 pi c / sectors from +x; columns wrap.
TriangleMesh MakeEllipsoid(const Vec3d& radii, int rings, int sectors, VertexGrid* grid = nullptr);

// Axis-aligned box centred at the origin with edge lengths `size`; every face
// is a grid of quads with edges no longer than `max_edge` (at least one quad
// per edge), welded along the box's edges. faces, if given, receives the six
// face grids in the order +x, -x, +y, -y, +z, -z: rows[r][c] is lattice point
// c along the face's axis p and r along its axis q, with p x q pointing out of
// the box: (p, q) = (y, z), (z, y), (z, x), (x, z), (x, y), (y, x).
TriangleMesh MakeBox(const Vec3d& size,
                     double max_edge,
                     std::array<VertexGrid, 6>* faces = nullptr);

// Torus around the z axis with ring radius `major` and tube radius `minor`,
// major_segments x minor_segments quads (clamped to >= 3 each). grid row r is
// the cross-section at angle 2 pi r / major_segments from +x; column 0 is on
// the outer equator and columns increase towards +z; columns wrap.
TriangleMesh MakeTorus(
    double major, double minor, int major_segments, int minor_segments, VertexGrid* grid = nullptr);

struct ProfilePoint {
  double radius = 0;
  double height = 0;
};

// Revolves `profile` (listed from bottom to top, at least 2 points) about the
// z axis with `sectors` vertices per ring (clamped to >= 3). An end with
// radius 0 becomes one pole vertex that closes the surface; an end with
// positive radius stays open (a boundary loop), like the mouth of a vase.
// Interior profile points must have positive radius. grid rows are the rings
// of positive radius, bottom to top; columns wrap.
absl::StatusOr<TriangleMesh> MakeSurfaceOfRevolution(const std::vector<ProfilePoint>& profile,
                                                     int sectors,
                                                     VertexGrid* grid = nullptr);

// A free-standing tube (generalised cylinder) along `path` (at least 2
// distinct points): one ring of options.sides vertices per path point with
// radius(t), t the arc-length fraction of the point, oriented by
// rotation-minimising frames so that it does not twist; capped per `options`.
// grid rows are the rings, first to last.
absl::StatusOr<TriangleMesh> MakeTube(const std::vector<Vec3d>& path,
                                      const RadiusProfile& radius,
                                      const TubeOptions& options,
                                      VertexGrid* grid = nullptr);

// Removes every triangle of `mesh` whose three corners are all in `patch` and
// returns the rim of the hole: its vertex ids in order, running the way the
// removed triangles ran (counter-clockwise seen from outside), as ExtrudeTube
// and BridgeHoles expect. The removed triangles must form one disk; otherwise
// (nothing selected, a patch with holes or pinched corners) this fails and
// leaves the mesh unchanged. Vertices inside the hole become unreferenced
// (RemoveUnreferencedVertices drops them once the shape is finished).
absl::StatusOr<std::vector<uint32_t>> CutHole(const std::vector<uint32_t>& patch,
                                              TriangleMesh* mesh);

// Grows a tube out of the hole `rim` (from CutHole), welded to it: ring 0 is
// the rim itself and ring i >= 1 is centred on path[i - 1] with radius(t_i),
// t_i the arc-length fraction of path[i - 1] along the polyline that starts at
// the rim's centroid. Rings are circles of options.sides vertices (or copies of
// the rim, see keep_rim_shape), stitched to the rim by angle so that the two
// counts need not match. The path should leave the surface (its first point
// about a radius away from the rim) and bend gently compared with the radius.
// Returns the grid of rings 1..n so that further holes can be cut in the tube.
absl::StatusOr<VertexGrid> ExtrudeTube(const std::vector<uint32_t>& rim,
                                       const std::vector<Vec3d>& path,
                                       const RadiusProfile& radius,
                                       const TubeOptions& options,
                                       TriangleMesh* mesh);

// Joins two holes with a tube along `path` (the interior points between the
// rims, at least one): rings of `sides` vertices stitched to rim_a at the start
// and rim_b at the end. The result is a handle, like the bridge of spectacles.
absl::Status BridgeHoles(const std::vector<uint32_t>& rim_a,
                         const std::vector<uint32_t>& rim_b,
                         const std::vector<Vec3d>& path,
                         const RadiusProfile& radius,
                         int sides,
                         TriangleMesh* mesh);

// Chaikin corner cutting, `iterations` times, keeping both end points: turns
// the joints of a limb into rounded elbows and knees.
std::vector<Vec3d> SmoothPolyline(const std::vector<Vec3d>& points, int iterations);

// Points at equal arc-length steps of about `spacing` along the polyline, both
// end points kept (at least 2 points unless the input has fewer).
std::vector<Vec3d> ResamplePolyline(const std::vector<Vec3d>& points, double spacing);

// Appends `part` to `mesh` without welding anything and returns the offset
// added to the part's vertex ids (for VertexGrid::Shift).
uint32_t AppendMesh(const TriangleMesh& part, TriangleMesh* mesh);

// Drops vertices no triangle uses and renumbers the rest (order kept).
void RemoveUnreferencedVertices(TriangleMesh* mesh);

// The same triangles with three private vertices each: a polygon soup, as
// STL files and many web models are.
TriangleMesh MakePolygonSoup(const TriangleMesh& mesh);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_SYNTH_SHAPES_H_
