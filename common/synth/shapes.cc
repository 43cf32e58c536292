#include "common/synth/shapes.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>
#include <unordered_set>

#include "absl/strings/str_cat.h"

namespace meshseek {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kTwoPi = 2 * kPi;

// Orthonormal frame of a tube ring: t along the tube, (u, w) spanning the
// ring's plane, counter-clockwise about t.
struct Frame {
  Vec3d t, u, w;
};

// Vertex ids of one ring and the angle of each about its frame's t axis. Rings
// are stitched by these angles, so neighbouring rings may differ in size.
struct Ring {
  std::vector<uint32_t> ids;
  std::vector<double> angles;
};

Vec3d Position(const TriangleMesh& mesh, uint32_t v) { return Vec3d(mesh.vertices[v]); }

uint32_t AddVertex(const Vec3d& p, TriangleMesh* mesh) {
  mesh->vertices.emplace_back(p);
  return static_cast<uint32_t>(mesh->vertices.size() - 1);
}

double PositiveAngle(double a) {  // in [0, 2 pi)
  a = std::fmod(a, kTwoPi);
  return a < 0 ? a + kTwoPi : a;
}

double SignedAngle(double a) {  // in [-pi, pi)
  return PositiveAngle(a + kPi) - kPi;
}

Vec3d AnyPerpendicular(const Vec3d& t) {
  const Vec3d a = std::abs(t.x) < 0.6 ? Vec3d(1, 0, 0) : Vec3d(0, 1, 0);
  return Normalized(a - t * Dot(a, t));
}

Frame MakeFrame(const Vec3d& t, const Vec3d& u_hint) {
  Vec3d u = Normalized(u_hint - t * Dot(u_hint, t));
  if (SquaredNorm(u) == 0) u = AnyPerpendicular(t);
  return {t, u, Cross(t, u)};
}

// Turns `f` by the smallest rotation that takes f.t to `t` (Rodrigues). Chained
// along a path this is parallel transport: the rings do not twist.
Frame Transport(const Frame& f, const Vec3d& t) {
  const Vec3d axis = Cross(f.t, t);
  const double s = Norm(axis), c = Dot(f.t, t);
  Vec3d u = f.u;
  if (s > 1e-12) {
    const Vec3d k = axis / s;
    u = u * c + Cross(k, u) * s + k * (Dot(k, u) * (1 - c));
  }
  return MakeFrame(t, u);
}

// Frames at every centre, the first one given; tangents by central differences.
std::vector<Frame> FramesAlong(const std::vector<Vec3d>& centers, const Frame& start) {
  std::vector<Frame> frames = {start};
  const std::size_t n = centers.size();
  for (std::size_t i = 1; i < n; ++i) {
    Vec3d t = Normalized(centers[std::min(i + 1, n - 1)] - centers[i - 1]);
    if (SquaredNorm(t) == 0) t = frames.back().t;
    frames.push_back(Transport(frames.back(), t));
  }
  return frames;
}

std::vector<double> ArcFractions(const std::vector<Vec3d>& points) {
  std::vector<double> s(points.size(), 0.0);
  for (std::size_t i = 1; i < points.size(); ++i) {
    s[i] = s[i - 1] + Distance(points[i - 1], points[i]);
  }
  if (s.back() > 0) {
    for (double& v : s) v /= s.back();
  }
  return s;
}

absl::StatusOr<double> CheckedRadius(const RadiusProfile& radius, double t) {
  const double r = radius(t);
  if (!(std::isfinite(r) && r > 0)) {
    return absl::InvalidArgumentError(absl::StrCat("tube radius at t = ", t, " is ", r));
  }
  return r;
}

Ring AddCircleRing(const Vec3d& center, const Frame& f, double r, int sides, TriangleMesh* mesh) {
  Ring ring;
  for (int j = 0; j < sides; ++j) {
    const double a = kTwoPi * j / sides;
    ring.ids.push_back(AddVertex(center + (f.u * std::cos(a) + f.w * std::sin(a)) * r, mesh));
    ring.angles.push_back(a);
  }
  return ring;
}

// A ring of existing vertices with their angles measured about `f` at `center`.
Ring MeasureRing(const std::vector<uint32_t>& ids,
                 const Vec3d& center,
                 const Frame& f,
                 const TriangleMesh& mesh) {
  Ring ring{ids, {}};
  for (uint32_t v : ids) {
    const Vec3d d = Position(mesh, v) - center;
    ring.angles.push_back(std::atan2(Dot(d, f.w), Dot(d, f.u)));
  }
  return ring;
}

// Cumulative counter-clockwise angles of `ring` from `origin`, starting at
// ring.ids[start], one more entry than the ring (back to the start).
std::vector<double> Unwrap(const Ring& ring, std::size_t start, double origin) {
  const std::size_t n = ring.ids.size();
  std::vector<double> u(n + 1);
  u[0] = SignedAngle(ring.angles[start] - origin);
  for (std::size_t k = 1; k <= n; ++k) {
    u[k] =
        u[k - 1] + PositiveAngle(ring.angles[(start + k) % n] - ring.angles[(start + k - 1) % n]);
  }
  return u;
}

// Triangulates the band between rings a and b (both counter-clockwise about
// the tube's direction, a before b) by merging their angle sequences, so any
// two sizes work; equal angle lists give a clean quad strip.
void Zip(const Ring& a, const Ring& b, TriangleMesh* mesh) {
  const std::size_t na = a.ids.size(), nb = b.ids.size();
  std::size_t jb = 0;
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t j = 0; j < nb; ++j) {
    const double d = std::abs(SignedAngle(b.angles[j] - a.angles[0]));
    if (d < best - 1e-12) {
      best = d;
      jb = j;
    }
  }
  const std::vector<double> ua = Unwrap(a, 0, a.angles[0]);
  const std::vector<double> ub = Unwrap(b, jb, a.angles[0]);
  std::size_t i = 0, j = 0;
  while (i < na || j < nb) {
    const uint32_t ai = a.ids[i % na], bj = b.ids[(jb + j) % nb];
    if (j == nb || (i < na && ua[i + 1] <= ub[j + 1])) {
      mesh->triangles.push_back({ai, a.ids[(i + 1) % na], bj});
      ++i;
    } else {
      mesh->triangles.push_back({ai, b.ids[(jb + j + 1) % nb], bj});
      ++j;
    }
  }
}

