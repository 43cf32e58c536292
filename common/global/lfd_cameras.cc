#include "common/global/lfd_cameras.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

namespace meshseek {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Columns a, n, a x n of the orthonormal frame of the unit vector a and the
// direction b (not parallel to a).
Rotation3 EdgeFrame(const Vec3d& a, const Vec3d& b) {
  const Vec3d n = Normalized(Cross(a, b));
  const Vec3d m = Cross(a, n);
  return {a.x, n.x, m.x, a.y, n.y, m.y, a.z, n.z, m.z};
}

Rotation3 Transpose(const Rotation3& r) {
  return {r[0], r[3], r[6], r[1], r[4], r[7], r[2], r[5], r[8]};
}

// Index of the vertex at v (unit), or -1 when none is within 1e-6 (the
// rotations are products of a few exact frames: errors stay near 1e-15).
int FindVertex(const std::array<Vec3d, 20>& vertices, const Vec3d& v) {
  for (int i = 0; i < 20; ++i) {
    if (SquaredDistance(vertices[i], v) < 1e-12) return i;
  }
  return -1;
}

// Uniform random rotation from three uniform numbers in [0, 1) (Shoemake,
// "Uniform random rotations", Graphics Gems III).
Rotation3 ShoemakeRotation(double u1, double u2, double u3) {
  const double a = std::sqrt(1 - u1), b = std::sqrt(u1);
  const double w = a * std::sin(2 * kPi * u2), x = a * std::cos(2 * kPi * u2);
  const double y = b * std::sin(2 * kPi * u3), z = b * std::cos(2 * kPi * u3);
  return {1 - 2 * (y * y + z * z),
          2 * (x * y - z * w),
          2 * (x * z + y * w),
          2 * (x * y + z * w),
          1 - 2 * (x * x + z * z),
          2 * (y * z - x * w),
          2 * (x * z - y * w),
          2 * (y * z + x * w),
          1 - 2 * (x * x + y * y)};
}

// Distance between the camera systems R and S: the smallest angle of
// R^T S g over the group (the largest trace, cos = (trace - 1) / 2).
double CameraSystemDistance(const Rotation3& r, const Rotation3& s) {
  const Rotation3 rs = Compose(Transpose(r), s);
  double best = -std::numeric_limits<double>::infinity();
  for (const Rotation3& g : IcosahedralRotations()) {
    // trace(A g) = sum_ij A_ij g_ji.
    double trace = 0;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) trace += rs[3 * i + j] * g[3 * j + i];
    }
    best = std::max(best, trace);
  }
  return std::acos(std::clamp((best - 1) / 2, -1.0, 1.0));
}

}  // namespace

const std::array<Vec3d, 20>& DodecahedronVertices() {
  static const std::array<Vec3d, 20> vertices = [] {
    const double phi = (1 + std::sqrt(5.0)) / 2, iphi = 1 / phi;
    const std::array<Vec3d, 10> half = {Vec3d(1, 1, 1),
                                        Vec3d(1, 1, -1),
                                        Vec3d(1, -1, 1),
                                        Vec3d(1, -1, -1),
                                        Vec3d(0, iphi, phi),
                                        Vec3d(0, iphi, -phi),
                                        Vec3d(iphi, phi, 0),
                                        Vec3d(iphi, -phi, 0),
                                        Vec3d(phi, 0, iphi),
                                        Vec3d(phi, 0, -iphi)};
    std::array<Vec3d, 20> all;
    for (int i = 0; i < 10; ++i) {
      all[i] = Normalized(half[i]);
      all[i + 10] = -all[i];
    }
    return all;
  }();
  return vertices;
}

std::array<Vec3d, kLfdViewsPerLightField> LightFieldViewDirections() {
  std::array<Vec3d, kLfdViewsPerLightField> directions;
  std::copy_n(DodecahedronVertices().begin(), kLfdViewsPerLightField, directions.begin());
  return directions;
}

