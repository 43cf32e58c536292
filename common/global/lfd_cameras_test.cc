#include "common/global/lfd_cameras.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

namespace meshseek {
namespace {

constexpr double kPi = 3.14159265358979323846;

double Determinant(const Rotation3& r) {
  return r[0] * (r[4] * r[8] - r[5] * r[7]) - r[1] * (r[3] * r[8] - r[5] * r[6]) +
         r[2] * (r[3] * r[7] - r[4] * r[6]);
}

void ExpectRotation(const Rotation3& r) {
  EXPECT_NEAR(Determinant(r), 1.0, 1e-12);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      double dot = 0;
      for (int k = 0; k < 3; ++k) dot += r[3 * i + k] * r[3 * j + k];
      EXPECT_NEAR(dot, i == j ? 1.0 : 0.0, 1e-12);
    }
  }
}

TEST(DodecahedronTest, UnitVerticesWithAntipodesAndThreeNeighbours) {
  const auto& v = DodecahedronVertices();
  for (int i = 0; i < 20; ++i) {
    EXPECT_NEAR(Norm(v[i]), 1.0, 1e-15);
    EXPECT_NEAR(Distance(v[i], -v[(i + 10) % 20]), 0.0, 1e-15);
  }
  // Edge: the dodecahedron's circumradius over edge length is
  // sqrt(3) phi / 2, so neighbours are 2 / (sqrt(3) phi) apart.
  const double phi = (1 + std::sqrt(5.0)) / 2;
  const double edge = 2 / (std::sqrt(3.0) * phi);
  for (int i = 0; i < 20; ++i) {
    int neighbours = 0;
    double nearest = 10;
    for (int j = 0; j < 20; ++j) {
      if (j == i) continue;
      nearest = std::min(nearest, Distance(v[i], v[j]));
      if (std::abs(Distance(v[i], v[j]) - edge) < 1e-12) ++neighbours;
    }
    EXPECT_NEAR(nearest, edge, 1e-12);
    EXPECT_EQ(neighbours, 3) << "vertex " << i;
  }
}

TEST(IcosahedralRotationsTest, SixtyDistinctSymmetriesIdentityFirst) {
  const auto& rotations = IcosahedralRotations();
  ASSERT_EQ(rotations.size(), 60u);
  EXPECT_NEAR(RotationAngle(rotations[0]), 0.0, 1e-12);
  for (const Rotation3& r : rotations) ExpectRotation(r);
  for (std::size_t a = 0; a < rotations.size(); ++a) {
    for (std::size_t b = a + 1; b < rotations.size(); ++b) {
      double diff = 0;
      for (int k = 0; k < 9; ++k)
        diff = std::max(diff, std::abs(rotations[a][k] - rotations[b][k]));
      EXPECT_GT(diff, 0.1) << a << " " << b;
    }
  }
  // The group's rotation angles: identity, 15 of pi (2-fold), 20 of 2pi/3
  // (3-fold), 24 of 2pi/5 or 4pi/5 (5-fold).
  int by_order[6] = {};
  for (const Rotation3& r : rotations) {
    const double angle = RotationAngle(r);
    // (acos near pi loses half the digits: compare to 1e-6.)
    if (angle < 1e-6) {
      ++by_order[1];
    } else if (std::abs(angle - kPi) < 1e-6) {
      ++by_order[2];
    } else if (std::abs(angle - 2 * kPi / 3) < 1e-6) {
      ++by_order[3];
    } else if (std::abs(angle - 2 * kPi / 5) < 1e-6 || std::abs(angle - 4 * kPi / 5) < 1e-6) {
      ++by_order[5];
    }
  }
  EXPECT_EQ(by_order[1], 1);
  EXPECT_EQ(by_order[2], 15);
  EXPECT_EQ(by_order[3], 20);
  EXPECT_EQ(by_order[5], 24);
}

TEST(ViewPermutationsTest, ExactlySixtyDistinctPermutationsFormingAGroup) {
  const auto& perms = ViewPermutations();
  ASSERT_EQ(perms.size(), 60u);
  std::set<ViewPermutation> distinct(perms.begin(), perms.end());
  EXPECT_EQ(distinct.size(), 60u);
  ViewPermutation identity;
  for (int i = 0; i < kLfdViewsPerLightField; ++i) identity[i] = static_cast<uint8_t>(i);
  EXPECT_EQ(perms[0], identity);
  for (const ViewPermutation& p : perms) {
    ViewPermutation sorted = p;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(sorted, identity);  // a bijection of the 10 views
  }
  // Closed under composition: q after p is again one of them.
  for (const ViewPermutation& p : perms) {
    for (const ViewPermutation& q : perms) {
      ViewPermutation qp;
      for (int i = 0; i < kLfdViewsPerLightField; ++i) qp[i] = q[p[i]];
      EXPECT_TRUE(distinct.count(qp));
    }
  }
  // And they are what the rotations do to the directions (up to sign).
  const auto dirs = LightFieldViewDirections();
  for (std::size_t g = 0; g < perms.size(); ++g) {
    for (int i = 0; i < kLfdViewsPerLightField; ++i) {
      const Vec3d moved = Rotate(IcosahedralRotations()[g], dirs[i]);
      EXPECT_NEAR(std::abs(Dot(moved, dirs[perms[g][i]])), 1.0, 1e-12);
    }
  }
}

TEST(LightFieldRotationsTest, TenSpreadRotationsIdentityFirstDeterministic) {
  const auto& rotations = LightFieldRotations();
  EXPECT_NEAR(RotationAngle(rotations[0]), 0.0, 1e-15);
  for (const Rotation3& r : rotations) ExpectRotation(r);
  // Farthest-point sampling keeps the camera systems apart: the smallest
  // distance between two of them (the least rotation angle taking one onto
  // the other, modulo the 60 symmetries) is large. The quotient's covering
  // radius is about 37 degrees, so 10 well-spread systems sit 20-odd
  // degrees apart; random ones would come within a few degrees.
  double closest = kPi;
  for (int a = 0; a < kLfdLightFields; ++a) {
    for (int b = a + 1; b < kLfdLightFields; ++b) {
      for (const Rotation3& g : IcosahedralRotations()) {
        // angle of R_a^T R_b g
        Rotation3 rt{};
        for (int i = 0; i < 3; ++i) {
          for (int j = 0; j < 3; ++j) rt[3 * i + j] = rotations[a][3 * j + i];
        }
        closest = std::min(closest, RotationAngle(Compose(Compose(rt, rotations[b]), g)));
      }
    }
  }
  std::printf("closest camera systems: %.2f degrees\n", closest * 180 / kPi);
  EXPECT_GT(closest, 15 * kPi / 180) << closest * 180 / kPi << " degrees";
  // Computed once; the same values every time.
  const auto& again = LightFieldRotations();
  EXPECT_EQ(&rotations, &again);
}

}  // namespace
}  // namespace meshseek