// Closes a ring with a fan to `apex`; at_end says whether the tube lies before
// the ring (its end) or after it (its start), which fixes the orientation.
void Cap(const Ring& ring, const Vec3d& apex, bool at_end, TriangleMesh* mesh) {
  const uint32_t c = AddVertex(apex, mesh);
  const std::size_t n = ring.ids.size();
  for (std::size_t m = 0; m < n; ++m) {
    const uint32_t p = ring.ids[m], q = ring.ids[(m + 1) % n];
    mesh->triangles.push_back(at_end ? Triangle{p, q, c} : Triangle{q, p, c});
  }
}

struct RimGeometry {
  Vec3d centroid;
  Vec3d normal;  // by the rim's orientation (outwards for a rim from CutHole)
  double mean_radius = 0;
};

absl::StatusOr<RimGeometry> MeasureRim(const std::vector<uint32_t>& rim, const TriangleMesh& mesh) {
  if (rim.size() < 3) {
    return absl::InvalidArgumentError(absl::StrCat("a rim needs 3 vertices, got ", rim.size()));
  }
  RimGeometry g;
  for (uint32_t v : rim) {
    if (v >= mesh.vertices.size()) {
      return absl::InvalidArgumentError(absl::StrCat("rim vertex ", v, " out of range"));
    }
    g.centroid += Position(mesh, v);
  }
  g.centroid = g.centroid / static_cast<double>(rim.size());
  Vec3d area;  // Newell's method: twice the vector area of the polygon
  for (std::size_t m = 0; m < rim.size(); ++m) {
    const Vec3d p = Position(mesh, rim[m]) - g.centroid;
    area += Cross(p, Position(mesh, rim[(m + 1) % rim.size()]) - g.centroid);
    g.mean_radius += Norm(p) / static_cast<double>(rim.size());
  }
  g.normal = Normalized(area);
  if (SquaredNorm(g.normal) == 0 || !(g.mean_radius > 0)) {
    return absl::InvalidArgumentError("rim is degenerate (zero area)");
  }
  return g;
}

}  // namespace

