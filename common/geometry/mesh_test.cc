#include "common/geometry/mesh.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "common/geometry/test_meshes.h"

namespace meshseek {
namespace {

using ::testing::HasSubstr;

std::string ValidationError(const TriangleMesh& mesh) {
  const absl::Status status = ValidateMesh(mesh);
  return status.ok() ? "OK" : std::string(status.message());
}

TEST(ValidateMeshTest, AcceptsAnOrdinaryMesh) {
  EXPECT_EQ(ValidationError(testing_meshes::Cube()), "OK");
}

TEST(ValidateMeshTest, CoordinatesNearTheFloatLimitWhoseAreaOverflowsAreRefused) {
  // Every coordinate is a finite float and the extent (3.4e38) is too, but
  // the area (5.8e76) is not a float: every algorithm would see infinity.
  TriangleMesh mesh;
  mesh.vertices = {Vec3f(0, 0, 0), Vec3f(3.4e38f, 0, 0), Vec3f(0, 3.4e38f, 0)};
  mesh.triangles = {{0, 1, 2}};
  EXPECT_THAT(ValidationError(mesh), HasSubstr("total surface area 5.78e+76 overflows float"));
  // Opposite signs overflow the extent even where the area is small.
  mesh.vertices = {Vec3f(-3e38f, 0, 0), Vec3f(3e38f, 0, 0), Vec3f(0, 1e-30f, 0)};
  EXPECT_THAT(ValidationError(mesh), HasSubstr("bounding box extent (6e+38, 1e-30, 0) overflows"));
}

TEST(ValidateMeshTest, NamesTheNonFiniteVertexAndTheBadIndex) {
  TriangleMesh mesh = testing_meshes::Cube();
  mesh.vertices[5].y = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THAT(ValidationError(mesh), HasSubstr("vertex 5 has a non-finite coordinate"));
  mesh = testing_meshes::Cube();
  mesh.vertices[2].z = -std::numeric_limits<float>::infinity();
  EXPECT_THAT(ValidationError(mesh), HasSubstr("vertex 2 has a non-finite coordinate"));
  mesh = testing_meshes::Cube();
  mesh.triangles[3][1] = 99;
  EXPECT_THAT(ValidationError(mesh), HasSubstr("triangle 3 references vertex 99 but the mesh has 8"));
}

TEST(ValidateMeshTest, NoFacesAndZeroAreaAreRefused) {
  TriangleMesh mesh;
  mesh.vertices = {Vec3f(0, 0, 0)};
  EXPECT_THAT(ValidationError(mesh), HasSubstr("mesh has no faces (1 vertices)"));
  mesh.vertices = {Vec3f(0, 0, 0), Vec3f(1, 1, 1), Vec3f(2, 2, 2)};
  mesh.triangles = {{0, 1, 2}};
  EXPECT_THAT(ValidationError(mesh), HasSubstr("zero total surface area"));
}

}  // namespace
}  // namespace meshseek