const std::vector<Rotation3>& IcosahedralRotations() {
  static const std::vector<Rotation3> rotations = [] {
    const std::array<Vec3d, 20>& v = DodecahedronVertices();
    // Neighbours are the vertices nearest to each other (largest dot product
    // below 1): 3 per vertex.
    double edge_dot = -2;
    for (int j = 1; j < 20; ++j) edge_dot = std::max(edge_dot, Dot(v[0], v[j]));
    std::vector<std::vector<int>> neighbours(20);
    for (int i = 0; i < 20; ++i) {
      for (int j = 0; j < 20; ++j) {
        if (i != j && std::abs(Dot(v[i], v[j]) - edge_dot) < 1e-9) neighbours[i].push_back(j);
      }
    }
    const int first = neighbours[0][0];
    const Rotation3 from = Transpose(EdgeFrame(v[0], v[first]));
    std::vector<Rotation3> found;
    for (int i = 0; i < 20; ++i) {
      for (int j : neighbours[i]) {
        const Rotation3 r = Compose(EdgeFrame(v[i], v[j]), from);
        bool maps_onto_itself = true;
        for (int k = 0; k < 20 && maps_onto_itself; ++k) {
          maps_onto_itself = FindVertex(v, Rotate(r, v[k])) >= 0;
        }
        if (maps_onto_itself) found.push_back(r);
      }
    }
    // Identity first (the edge sent onto itself), the rest in discovery order.
    std::stable_partition(
        found.begin(), found.end(), [](const Rotation3& r) { return RotationAngle(r) < 1e-9; });
    return found;
  }();
  return rotations;
}

const std::vector<ViewPermutation>& ViewPermutations() {
  static const std::vector<ViewPermutation> permutations = [] {
    const std::array<Vec3d, 20>& v = DodecahedronVertices();
    std::vector<ViewPermutation> out;
    for (const Rotation3& r : IcosahedralRotations()) {
      ViewPermutation p{};
      for (int i = 0; i < kLfdViewsPerLightField; ++i) {
        // A vertex k and its antipode k + 10 are the same view.
        p[i] = static_cast<uint8_t>(FindVertex(v, Rotate(r, v[i])) % kLfdViewsPerLightField);
      }
      out.push_back(p);
    }
    return out;
  }();
  return permutations;
}

const std::array<Rotation3, kLfdLightFields>& LightFieldRotations() {
  static const std::array<Rotation3, kLfdLightFields> chosen = [] {
    constexpr int kCandidates = 4096;
    std::mt19937_64 rng(2003);
    // 53 random bits to a double in [0, 1), independent of the library's
    // distributions (whose algorithms the standard leaves open).
    auto unit = [&rng] { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };
    std::vector<Rotation3> candidates(kCandidates);
    for (Rotation3& c : candidates) {
      const double u1 = unit(), u2 = unit(), u3 = unit();
      c = ShoemakeRotation(u1, u2, u3);
    }
    std::array<Rotation3, kLfdLightFields> picked;
    picked[0] = IcosahedralRotations()[0];
    std::vector<double> nearest(kCandidates);
    for (int c = 0; c < kCandidates; ++c)
      nearest[c] = CameraSystemDistance(picked[0], candidates[c]);
    for (int k = 1; k < kLfdLightFields; ++k) {
      const int best =
          static_cast<int>(std::max_element(nearest.begin(), nearest.end()) - nearest.begin());
      picked[k] = candidates[best];
      for (int c = 0; c < kCandidates; ++c) {
        nearest[c] = std::min(nearest[c], CameraSystemDistance(picked[k], candidates[c]));
      }
    }
    return picked;
  }();
  return chosen;
}

double RotationAngle(const Rotation3& r) {
  return std::acos(std::clamp((r[0] + r[4] + r[8] - 1) / 2, -1.0, 1.0));
}

Vec3d Rotate(const Rotation3& r, const Vec3d& v) {
  return {r[0] * v.x + r[1] * v.y + r[2] * v.z,
          r[3] * v.x + r[4] * v.y + r[5] * v.z,
          r[6] * v.x + r[7] * v.y + r[8] * v.z};
}

Rotation3 Compose(const Rotation3& a, const Rotation3& b) {
  Rotation3 c{};
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      for (int k = 0; k < 3; ++k) c[3 * i + j] += a[3 * i + k] * b[3 * k + j];
    }
  }
  return c;
}

}  // namespace meshseek