std::vector<uint32_t> VertexGrid::Patch(int row, int col, int height, int width) const {
  const int nr = num_rows(), nc = num_cols();
  if (height < 1 || width < 1 || row < 0 || row + height >= nr) return {};
  if (wrap_cols ? width >= nc : (col < 0 || col + width >= nc)) return {};
  std::vector<uint32_t> ids;
  for (int r = row; r <= row + height; ++r) {
    for (int c = col; c <= col + width; ++c) ids.push_back(rows[r][((c % nc) + nc) % nc]);
  }
  return ids;
}

void VertexGrid::Shift(uint32_t offset) {
  for (auto& row : rows) {
    for (uint32_t& v : row) v += offset;
  }
}

TriangleMesh MakeEllipsoid(const Vec3d& radii, int rings, int sectors, VertexGrid* grid) {
  rings = std::max(rings, 2);
  sectors = std::max(sectors, 3);
  TriangleMesh mesh;
  VertexGrid g{{}, true};
  const uint32_t north = AddVertex({0, 0, radii.z}, &mesh);
  for (int i = 1; i < rings; ++i) {
    const double phi = kPi * i / rings;
    g.rows.emplace_back();
    for (int j = 0; j < sectors; ++j) {
      const double theta = kTwoPi * j / sectors;
      g.rows.back().push_back(AddVertex({radii.x * std::sin(phi) * std::cos(theta),
                                         radii.y * std::sin(phi) * std::sin(theta),
                                         radii.z * std::cos(phi)},
                                        &mesh));
    }
  }
  const uint32_t south = AddVertex({0, 0, -radii.z}, &mesh);
  for (int j = 0; j < sectors; ++j) {
    const int k = (j + 1) % sectors;
    mesh.triangles.push_back({north, g.rows[0][j], g.rows[0][k]});
    for (int i = 0; i + 1 < rings - 1; ++i) {
      const auto &a = g.rows[i], &b = g.rows[i + 1];
      mesh.triangles.push_back({a[j], b[j], b[k]});
      mesh.triangles.push_back({a[j], b[k], a[k]});
    }
    mesh.triangles.push_back({south, g.rows.back()[k], g.rows.back()[j]});
  }
  if (grid != nullptr) *grid = std::move(g);
  return mesh;
}

TriangleMesh MakeBox(const Vec3d& size, double max_edge, std::array<VertexGrid, 6>* faces) {
  std::array<int, 3> n;
  for (int a = 0; a < 3; ++a) {
    n[a] = max_edge > 0 ? std::max(1, static_cast<int>(std::ceil(size[a] / max_edge - 1e-9))) : 1;
  }
  // Surface lattice points are shared by the faces that meet there; the dense
  // id table welds them exactly (no position comparisons).
  std::vector<int64_t> id((n[0] + 1) * (n[1] + 1) * (n[2] + 1), -1);
  TriangleMesh mesh;
  auto vertex = [&](const std::array<int, 3>& l) {
    int64_t& v = id[(l[0] * (n[1] + 1) + l[1]) * (n[2] + 1) + l[2]];
    if (v < 0) {
      v = AddVertex({(static_cast<double>(l[0]) / n[0] - 0.5) * size.x,
                     (static_cast<double>(l[1]) / n[1] - 0.5) * size.y,
                     (static_cast<double>(l[2]) / n[2] - 0.5) * size.z},
                    &mesh);
    }
    return static_cast<uint32_t>(v);
  };
  // (normal axis, side, first in-plane axis p, second q) with e_p x e_q = side * e_axis.
  constexpr int kFaces[6][4] = {
      {0, 1, 1, 2}, {0, 0, 2, 1}, {1, 1, 2, 0}, {1, 0, 0, 2}, {2, 1, 0, 1}, {2, 0, 1, 0}};
  for (int f = 0; f < 6; ++f) {
    const int axis = kFaces[f][0], p = kFaces[f][2], q = kFaces[f][3];
    VertexGrid g;
    for (int r = 0; r <= n[q]; ++r) {
      g.rows.emplace_back();
      for (int c = 0; c <= n[p]; ++c) {
        std::array<int, 3> l;
        l[axis] = kFaces[f][1] ? n[axis] : 0;
        l[p] = c;
        l[q] = r;
        g.rows.back().push_back(vertex(l));
      }
    }
    for (int r = 0; r < n[q]; ++r) {
      for (int c = 0; c < n[p]; ++c) {
        const uint32_t v00 = g.rows[r][c], v10 = g.rows[r][c + 1];
        const uint32_t v11 = g.rows[r + 1][c + 1], v01 = g.rows[r + 1][c];
        mesh.triangles.push_back({v00, v10, v11});
        mesh.triangles.push_back({v00, v11, v01});
      }
    }
    if (faces != nullptr) (*faces)[f] = std::move(g);
  }
  return mesh;
}

