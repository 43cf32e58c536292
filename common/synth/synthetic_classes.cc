#include "common/synth/synthetic_classes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "common/base/hash.h"
#include "common/base/status_macros.h"
#include "common/synth/shapes.h"

namespace meshseek {

int SynthRandom::UniformInt(int lo, int hi) {
  const uint64_t span = static_cast<uint64_t>(static_cast<int64_t>(hi) - lo) + 1;
  return static_cast<int>(lo + static_cast<int64_t>(engine_() % span));
}

double SynthRandom::Normal() {
  const double u1 = 1.0 - Uniform();  // (0, 1]: log stays finite
  const double u2 = Uniform();
  constexpr double kTwoPi = 6.28318530717958647692;
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(kTwoPi * u2);
}

uint64_t MixSeed(uint64_t a, uint64_t b) {
  uint64_t z = a ^ (b * 0x9e3779b97f4a7c15ULL + 0x632be59bd9b4e019ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

uint64_t HashName(absl::string_view name) { return Fnv1a64(name); }

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kBaseEdge = 0.12;  // target edge length at density 1
const Vec3d kX(1, 0, 0), kY(0, 1, 0), kZ(0, 0, 1);

double Deg(double degrees) { return degrees * kPi / 180; }

// Rotates v about the unit axis by angle (Rodrigues).
Vec3d Rotate(const Vec3d& v, const Vec3d& axis, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return v * c + Cross(axis, v) * s + axis * (Dot(axis, v) * (1 - c));
}

// Unit vector at `azimuth` from +x towards +y and `elevation` above the xy plane.
Vec3d Direction(double azimuth, double elevation) {
  return {std::cos(elevation) * std::cos(azimuth),
          std::cos(elevation) * std::sin(azimuth),
          std::sin(elevation)};
}

// Where the ray from the centre along `dir` leaves the ellipsoid with semi-axes r.
Vec3d EllipsoidPoint(const Vec3d& r, const Vec3d& dir) {
  const Vec3d d = Normalized(dir);
  const double x = d.x / r.x, y = d.y / r.y, z = d.z / r.z;
  return d / std::sqrt(x * x + y * y + z * z);
}

// Piecewise-linear interpolation through (t, value) keys with increasing t.
double Interpolate(const std::vector<std::array<double, 2>>& keys, double t) {
  if (t <= keys.front()[0]) return keys.front()[1];
  for (std::size_t i = 1; i < keys.size(); ++i) {
    if (t <= keys[i][0]) {
      const double f = (t - keys[i - 1][0]) / (keys[i][0] - keys[i - 1][0]);
      return keys[i - 1][1] + f * (keys[i][1] - keys[i - 1][1]);
    }
  }
  return keys.back()[1];
}

// Radius of a neck of length `neck` and radius `neck_r` carrying a ball of
// radius `ball`, at distance s along the axis: heads of humans and teddies.
double NeckAndBall(double s, double neck, double neck_r, double ball) {
  if (s < neck) return neck_r;
  const double d = s - neck - ball;  // from the ball's centre
  const double r = std::sqrt(std::max(0.0, ball * ball - d * d));
  return std::max(d < 0 ? neck_r : 0.12 * ball, r);
}

// A dome: full radius at the base, closing towards the tip (ears, paws).
RadiusProfile Dome(double r, double start = 0.0) {
  return [r, start](double t) {
    const double u = std::max(0.0, (t - start) / (1 - start));
    return r * std::sqrt(std::max(0.03, 1 - u * u));
  };
}

// Collects the parts of one shape. Welded, limbs grow from holes cut into the
// body (one closed surface); unwelded, each limb is a separate capped tube
// that starts inside the body (overlapping components).
class Assembly {
 public:
  explicit Assembly(const SyntheticShapeParams& params) : params_(params) {}

  bool welded() const { return params_.welded; }
  double edge() const { return kBaseEdge / params_.density; }

  // Vertices around a tube of this radius: about square quads, but never
  // fewer than 4 x density (thin limbs of dense models stay round).
  int Sides(double radius) const {
    const int min_sides = std::max(4, static_cast<int>(std::lround(4 * params_.density)));
    return std::clamp(static_cast<int>(std::lround(2 * kPi * radius / edge())), min_sides, 96);
  }
  int Segments(double length, int min_segments) const {
    return std::max(min_segments, static_cast<int>(std::lround(length / edge())));
  }

  // An ellipsoid body with about square quads, at least `min_rings` x `min_sectors`.
  VertexGrid AddEllipsoid(const Vec3d& radii,
                          int min_rings,
                          int min_sectors,
                          const std::array<double, 9>& rotation = {1, 0, 0, 0, 1, 0, 0, 0, 1},
                          const Vec3d& center = {}) {
    const double equator = std::max(radii.x, radii.y);
    VertexGrid grid;
    TriangleMesh part = MakeEllipsoid(radii,
                                      Segments(kPi * (equator + radii.z) / 2, min_rings),
                                      Segments(2 * kPi * equator, min_sectors),
                                      &grid);
    TransformMesh(rotation, 1.0, center, &part);
    return Add(part, std::move(grid));
  }

  VertexGrid Add(const TriangleMesh& part, VertexGrid grid) {
    grid.Shift(AppendMesh(part, &mesh_));
    return grid;
  }

  struct Limb {
    std::vector<Vec3d> joints;  // joints[0] on the body surface
    RadiusProfile radius;       // absolute radius along the limb
    int smoothing = 2;          // Chaikin passes that round the joints
    double hole = 1.4;          // side of the hole cut for it / radius(0)
    bool keep_rim_shape = false;
    int sides = 0;  // 0: Sides() of the largest radius
    double cap_height = 0.6;
    std::vector<uint32_t> patch;  // explicit hole; default: a grid rectangle at joints[0]
  };

  // Adds a limb to `body`; returns the limb's grid, on which further limbs
  // can grow.
  absl::StatusOr<VertexGrid> AddLimb(const VertexGrid& body, const Limb& limb) {
    double r_max = 0;
    for (int i = 0; i <= 20; ++i) r_max = std::max(r_max, limb.radius(i / 20.0));
    TubeOptions options;
    options.sides = limb.sides > 0 ? limb.sides : Sides(r_max);
    options.keep_rim_shape = limb.keep_rim_shape && welded();
    options.cap_start = !welded();
    options.cap_height = limb.cap_height;
    // Rings about as far apart as their vertices, no further than edge(), and
    // at least 5 of them so that short domes (ears, paws) come out round.
    std::vector<Vec3d> path = SmoothPolyline(limb.joints, limb.smoothing);
    double length = 0;
    for (std::size_t i = 1; i < path.size(); ++i) length += Distance(path[i - 1], path[i]);
    path = ResamplePolyline(path,
                            std::min({edge(), 1.5 * 2 * kPi * r_max / options.sides, length / 5}));
    const double r0 = limb.radius(0);
    if (!welded()) {
      path.insert(path.begin(), path[0] - Normalized(path[1] - path[0]) * r0);
      VertexGrid grid;
      MESHSEEK_ASSIGN_OR_RETURN(TriangleMesh tube, MakeTube(path, limb.radius, options, &grid));
      return Add(tube, std::move(grid));
    }
    std::vector<uint32_t> patch = limb.patch;
    if (patch.empty()) {
      MESHSEEK_ASSIGN_OR_RETURN(patch, FreePatch(body, path[0], limb.hole * r0));
    } else if (Overlaps(patch)) {
      return absl::InternalError("explicit limb patch overlaps an earlier hole");
    }
    MESHSEEK_ASSIGN_OR_RETURN(const std::vector<uint32_t> rim, CutHole(patch, &mesh_));
    for (uint32_t v : patch) cut_[v] = true;
    Vec3d centroid;
    double rim_radius = 0;
    for (uint32_t v : rim) centroid += Vec3d(mesh_.vertices[v]) / static_cast<double>(rim.size());
    for (uint32_t v : rim) {
      rim_radius += Distance(Vec3d(mesh_.vertices[v]), centroid) / static_cast<double>(rim.size());
    }
    // The first ring should stand off the hole, not lie in it.
    const double clearance = 0.6 * std::max(r0, rim_radius);
    while (path.size() > 1 && Distance(path.front(), centroid) < clearance) {
      path.erase(path.begin());
    }
    RadiusProfile radius = limb.radius;
    if (options.keep_rim_shape) {  // the hole is the cross-section; radius scales it
      radius = [profile = limb.radius, rim_radius, r0](double t) {
        return rim_radius * profile(t) / r0;
      };
    }
    return ExtrudeTube(rim, path, radius, options, &mesh_);
  }

  // Joins holes in two bodies with a tube (welded), or lays a tube from
  // inside one to inside the other (unwelded).
  absl::Status AddBridge(const VertexGrid& a,
                         const Vec3d& anchor_a,
                         const VertexGrid& b,
                         const Vec3d& anchor_b,
                         const std::vector<Vec3d>& joints,  // anchor_a ... anchor_b
                         double radius) {
    const int sides = Sides(radius);
    std::vector<Vec3d> path = ResamplePolyline(SmoothPolyline(joints, 2),
                                               std::min(edge(), 1.5 * 2 * kPi * radius / sides));
    const RadiusProfile profile = [radius](double) { return radius; };
    if (!welded()) {
      TubeOptions options;
      options.sides = sides;
      MESHSEEK_ASSIGN_OR_RETURN(TriangleMesh tube, MakeTube(path, profile, options));
      AppendMesh(tube, &mesh_);
      return absl::OkStatus();
    }
    MESHSEEK_ASSIGN_OR_RETURN(const std::vector<uint32_t> patch_a,
                              FreePatch(a, anchor_a, 1.4 * radius));
    MESHSEEK_ASSIGN_OR_RETURN(const std::vector<uint32_t> rim_a, CutHole(patch_a, &mesh_));
    for (uint32_t v : patch_a) cut_[v] = true;
    MESHSEEK_ASSIGN_OR_RETURN(const std::vector<uint32_t> patch_b,
                              FreePatch(b, anchor_b, 1.4 * radius));
    MESHSEEK_ASSIGN_OR_RETURN(const std::vector<uint32_t> rim_b, CutHole(patch_b, &mesh_));
    for (uint32_t v : patch_b) cut_[v] = true;
    std::vector<Vec3d> inner;
    for (const Vec3d& p : path) {
      if (Distance(p, anchor_a) > 1.2 * radius && Distance(p, anchor_b) > 1.2 * radius) {
        inner.push_back(p);
      }
    }
    if (inner.empty()) inner.push_back((anchor_a + anchor_b) * 0.5);
    return BridgeHoles(rim_a, rim_b, inner, profile, sides, &mesh_);
  }

  // The vertex ids of the pole `pole` and of as many grid rows next to it
  // (from the top if from_top, else from the bottom) as it takes to open a
  // hole of at least `radius` around the pole: where necks and waists attach.
  std::vector<uint32_t> PolePatch(const VertexGrid& grid,
                                  uint32_t pole,
                                  bool from_top,
                                  double radius) const {
    std::vector<uint32_t> patch = {pole};
    const Vec3d p(mesh_.vertices[pole]);
    for (int k = 0; k + 2 < grid.num_rows(); ++k) {
      const auto& row = grid.rows[from_top ? k : grid.num_rows() - 1 - k];
      patch.insert(patch.end(), row.begin(), row.end());
      Vec3d c;
      for (uint32_t v : row) c += Vec3d(mesh_.vertices[v]) / static_cast<double>(row.size());
      if (Distance(Vec3d(mesh_.vertices[row[0]]), c) >= radius || Distance(c, p) > 2 * radius) {
        break;
      }
    }
    return patch;
  }

  absl::StatusOr<TriangleMesh> Finish() {
    RemoveUnreferencedVertices(&mesh_);
    MESHSEEK_RETURN_IF_ERROR(ValidateMesh(mesh_));
    return std::move(mesh_);
  }

  TriangleMesh& mesh() { return mesh_; }

 private:
  bool Overlaps(const std::vector<uint32_t>& patch) {
    cut_.resize(mesh_.vertices.size(), false);
    for (uint32_t v : patch) {
      if (cut_[v]) return true;
    }
    return false;
  }

  // A rectangle of the grid about `side` across, around the vertex nearest to
  // `anchor`, that shares no vertex with earlier holes (a shared vertex would
  // make the surface non-manifold there): shrunk or nudged if it must be.
  absl::StatusOr<std::vector<uint32_t>> FreePatch(const VertexGrid& grid,
                                                  const Vec3d& anchor,
                                                  double side) {
    if (grid.num_rows() < 2 || grid.num_cols() < 2) {
      return absl::InternalError("a limb needs a body grid of at least 2 x 2 vertices");
    }
    int row = 0, col = 0;
    double best = std::numeric_limits<double>::infinity();
    for (int r = 0; r < grid.num_rows(); ++r) {
      for (int c = 0; c < grid.num_cols(); ++c) {
        const double d = SquaredDistance(Vec3d(mesh_.vertices[grid.rows[r][c]]), anchor);
        if (d < best) {
          best = d;
          row = r;
          col = c;
        }
      }
    }
    auto spacing = [&](int r1, int c1) {
      const int nc = grid.num_cols();
      if (r1 < 0 || r1 >= grid.num_rows()) return 0.0;
      if (!grid.wrap_cols && (c1 < 0 || c1 >= nc)) return 0.0;
      return Distance(Vec3d(mesh_.vertices[grid.rows[row][col]]),
                      Vec3d(mesh_.vertices[grid.rows[r1][((c1 % nc) + nc) % nc]]));
    };
    auto quads = [&](double a, double b, int limit) {
      const double q = std::max(a, b) > 0 ? std::max(a, b) : edge();
      return std::clamp(static_cast<int>(std::lround(side / q)), 1, std::max(1, limit));
    };
    const int max_rows = grid.num_rows() - 1;
    const int max_cols = grid.wrap_cols ? grid.num_cols() / 2 - 1 : grid.num_cols() - 1;
    const int kr = quads(spacing(row - 1, col), spacing(row + 1, col), max_rows);
    const int kc = quads(spacing(row, col - 1), spacing(row, col + 1), max_cols);
    constexpr int kNudges[9][2] = {
        {0, 0}, {0, 1}, {0, -1}, {1, 0}, {-1, 0}, {0, 2}, {0, -2}, {2, 0}, {-2, 0}};
    for (int shrink = 0; shrink < std::max(kr, kc); ++shrink) {
      const int h = std::max(1, kr - shrink), w = std::max(1, kc - shrink);
      for (const auto& nudge : kNudges) {
        int r0 = std::clamp(row - h / 2 + nudge[0], 0, grid.num_rows() - 1 - h);
        int c0 = col - w / 2 + nudge[1];
        if (!grid.wrap_cols) c0 = std::clamp(c0, 0, grid.num_cols() - 1 - w);
        const std::vector<uint32_t> patch = grid.Patch(r0, c0, h, w);
        if (!patch.empty() && !Overlaps(patch)) return patch;
      }
    }
    return absl::InternalError(
        absl::StrCat("no room on the body for a limb of size ", side, " at x = ", anchor.x));
  }

  SyntheticShapeParams params_;
  TriangleMesh mesh_;
  std::vector<bool> cut_;  // vertices of earlier holes
};

// ---------------------------------------------------------------------------
// Classes.

// A tube along a random sinuous centre line: head bulge, neck, long tapering
// tail. Varies in length, thickness, number and amplitude of bends, head lift.
absl::StatusOr<TriangleMesh> MakeSnake(const SyntheticShapeParams& params, SynthRandom* rng) {
  Assembly as(params);
  const double length = rng->Uniform(3.0, 5.0);
  const double r = length * rng->Uniform(0.022, 0.035);
  const int n = rng->UniformInt(6, 9);
  const double waves = rng->Uniform(0.8, 2.2);
  const double amplitude = length * rng->Uniform(0.05, 0.16);
  const double phase = rng->Uniform(0, 2 * kPi);
  const double lift = rng->Bernoulli(0.4) ? rng->Uniform(0.1, 0.4) : 0.0;
  std::vector<Vec3d> control;
  for (int i = 0; i < n; ++i) {
    const double s = static_cast<double>(i) / (n - 1);
    control.push_back({s * length,
                       amplitude * (std::sin(2 * kPi * waves * s + phase) + 0.15 * rng->Normal()),
                       0.1 * amplitude * rng->Normal() + (i == 0 ? lift : 0.0)});
  }
  const std::vector<std::array<double, 2>> keys = {
      {0, 0.75}, {0.03, 1.15}, {0.07, 1.2}, {0.11, 0.85}, {0.2, 1.0}, {0.55, 1.0}, {1, 0.12}};
  TubeOptions options;
  options.sides = as.Sides(1.2 * r);
  options.cap_height = 0.8;
  const std::vector<Vec3d> path = ResamplePolyline(
      SmoothPolyline(control, 4), std::min(as.edge(), 3 * kPi * r / options.sides));
  // Unwelded: the body in 2 or 3 overlapping pieces, each capped.
  const int pieces = as.welded() ? 1 : rng->UniformInt(2, 3);
  const int last = static_cast<int>(path.size()) - 1;
  int begin = 0;
  for (int k = 0; k < pieces; ++k) {
    int end = k + 1 == pieces ? last : (last * (k + 1)) / pieces + rng->UniformInt(-2, 2);
    end = std::clamp(end, begin + 2, last);
    const int from = std::max(0, begin - (k > 0 ? 2 : 0));
    const std::vector<Vec3d> piece(path.begin() + from, path.begin() + end + 1);
    const double t0 = static_cast<double>(from) / last, t1 = static_cast<double>(end) / last;
    const RadiusProfile radius = [&keys, r, t0, t1](double t) {
      return r * Interpolate(keys, t0 + (t1 - t0) * t);
    };
    MESHSEEK_ASSIGN_OR_RETURN(TriangleMesh tube, MakeTube(piece, radius, options));
    AppendMesh(tube, &as.mesh());
    begin = end;
    if (begin >= last) break;
  }
  return as.Finish();
}

// An egg-shaped mantle with eight tapering arms that leave it downwards and
// curl towards their tips. Varies in mantle shape, arm length, droop and curl.
absl::StatusOr<TriangleMesh> MakeOctopus(const SyntheticShapeParams& params, SynthRandom* rng) {
  Assembly as(params);
  const double a = rng->Uniform(0.3, 0.4);
  const Vec3d mantle{a, a * rng->Uniform(0.85, 1.0), a * rng->Uniform(1.1, 1.5)};
  const VertexGrid body = as.AddEllipsoid(mantle, 12, 24);
  const double base_azimuth = rng->Uniform(0, 2 * kPi);
  const double arm_r = a * rng->Uniform(0.2, 0.26);
  for (int i = 0; i < 8; ++i) {
    const double az = base_azimuth + 2 * kPi * i / 8 + rng->Uniform(-0.08, 0.08);
    const double polar = Deg(rng->Uniform(110, 130));
    const Vec3d anchor = EllipsoidPoint(
        mantle, {std::sin(polar) * std::cos(az), std::sin(polar) * std::sin(az), std::cos(polar)});
    const Vec3d radial(std::cos(az), std::sin(az), 0);
    const double droop = Deg(rng->Uniform(15, 70));
    Vec3d heading = radial * std::cos(droop) - kZ * std::sin(droop);
    const Vec3d axis = Normalized(Cross(heading, kZ) + radial * rng->Uniform(-0.5, 0.5));
    // Curvature grows along the arm: a bend near the base, a curl at the tip.
    const double length = a * rng->Uniform(3.0, 5.0);
    const double bend = Deg(rng->Uniform(-60, 90)), curl = Deg(rng->Uniform(90, 360));
    const double k0 = bend / length, k1 = 3 * curl / length * (rng->Bernoulli(0.5) ? 1 : -1);
    std::vector<Vec3d> joints = {anchor};
    constexpr int kSteps = 40;
    for (int k = 0; k < kSteps; ++k) {
      const double s = (k + 0.5) / kSteps;
      joints.push_back(joints.back() + heading * (length / kSteps));
      heading = Rotate(heading, axis, (k0 + k1 * s * s) * length / kSteps);
    }
    Assembly::Limb arm;
    arm.joints = std::move(joints);
    arm.smoothing = 0;
    arm.radius = [arm_r](double t) { return arm_r * (1 - 0.88 * t); };
    arm.cap_height = 1.5;
    MESHSEEK_RETURN_IF_ERROR(as.AddLimb(body, arm).status());
  }
  return as.Finish();
}

// A cephalothorax with an egg-shaped abdomen behind a thin waist and eight
// thin legs with knees, each at its own random joint angles.
absl::StatusOr<TriangleMesh> MakeSpider(const SyntheticShapeParams& params, SynthRandom* rng) {
  Assembly as(params);
  const Vec3d head{rng->Uniform(0.26, 0.32), rng->Uniform(0.2, 0.25), rng->Uniform(0.13, 0.17)};
  // Built about z, then turned so that the poles point front (+x) and back.
  const std::array<double, 9> z_to_x = {0, 0, 1, 0, 1, 0, -1, 0, 0};
  const VertexGrid body = as.AddEllipsoid({head.z, head.y, head.x}, 20, 12, z_to_x);
  const uint32_t rear_pole = static_cast<uint32_t>(as.mesh().vertices.size() - 1);

  const double abdomen_r = rng->Uniform(0.22, 0.32), waist = 0.35 * head.z;
  const double lift = Deg(rng->Uniform(0, 25));
  Assembly::Limb abdomen;
  const Vec3d rear(-head.x, 0, 0);
  abdomen.joints = {rear,
                    rear + Vec3d(-std::cos(lift), 0, std::sin(lift)) * rng->Uniform(0.5, 0.75)};
  abdomen.smoothing = 0;
  abdomen.radius = [abdomen_r, waist](double t) {
    const double s = std::clamp((t - 0.08) / 0.92, 0.0, 1.0);
    const double bulb = abdomen_r * std::sqrt(std::max(0.0, std::sin(kPi * s)));
    return std::max(t < 0.15 ? waist : 0.1 * abdomen_r, bulb);
  };
  abdomen.patch =
      as.welded() ? as.PolePatch(body, rear_pole, false, waist) : std::vector<uint32_t>{};
  MESHSEEK_RETURN_IF_ERROR(as.AddLimb(body, abdomen).status());

  const double leg_r = rng->Uniform(0.028, 0.038);
  constexpr double kLegAzimuth[4] = {40, 72, 104, 136};
  for (const int side : {1, -1}) {
    for (int i = 0; i < 4; ++i) {
      const double az = side * Deg(kLegAzimuth[i] + rng->Uniform(-6, 6));
      const Vec3d anchor = EllipsoidPoint(head, {std::cos(az), std::sin(az), -0.1});
      const Vec3d out(std::cos(az), std::sin(az), 0);
      const double scale = (i == 0 || i == 3) ? 1.1 : 1.0;
      const double e1 = Deg(rng->Uniform(25, 65)), e2 = -Deg(rng->Uniform(35, 75));
      const double e3 = -Deg(rng->Uniform(60, 90));
      const Vec3d hip = anchor + out * 0.06;
      const Vec3d knee =
          hip + (out * std::cos(e1) + kZ * std::sin(e1)) * (scale * rng->Uniform(0.35, 0.5));
      const Vec3d ankle =
          knee + (out * std::cos(e2) + kZ * std::sin(e2)) * (scale * rng->Uniform(0.45, 0.6));
      const Vec3d foot =
          ankle + (out * std::cos(e3) + kZ * std::sin(e3)) * (scale * rng->Uniform(0.2, 0.3));
      Assembly::Limb leg;
      leg.joints = {anchor, hip, knee, ankle, foot};
      leg.radius = [leg_r](double t) { return leg_r * (1 - 0.5 * t); };
      leg.cap_height = 1.0;
      MESHSEEK_RETURN_IF_ERROR(as.AddLimb(body, leg).status());
    }
  }
  return as.Finish();
}

// A torso with a neck and round head, two arms and two legs, posed at random
// shoulder, elbow, hip and knee angles (standing, walking, sitting, waving).
absl::StatusOr<TriangleMesh> MakeHumanoid(const SyntheticShapeParams& params, SynthRandom* rng) {
  Assembly as(params);
  const Vec3d torso{rng->Uniform(0.12, 0.16), rng->Uniform(0.2, 0.26), rng->Uniform(0.36, 0.44)};
  const VertexGrid body = as.AddEllipsoid(torso, 10, 12);
  const double neck = rng->Uniform(0.06, 0.1), neck_r = rng->Uniform(0.045, 0.06);
  const double head_r = rng->Uniform(0.11, 0.14);
  const double nod = Deg(rng->Uniform(-20, 25)), tilt = Deg(rng->Uniform(-15, 15));
  const Vec3d head_dir = Rotate(Rotate(kZ, kY, nod), kX, tilt);
  const Vec3d top(0, 0, torso.z);
  Assembly::Limb head;
  const double head_len = neck + 2 * head_r;
  head.joints = {top, top + head_dir * head_len};
  head.smoothing = 0;
  head.radius = [=](double t) { return NeckAndBall(t * head_len, neck, neck_r, head_r); };
  head.cap_height = 0.3;
  head.patch = as.welded() ? as.PolePatch(body, 0, true, neck_r) : std::vector<uint32_t>{};
  MESHSEEK_RETURN_IF_ERROR(as.AddLimb(body, head).status());

  for (const int side : {1, -1}) {
    // Arm: abduction swings it out sideways, flexion forwards, then the elbow bends.
    const Vec3d shoulder = EllipsoidPoint(torso, {0, side * 0.9, 0.55});
    Vec3d upper = Rotate(-kZ, kX, side * Deg(rng->Uniform(10, 140)));
    upper = Rotate(upper, kY, -Deg(rng->Uniform(-40, 80)));
    Vec3d forward = kX - upper * Dot(kX, upper);
    forward = SquaredNorm(forward) > 1e-6 ? Normalized(forward) : kZ;
    const double elbow_angle = Deg(rng->Uniform(0, 110));
    const Vec3d fore = upper * std::cos(elbow_angle) + forward * std::sin(elbow_angle);
    const Vec3d out = shoulder + Vec3d(0, side * 0.04, 0);
    const Vec3d elbow = out + upper * rng->Uniform(0.28, 0.34);
    Assembly::Limb arm;
    arm.joints = {shoulder, out, elbow, elbow + fore * rng->Uniform(0.26, 0.32)};
    arm.radius = [](double t) {
      return Interpolate({{0, 0.058}, {0.5, 0.047}, {0.85, 0.038}, {0.93, 0.046}, {1, 0.035}}, t);
    };
    MESHSEEK_RETURN_IF_ERROR(as.AddLimb(body, arm).status());

    // Leg: hip flexion forwards (up to sitting), abduction, knee bends back.
    const Vec3d hip = EllipsoidPoint(torso, {0, side * 0.45, -0.9});
    Vec3d thigh = Rotate(-kZ, kX, side * Deg(rng->Uniform(0, 30)));
    thigh = Rotate(thigh, kY, -Deg(rng->Uniform(-25, 95)));
    Vec3d back = -kX + thigh * Dot(kX, thigh);
    back = SquaredNorm(back) > 1e-6 ? Normalized(back) : -kZ;
    const double knee_angle = Deg(rng->Uniform(0, 110));
    const Vec3d shin = thigh * std::cos(knee_angle) + back * std::sin(knee_angle);
    Vec3d foot = kX - shin * Dot(kX, shin);
    foot = SquaredNorm(foot) > 1e-6 ? Normalized(foot) : kX;
    const Vec3d knee = hip + thigh * rng->Uniform(0.42, 0.5);
    const Vec3d ankle = knee + shin * rng->Uniform(0.4, 0.46);
    Assembly::Limb leg;
    leg.joints = {hip, hip + thigh * 0.05, knee, ankle, ankle + foot * rng->Uniform(0.12, 0.16)};
    leg.radius = [](double t) { return 0.085 - 0.04 * t; };
    MESHSEEK_RETURN_IF_ERROR(as.AddLimb(body, leg).status());
  }
  return as.Finish();
}

// A fat body, a big round head on a short neck with two round ears and a
// muzzle, and four stubby rounded limbs at random angles.
absl::StatusOr<TriangleMesh> MakeTeddy(const SyntheticShapeParams& params, SynthRandom* rng) {
  Assembly as(params);
  const Vec3d belly{rng->Uniform(0.36, 0.42), rng->Uniform(0.38, 0.44), rng->Uniform(0.48, 0.56)};
  const VertexGrid body = as.AddEllipsoid(belly, 12, 16);
  const double neck = rng->Uniform(0.0, 0.05), neck_r = rng->Uniform(0.16, 0.22);
  const double head_r = rng->Uniform(0.3, 0.36);
  const double nod = Deg(rng->Uniform(-15, 15)), tilt = Deg(rng->Uniform(-15, 15));
  const Vec3d head_dir = Rotate(Rotate(kZ, kY, nod), kX, tilt);
  const Vec3d top(0, 0, belly.z);
  const double head_len = neck + 2 * head_r;
  Assembly::Limb head;
  head.joints = {top, top + head_dir * head_len};
  head.smoothing = 0;
  head.radius = [=](double t) { return NeckAndBall(t * head_len, neck, neck_r, head_r); };
  head.cap_height = 0.3;
  head.patch = as.welded() ? as.PolePatch(body, 0, true, neck_r) : std::vector<uint32_t>{};
  MESHSEEK_ASSIGN_OR_RETURN(const VertexGrid head_grid, as.AddLimb(body, head));
  const Vec3d head_center = top + head_dir * (neck + 0.8 * head_r);

  const Vec3d side_dir = Normalized(Cross(head_dir, kX));  // +y when upright
  const double ear_r = rng->Uniform(0.1, 0.13);
  for (const int side : {1, -1}) {
    const Vec3d dir = Normalized(head_dir * 0.75 + side_dir * (side * 0.7));
    const Vec3d anchor = head_center + dir * head_r;
    Assembly::Limb ear;
    ear.joints = {anchor, anchor + dir * (ear_r * rng->Uniform(0.9, 1.3))};
    ear.smoothing = 0;
    ear.radius = Dome(ear_r);
    ear.cap_height = 0.2;
    MESHSEEK_RETURN_IF_ERROR(as.AddLimb(head_grid, ear).status());
  }
  const Vec3d snout_dir = Normalized(Cross(side_dir, head_dir) - head_dir * 0.35);
  const Vec3d snout = head_center + snout_dir * head_r;
  Assembly::Limb muzzle;
  muzzle.joints = {snout, snout + snout_dir * rng->Uniform(0.1, 0.15)};
  muzzle.smoothing = 0;
  muzzle.radius = Dome(rng->Uniform(0.1, 0.13));
  muzzle.cap_height = 0.2;
  MESHSEEK_RETURN_IF_ERROR(as.AddLimb(head_grid, muzzle).status());

  for (const int side : {1, -1}) {
    const Vec3d shoulder = EllipsoidPoint(belly, {0.1, side * 1.0, 0.35});
    const Vec3d arm_dir = Normalized(
        Vec3d{rng->Uniform(-0.2, 0.8), side * rng->Uniform(0.5, 1.0), rng->Uniform(-0.9, 0.5)});
    Assembly::Limb arm;
    arm.joints = {shoulder, shoulder + arm_dir * rng->Uniform(0.3, 0.42)};
    arm.smoothing = 0;
    arm.radius = Dome(rng->Uniform(0.11, 0.14), 0.6);
    arm.cap_height = 0.2;
    MESHSEEK_RETURN_IF_ERROR(as.AddLimb(body, arm).status());

    const Vec3d hip = EllipsoidPoint(belly, {0.35, side * 0.55, -0.75});
    const double down = Deg(rng->Uniform(0, 60));
    const Vec3d leg_dir =
        Normalized(Vec3d{std::cos(down), side * rng->Uniform(0.1, 0.4), -std::sin(down)});
    Assembly::Limb leg;
    leg.joints = {hip, hip + leg_dir * rng->Uniform(0.35, 0.48)};
    leg.smoothing = 0;
    leg.radius = Dome(rng->Uniform(0.14, 0.17), 0.65);
    leg.cap_height = 0.2;
    MESHSEEK_RETURN_IF_ERROR(as.AddLimb(body, leg).status());
  }
  return as.Finish();
}

// Two levers crossing at a hinge, each a short tapered jaw and a long bowed
// handle; the opening angle, lengths and bows vary.
absl::StatusOr<TriangleMesh> MakePliers(const SyntheticShapeParams& params, SynthRandom* rng) {
  Assembly as(params);
  const double hinge_r = rng->Uniform(0.12, 0.15);
  const Vec3d hinge(hinge_r, hinge_r, rng->Uniform(0.06, 0.08));
  const VertexGrid body = as.AddEllipsoid(hinge, 8, 12);
  const double opening = Deg(rng->Uniform(4, 45));
  const double jaw_len = rng->Uniform(0.3, 0.45), handle_len = rng->Uniform(0.75, 1.05);
  const double jaw_r = rng->Uniform(0.04, 0.055), handle_r = rng->Uniform(0.04, 0.05);
  const double jaw_bend = Deg(rng->Uniform(0, 15));
  for (const int s : {1, -1}) {  // the upper lever, then the lower one
    const double elevation = s * Deg(35);
    const double jaw_az = s * opening / 2, handle_az = kPi + s * opening / 2;
    const Vec3d out = Direction(jaw_az, 0);
    const Vec3d jaw_anchor = EllipsoidPoint(hinge, Direction(jaw_az, elevation));
    const Vec3d p1 = out * (hinge_r + 0.06) + kZ * (s * 0.2 * hinge.z);
    const Vec3d p2 = p1 + out * (0.5 * jaw_len);
    Assembly::Limb jaw;
    jaw.joints = {jaw_anchor, p1, p2, p2 + Rotate(out, kZ, -s * jaw_bend) * (0.5 * jaw_len)};
    jaw.radius = [jaw_r](double t) { return jaw_r * (1 - 0.65 * t); };
    jaw.cap_height = 1.2;
    MESHSEEK_RETURN_IF_ERROR(as.AddLimb(body, jaw).status());

    const Vec3d hout = Direction(handle_az, 0);
    const Vec3d away = Cross(kZ, hout) * s;  // away from the other handle
    const double bow = rng->Uniform(0.0, 0.12), flare = rng->Uniform(0.0, 0.1);
    const Vec3d handle_anchor = EllipsoidPoint(hinge, Direction(handle_az, elevation));
    const Vec3d q1 = hout * (hinge_r + 0.08) + kZ * (s * 0.2 * hinge.z);
    Assembly::Limb handle;
    handle.joints = {handle_anchor,
                     q1,
                     q1 + hout * (0.5 * handle_len) + away * bow,
                     q1 + hout * handle_len + away * (0.6 * bow + flare)};
    handle.radius = [handle_r](double t) {
      return handle_r *
             Interpolate({{0, 1.0}, {0.2, 0.85}, {0.5, 1.12}, {0.93, 1.12}, {1, 0.7}}, t);
    };
    handle.cap_height = 0.8;
    MESHSEEK_RETURN_IF_ERROR(as.AddLimb(body, handle).status());
  }
  return as.Finish();
}

// Two oval rims joined by an arched bridge, with two temples that may be open
// or folded at random angles and bend down at the ear. Unwelded models also
// get lenses.
absl::StatusOr<TriangleMesh> MakeSpectacles(const SyntheticShapeParams& params, SynthRandom* rng) {
  Assembly as(params);
  const double rim_R = rng->Uniform(0.3, 0.4), wire = rng->Uniform(0.022, 0.035);
  const double sx = rng->Uniform(1.0, 1.35), sz = rng->Uniform(0.75, 1.0);
  const double gap = rng->Uniform(0.12, 0.25), cx = sx * rim_R + gap / 2;
  // Torus plane xy -> lens plane xz, stretched into an oval: (x, y, z) -> (sx x, -z, sz y).
  const std::array<double, 9> to_front = {sx, 0, 0, 0, 0, -1, 0, sz, 0};
  const int major = as.Segments(2 * kPi * rim_R * (sx + sz) / 2, 16);
  std::array<VertexGrid, 2> rims;
  std::array<Vec3d, 2> centers = {Vec3d(cx, 0, 0), Vec3d(-cx, 0, 0)};
  for (int k = 0; k < 2; ++k) {
    VertexGrid grid;
    TriangleMesh torus = MakeTorus(rim_R, wire, major, as.Sides(wire), &grid);
    TransformMesh(to_front, 1.0, centers[k], &torus);
    rims[k] = as.Add(torus, std::move(grid));
  }
  // The point of rim k at angle u in its own plane, on the wire's surface
  // (offset 1) or its centre line (offset 0).
  auto rim_point = [&](int k, double u, double offset) {
    return centers[k] + Vec3d(sx * std::cos(u), 0, sz * std::sin(u)) * (rim_R + offset * wire);
  };
  const double bridge_u = Deg(rng->Uniform(0, 25)), arch = rng->Uniform(0.02, 0.1);
  const double surface = as.welded() ? 1 : 0;  // unwelded parts start inside the wire
  const Vec3d a = rim_point(0, kPi - bridge_u, surface), b = rim_point(1, bridge_u, surface);
  MESHSEEK_RETURN_IF_ERROR(as.AddBridge(rims[0],
                                        a,
                                        rims[1],
                                        b,
                                        {a, (a + b) * 0.5 + Vec3d(0, -0.02, arch), b},
                                        wire * rng->Uniform(0.8, 1.0)));

  const double temple_r = wire * rng->Uniform(0.7, 0.9), temple_u = Deg(rng->Uniform(5, 25));
  const double temple_len = rng->Uniform(0.9, 1.2);
  for (int k = 0; k < 2; ++k) {
    const double side = k == 0 ? 1 : -1;
    const Vec3d anchor = rim_point(k, k == 0 ? temple_u : kPi - temple_u, 1);
    const Vec3d out(side, 0, 0);
    // 90 degrees: open, straight back (+y); towards 170: folded behind the lenses.
    const double fold = Deg(rng->Bernoulli(0.6) ? rng->Uniform(85, 100) : rng->Uniform(100, 170));
    const Vec3d dir = out * std::cos(fold) + kY * std::sin(fold);
    const double ear = Deg(rng->Uniform(15, 45));
    const Vec3d hinge = anchor + out * 0.04;
    const Vec3d bend = hinge + dir * (0.75 * temple_len);
    Assembly::Limb temple;
    temple.joints = {anchor,
                     hinge,
                     bend,
                     bend + (dir * std::cos(ear) - kZ * std::sin(ear)) * (0.25 * temple_len)};
    temple.radius = [temple_r](double t) {
      return temple_r * Interpolate({{0, 1.0}, {0.8, 1.0}, {0.9, 1.25}, {1, 1.0}}, t);
    };
    temple.cap_height = 0.8;
    MESHSEEK_RETURN_IF_ERROR(as.AddLimb(rims[k], temple).status());
  }
  if (!as.welded()) {  // lenses: thin discs filling the rims
    for (int k = 0; k < 2; ++k) {
      as.AddEllipsoid(
          {sx * rim_R, 0.012, sz * rim_R}, 8, 16, {1, 0, 0, 0, 1, 0, 0, 0, 1}, centers[k]);
    }
  }
  return as.Finish();
}

// A flat box top on four legs, square or round, straight or splayed, tapered
// or not; proportions and leg length vary.
absl::StatusOr<TriangleMesh> MakeTable(const SyntheticShapeParams& params, SynthRandom* rng) {
  Assembly as(params);
  const double lx = rng->Uniform(1.2, 2.0), ly = lx * rng->Uniform(0.45, 0.8);
  const double thickness = rng->Uniform(0.04, 0.08);
  std::array<VertexGrid, 6> faces;
  // At least 6 quads across, so that four legs always find disjoint holes.
  const TriangleMesh top = MakeBox({lx, ly, thickness}, std::min(as.edge(), ly / 6), &faces);
  const VertexGrid bottom = as.Add(top, faces[5]);
  const double width = rng->Uniform(0.07, 0.13), inset = rng->Uniform(0.04, 0.15) + width / 2;
  const double height = rng->Uniform(0.55, 1.0), splay = Deg(rng->Uniform(0, 12));
  const double taper = rng->Uniform(0.55, 1.0);
  const bool square = rng->Bernoulli(0.6);
  for (const int sx : {1, -1}) {
    for (const int sy : {1, -1}) {
      const Vec3d anchor(sx * (lx / 2 - inset), sy * (ly / 2 - inset), -thickness / 2);
      const Vec3d dir = Normalized(Vec3d{sx * std::sin(splay) / std::sqrt(2.0),
                                         sy * std::sin(splay) / std::sqrt(2.0),
                                         -std::cos(splay)});
      Assembly::Limb leg;
      leg.joints = {anchor, anchor + dir * height};
      leg.smoothing = 0;
      leg.radius = [width, taper](double t) { return width / 2 * (1 + (taper - 1) * t); };
      leg.hole = 2.0;  // the hole is the leg's cross-section
      leg.keep_rim_shape = square;
      leg.sides = square && !as.welded() ? 4 : 0;
      leg.cap_height = 0;  // flat feet
      MESHSEEK_RETURN_IF_ERROR(as.AddLimb(bottom, leg).status());
    }
  }
  return as.Finish();
}

// An open surface of revolution (no thickness, open at the top) through a
// random base, belly, neck and lip, slightly bent and squashed. Unwelded
// models get a handle.
absl::StatusOr<TriangleMesh> MakeVase(const SyntheticShapeParams& params, SynthRandom* rng) {
  Assembly as(params);
  const double height = rng->Uniform(1.0, 2.0);
  const double base = rng->Uniform(0.2, 0.35), belly = rng->Uniform(0.35, 0.6);
  const double neck = rng->Uniform(0.12, 0.3), lip = neck * rng->Uniform(1.0, 1.6);
  const std::vector<Vec3d> control = {{0, 0, 0},
                                      {base, 0, 0},
                                      {belly, 0, height * rng->Uniform(0.25, 0.5)},
                                      {neck, 0, height * rng->Uniform(0.7, 0.85)},
                                      {lip, 0, height}};
  const std::vector<Vec3d> outline = ResamplePolyline(SmoothPolyline(control, 3), as.edge());
  std::vector<ProfilePoint> profile;
  for (const Vec3d& p : outline) profile.push_back({p.x, p.z});
  MESHSEEK_ASSIGN_OR_RETURN(const TriangleMesh vase,
                            MakeSurfaceOfRevolution(profile, as.Sides(belly)));
  AppendMesh(vase, &as.mesh());
  if (!as.welded()) {
    auto radius_at = [&](double z) {
      for (std::size_t i = 1; i < profile.size(); ++i) {
        if (profile[i].height >= z) return profile[i].radius;
      }
      return profile.back().radius;
    };
    const double z1 = height * rng->Uniform(0.6, 0.8), z2 = height * rng->Uniform(0.25, 0.45);
    const double r1 = radius_at(z1), r2 = radius_at(z2), reach = rng->Uniform(0.2, 0.3);
    const double handle_r = rng->Uniform(0.025, 0.04);
    TubeOptions options;
    options.sides = as.Sides(handle_r);
    MESHSEEK_ASSIGN_OR_RETURN(TriangleMesh handle,
                              MakeTube(
                                  ResamplePolyline(SmoothPolyline({{r1 - 0.02, 0, z1},
                                                                   {r1 + reach, 0, z1 + 0.03},
                                                                   {r2 + reach, 0, z2 + 0.05},
                                                                   {r2 - 0.02, 0, z2}},
                                                                  3),
                                                   as.edge() / 2),
                                  [handle_r](double) { return handle_r; },
                                  options));
    AppendMesh(handle, &as.mesh());
  }
  const double bend = rng->Uniform(-0.12, 0.12) / height, squash = rng->Uniform(0.8, 1.0);
  for (Vec3f& v : as.mesh().vertices) {
    v.x += static_cast<float>(bend * v.z * v.z);
    v.y *= static_cast<float>(squash);
  }
  return as.Finish();
}

}  // namespace

const std::vector<SyntheticClass>& SyntheticClasses() {
  static const std::vector<SyntheticClass> kClasses = {
      {"snake", "tube along a random sinuous curve; head bulge, tapering tail", MakeSnake},
      {"octopus", "egg-shaped mantle with eight tapering, curling arms", MakeOctopus},
      {"spider", "body, abdomen behind a waist, eight thin jointed legs", MakeSpider},
      {"humanoid", "torso, head on a neck, jointed arms and legs in random poses", MakeHumanoid},
      {"teddy", "fat body, big head with ears and muzzle, four stubby limbs", MakeTeddy},
      {"pliers", "two levers crossing at a hinge: tapered jaws, bowed handles", MakePliers},
      {"spectacles", "two oval rims, arched bridge, temples open or folded", MakeSpectacles},
      {"table", "box top on four square or round, straight or splayed legs", MakeTable},
      {"vase", "open surface of revolution: base, belly, neck and lip", MakeVase},
  };
  return kClasses;
}

std::vector<std::string> SyntheticClassNames() {
  std::vector<std::string> names;
  for (const SyntheticClass& c : SyntheticClasses()) names.push_back(c.name);
  return names;
}

}  // namespace meshseek