TriangleMesh MakeTorus(
    double major, double minor, int major_segments, int minor_segments, VertexGrid* grid) {
  const int nu = std::max(major_segments, 3), nv = std::max(minor_segments, 3);
  TriangleMesh mesh;
  VertexGrid g{{}, true};
  for (int r = 0; r < nu; ++r) {
    const double u = kTwoPi * r / nu;
    g.rows.emplace_back();
    for (int c = 0; c < nv; ++c) {
      const double v = kTwoPi * c / nv, ring = major + minor * std::cos(v);
      g.rows.back().push_back(
          AddVertex({ring * std::cos(u), ring * std::sin(u), minor * std::sin(v)}, &mesh));
    }
  }
  for (int r = 0; r < nu; ++r) {
    const auto &a = g.rows[r], &b = g.rows[(r + 1) % nu];
    for (int c = 0; c < nv; ++c) {
      const int d = (c + 1) % nv;
      mesh.triangles.push_back({a[c], b[c], b[d]});
      mesh.triangles.push_back({a[c], b[d], a[d]});
    }
  }
  if (grid != nullptr) *grid = std::move(g);
  return mesh;
}

absl::StatusOr<TriangleMesh> MakeSurfaceOfRevolution(const std::vector<ProfilePoint>& profile,
                                                     int sectors,
                                                     VertexGrid* grid) {
  const std::size_t n = profile.size();
  if (n < 2) {
    return absl::InvalidArgumentError(absl::StrCat("profile needs 2 points, got ", n));
  }
  for (std::size_t i = 0; i < n; ++i) {
    const ProfilePoint& p = profile[i];
    const bool end = i == 0 || i + 1 == n;
    if (!std::isfinite(p.height) || !std::isfinite(p.radius) || p.radius < 0 ||
        (!end && p.radius == 0)) {
      return absl::InvalidArgumentError(
          absl::StrCat("profile point ", i, " has radius ", p.radius, " and height ", p.height));
    }
  }
  const bool bottom_pole = profile.front().radius == 0, top_pole = profile.back().radius == 0;
  if (n - bottom_pole - top_pole < 1) {
    return absl::InvalidArgumentError("profile has no point of positive radius");
  }
  sectors = std::max(sectors, 3);
  TriangleMesh mesh;
  VertexGrid g{{}, true};
  for (const ProfilePoint& p : profile) {
    if (p.radius == 0) continue;
    g.rows.emplace_back();
    for (int j = 0; j < sectors; ++j) {
      const double theta = kTwoPi * j / sectors;
      g.rows.back().push_back(
          AddVertex({p.radius * std::cos(theta), p.radius * std::sin(theta), p.height}, &mesh));
    }
  }
  for (int j = 0; j < sectors; ++j) {
    const int k = (j + 1) % sectors;
    for (std::size_t i = 0; i + 1 < g.rows.size(); ++i) {
      const auto &a = g.rows[i], &b = g.rows[i + 1];
      mesh.triangles.push_back({a[j], a[k], b[k]});
      mesh.triangles.push_back({a[j], b[k], b[j]});
    }
  }
  if (bottom_pole) {
    const uint32_t pole = AddVertex({0, 0, profile.front().height}, &mesh);
    for (int j = 0; j < sectors; ++j) {
      mesh.triangles.push_back({pole, g.rows.front()[(j + 1) % sectors], g.rows.front()[j]});
    }
  }
  if (top_pole) {
    const uint32_t pole = AddVertex({0, 0, profile.back().height}, &mesh);
    for (int j = 0; j < sectors; ++j) {
      mesh.triangles.push_back({pole, g.rows.back()[j], g.rows.back()[(j + 1) % sectors]});
    }
  }
  if (grid != nullptr) *grid = std::move(g);
  return mesh;
}

absl::StatusOr<TriangleMesh> MakeTube(const std::vector<Vec3d>& path,
                                      const RadiusProfile& radius,
                                      const TubeOptions& options,
                                      VertexGrid* grid) {
  if (path.size() < 2 || options.sides < 3) {
    return absl::InvalidArgumentError(absl::StrCat(
        "a tube needs 2 path points and 3 sides, got ", path.size(), " and ", options.sides));
  }
  Vec3d t0;
  for (std::size_t i = 1; i < path.size() && SquaredNorm(t0) == 0; ++i) {
    t0 = Normalized(path[i] - path[0]);
  }
  if (SquaredNorm(t0) == 0) return absl::InvalidArgumentError("tube path has zero length");
  const std::vector<Frame> frames = FramesAlong(path, MakeFrame(t0, AnyPerpendicular(t0)));
  const std::vector<double> t = ArcFractions(path);
  TriangleMesh mesh;
  VertexGrid g{{}, true};
  std::vector<Ring> rings;
  double r_first = 0, r_last = 0;
  for (std::size_t i = 0; i < path.size(); ++i) {
    auto r = CheckedRadius(radius, t[i]);
    if (!r.ok()) return r.status();
    (i == 0 ? r_first : r_last) = *r;
    rings.push_back(AddCircleRing(path[i], frames[i], *r, options.sides, &mesh));
    if (i > 0) Zip(rings[i - 1], rings[i], &mesh);
    g.rows.push_back(rings.back().ids);
  }
  if (options.cap_start) {
    Cap(rings.front(),
        path.front() - frames.front().t * (options.cap_height * r_first),
        false,
        &mesh);
  }
  if (options.cap_end) {
    Cap(rings.back(), path.back() + frames.back().t * (options.cap_height * r_last), true, &mesh);
  }
  if (grid != nullptr) *grid = std::move(g);
  return mesh;
}

absl::StatusOr<std::vector<uint32_t>> CutHole(const std::vector<uint32_t>& patch,
                                              TriangleMesh* mesh) {
  std::vector<bool> in(mesh->vertices.size(), false);
  for (uint32_t v : patch) {
    if (v >= in.size()) return absl::InvalidArgumentError(absl::StrCat("patch vertex ", v));
    in[v] = true;
  }
  std::vector<bool> removed(mesh->triangles.size(), false);
  std::unordered_set<uint64_t> edges;  // directed edges of the removed triangles
  auto key = [](uint32_t a, uint32_t b) { return (static_cast<uint64_t>(a) << 32) | b; };
  for (std::size_t t = 0; t < mesh->triangles.size(); ++t) {
    const Triangle& tri = mesh->triangles[t];
    if (!(in[tri[0]] && in[tri[1]] && in[tri[2]])) continue;
    removed[t] = true;
    for (int k = 0; k < 3; ++k) edges.insert(key(tri[k], tri[(k + 1) % 3]));
  }
  if (edges.empty()) return absl::InvalidArgumentError("patch selects no triangle");
  std::unordered_map<uint32_t, uint32_t> next;  // rim edges, keyed by their start
  uint32_t start = std::numeric_limits<uint32_t>::max();
  for (uint64_t e : edges) {
    const uint32_t a = static_cast<uint32_t>(e >> 32), b = static_cast<uint32_t>(e);
    if (edges.count(key(b, a)) != 0) continue;
    if (!next.emplace(a, b).second) {
      return absl::InvalidArgumentError(absl::StrCat("patch is pinched at vertex ", a));
    }
    start = std::min(start, a);  // deterministic start, whatever the hash order
  }
  std::vector<uint32_t> rim = {start};
  while (rim.size() <= next.size()) {
    const auto it = next.find(rim.back());
    if (it == next.end() || it->second == start) break;
    rim.push_back(it->second);
  }
  const auto closing = next.find(rim.back());
  if (rim.size() != next.size() || closing == next.end() || closing->second != start) {
    return absl::InvalidArgumentError(
        absl::StrCat("patch is not a disk: its rim has ", next.size(), " edges in several loops"));
  }
  std::size_t kept = 0;
  for (std::size_t t = 0; t < mesh->triangles.size(); ++t) {
    if (!removed[t]) mesh->triangles[kept++] = mesh->triangles[t];
  }
  mesh->triangles.resize(kept);
  return rim;
}

absl::StatusOr<VertexGrid> ExtrudeTube(const std::vector<uint32_t>& rim,
                                       const std::vector<Vec3d>& path,
                                       const RadiusProfile& radius,
                                       const TubeOptions& options,
                                       TriangleMesh* mesh) {
  auto geometry = MeasureRim(rim, *mesh);
  if (!geometry.ok()) return geometry.status();
  if (path.empty() || (!options.keep_rim_shape && options.sides < 3)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "extrusion needs a path and 3 sides, got ", path.size(), " and ", options.sides));
  }
  const RimGeometry& g = *geometry;
  const Frame f0 = MakeFrame(g.normal, Position(*mesh, rim[0]) - g.centroid);
  std::vector<Vec3d> centers = {g.centroid};
  centers.insert(centers.end(), path.begin(), path.end());
  const std::vector<Frame> frames = FramesAlong(centers, f0);
  const std::vector<double> t = ArcFractions(centers);
  Ring previous = MeasureRing(rim, g.centroid, f0, *mesh);
  std::vector<std::array<double, 2>> shape;  // rim offsets in f0, per unit mean radius
  for (uint32_t v : rim) {
    const Vec3d d = (Position(*mesh, v) - g.centroid) / g.mean_radius;
    shape.push_back({Dot(d, f0.u), Dot(d, f0.w)});
  }
  VertexGrid grid{{}, true};
  double r = 0;
  for (std::size_t i = 1; i < centers.size(); ++i) {
    auto ri = CheckedRadius(radius, t[i]);
    if (!ri.ok()) return ri.status();
    r = *ri;
    Ring ring;
    if (options.keep_rim_shape) {
      ring.angles = previous.angles;
      for (const auto& s : shape) {
        ring.ids.push_back(
            AddVertex(centers[i] + (frames[i].u * s[0] + frames[i].w * s[1]) * r, mesh));
      }
    } else {
      ring = AddCircleRing(centers[i], frames[i], r, options.sides, mesh);
    }
    Zip(previous, ring, mesh);
    grid.rows.push_back(ring.ids);
    previous = std::move(ring);
  }
  if (options.cap_end) {
    Cap(previous, centers.back() + frames.back().t * (options.cap_height * r), true, mesh);
  }
  return grid;
}

absl::Status BridgeHoles(const std::vector<uint32_t>& rim_a,
                         const std::vector<uint32_t>& rim_b,
                         const std::vector<Vec3d>& path,
                         const RadiusProfile& radius,
                         int sides,
                         TriangleMesh* mesh) {
  auto a = MeasureRim(rim_a, *mesh);
  if (!a.ok()) return a.status();
  auto b = MeasureRim(rim_b, *mesh);
  if (!b.ok()) return b.status();
  if (path.empty() || sides < 3) {
    return absl::InvalidArgumentError(
        absl::StrCat("a bridge needs a path and 3 sides, got ", path.size(), " and ", sides));
  }
  const Frame f0 = MakeFrame(a->normal, Position(*mesh, rim_a[0]) - a->centroid);
  std::vector<Vec3d> centers = {a->centroid};
  centers.insert(centers.end(), path.begin(), path.end());
  centers.push_back(b->centroid);
  const std::vector<Frame> frames = FramesAlong(centers, f0);
  const std::vector<double> t = ArcFractions(centers);
  Ring previous = MeasureRing(rim_a, a->centroid, f0, *mesh);
  for (std::size_t i = 1; i + 1 < centers.size(); ++i) {
    auto r = CheckedRadius(radius, t[i]);
    if (!r.ok()) return r.status();
    Ring ring = AddCircleRing(centers[i], frames[i], *r, sides, mesh);
    Zip(previous, ring, mesh);
    previous = std::move(ring);
  }
  // rim_b runs counter-clockwise about its own outward normal, which points
  // back along the bridge: reversed, it runs the way the bridge's rings do.
  const std::vector<uint32_t> reversed(rim_b.rbegin(), rim_b.rend());
  Zip(previous, MeasureRing(reversed, b->centroid, frames.back(), *mesh), mesh);
  return absl::OkStatus();
}

std::vector<Vec3d> SmoothPolyline(const std::vector<Vec3d>& points, int iterations) {
  std::vector<Vec3d> p = points;
  for (int it = 0; it < iterations && p.size() > 2; ++it) {
    std::vector<Vec3d> q = {p.front()};
    for (std::size_t i = 0; i + 1 < p.size(); ++i) {
      q.push_back(p[i] * 0.75 + p[i + 1] * 0.25);
      q.push_back(p[i] * 0.25 + p[i + 1] * 0.75);
    }
    q.push_back(p.back());
    p = std::move(q);
  }
  return p;
}

std::vector<Vec3d> ResamplePolyline(const std::vector<Vec3d>& points, double spacing) {
  if (points.size() < 2 || !(spacing > 0)) return points;
  std::vector<double> s(points.size(), 0.0);
  for (std::size_t i = 1; i < points.size(); ++i) {
    s[i] = s[i - 1] + Distance(points[i - 1], points[i]);
  }
  const int n = std::max(1, static_cast<int>(std::lround(s.back() / spacing)));
  std::vector<Vec3d> out = {points.front()};
  std::size_t seg = 0;
  for (int k = 1; k < n; ++k) {
    const double target = s.back() * k / n;
    while (seg + 2 < points.size() && s[seg + 1] < target) ++seg;
    const double len = s[seg + 1] - s[seg];
    const double f = len > 0 ? (target - s[seg]) / len : 0;
    out.push_back(points[seg] * (1 - f) + points[seg + 1] * f);
  }
  out.push_back(points.back());
  return out;
}

uint32_t AppendMesh(const TriangleMesh& part, TriangleMesh* mesh) {
  const uint32_t offset = static_cast<uint32_t>(mesh->vertices.size());
  mesh->vertices.insert(mesh->vertices.end(), part.vertices.begin(), part.vertices.end());
  for (const Triangle& t : part.triangles) {
    mesh->triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  }
  return offset;
}

void RemoveUnreferencedVertices(TriangleMesh* mesh) {
  constexpr uint32_t kUnused = std::numeric_limits<uint32_t>::max();
  std::vector<uint32_t> new_id(mesh->vertices.size(), kUnused);
  for (const Triangle& t : mesh->triangles) {
    for (uint32_t v : t) new_id[v] = 0;
  }
  uint32_t next = 0;
  for (std::size_t v = 0; v < new_id.size(); ++v) {
    if (new_id[v] == kUnused) continue;
    new_id[v] = next;
    mesh->vertices[next++] = mesh->vertices[v];
  }
  mesh->vertices.resize(next);
  for (Triangle& t : mesh->triangles) {
    for (uint32_t& v : t) v = new_id[v];
  }
}

TriangleMesh MakePolygonSoup(const TriangleMesh& mesh) {
  TriangleMesh soup;
  soup.vertices.reserve(3 * mesh.triangles.size());
  for (const Triangle& t : mesh.triangles) {
    const uint32_t base = static_cast<uint32_t>(soup.vertices.size());
    for (uint32_t v : t) soup.vertices.push_back(mesh.vertices[v]);
    soup.triangles.push_back({base, base + 1, base + 2});
  }
  return soup;
}

}  // namespace meshseek
