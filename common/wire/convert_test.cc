#include "common/wire/convert.h"

#include <limits>
#include <string>

#include "common/geometry/test_meshes.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace meshseek::wire {
namespace {

TEST(ConvertTest, MeshRoundTripsExactly) {
  const TriangleMesh cube = testing_meshes::Cube(0.75f);
  v1::MeshInput input;
  MeshToProto(cube, input.mutable_mesh());
  auto back = MeshFromProto(input);
  ASSERT_TRUE(back.ok()) << back.status();
  ASSERT_EQ(back->vertices.size(), cube.vertices.size());
  for (std::size_t i = 0; i < cube.vertices.size(); ++i) {
    EXPECT_EQ(back->vertices[i].x, cube.vertices[i].x);
    EXPECT_EQ(back->vertices[i].z, cube.vertices[i].z);
  }
  EXPECT_EQ(back->triangles, cube.triangles);
}

TEST(ConvertTest, BadMeshesAreInvalidArgumentNamingTheProblem) {
  v1::MeshInput input;
  EXPECT_EQ(MeshFromProto(input).status().code(), absl::StatusCode::kInvalidArgument);
  MeshToProto(testing_meshes::Cube(), input.mutable_mesh());
  input.mutable_mesh()->set_triangles(4, 999);
  const absl::Status out_of_range = MeshFromProto(input).status();
  EXPECT_EQ(out_of_range.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(out_of_range.message().find("999"), std::string::npos) << out_of_range;
  input.mutable_mesh()->add_vertices(1.0f);  // not a multiple of 3
  EXPECT_NE(MeshFromProto(input).status().message().find("multiples of 3"), std::string::npos);
}

TEST(ConvertTest, MeshFileBytesAreReadByTheFileReaders) {
  v1::MeshInput input;
  input.mutable_file()->set_name("tetra.off");
  input.mutable_file()->set_data("OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
                                 "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n");
  auto mesh = MeshFromProto(input);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_EQ(mesh->triangles.size(), 4u);
  input.mutable_file()->set_data("OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 7\n");
  const absl::Status bad = MeshFromProto(input).status();
  EXPECT_FALSE(bad.ok());
  EXPECT_NE(bad.message().find("tetra.off"), std::string::npos) << bad;
  input.mutable_file()->set_name("model.xyz");
  EXPECT_EQ(MeshFromProto(input).status().code(), absl::StatusCode::kInvalidArgument);
}

TEST(ConvertTest, AnOffFileNamedObjWithCommentsBeforeItsHeaderIsReadByItsContent) {
  // What a user's Ingest sends when an exporter wrote OFF under a .obj name:
  // read as OFF (the content decides), not "mesh has no faces".
  v1::MeshInput input;
  input.mutable_file()->set_name("chair.obj");
  input.mutable_file()->set_data("# exported by hand\n\n# second comment\nOFF\n4 4 0\n0 0 0\n"
                                 "1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n");
  auto mesh = MeshFromProto(input);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_EQ(mesh->triangles.size(), 4u);
  // Declared OBJ by the format tag as well: the content still decides.
  input.mutable_file()->set_format(v1::MESH_FORMAT_OBJ);
  EXPECT_TRUE(MeshFromProto(input).ok());
  // A bare OFF header under that name is refused naming the file.
  input.mutable_file()->set_data("OFF\n");
  const absl::Status bare = MeshFromProto(input).status();
  EXPECT_EQ(bare.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(bare.message()), ::testing::HasSubstr("chair.obj"));
}

TEST(ConvertTest, FeaturesRoundTripAndWrongDescriptorSizesAreRejected) {
  LocalFeatures features;
  features.keypoints.resize(2);
  features.keypoints[1].position = Vec3f(1, 2, 3);
  features.keypoints[1].scale = 0.5f;
  features.keypoints[1].level = 7;
  features.descriptors.assign(2 * kSiftDimension, 9);
  v1::LocalFeatures proto;
  FeaturesToProto(features, &proto);
  auto back = FeaturesFromProto(proto);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->descriptors, features.descriptors);
  EXPECT_EQ(back->keypoints[1].position.y, 2.0f);
  EXPECT_EQ(back->keypoints[1].level, 7);
  proto.mutable_descriptors()->pop_back();
  const absl::Status short_descriptors = FeaturesFromProto(proto).status();
  EXPECT_EQ(short_descriptors.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(short_descriptors.message().find("255 descriptor bytes"), std::string::npos)
      << short_descriptors;
  FeaturesToProto(features, &proto);
  proto.set_dimension(64);
  EXPECT_NE(FeaturesFromProto(proto).status().message().find("features of 64 (need 128)"),
            std::string::npos)
      << FeaturesFromProto(proto).status();
  for (uint32_t bad : {0u, 100000u}) {
    proto.set_dimension(bad);
    EXPECT_NE(FeaturesFromProto(proto).status().message().find("descriptor dimension"),
              std::string::npos);
  }
  // Another method's dimension travels as it is.
  LocalFeatures other;
  other.keypoints.resize(3);
  other.dimension = 32;
  other.descriptors.assign(96, 7);
  FeaturesToProto(other, &proto);
  const absl::StatusOr<LocalFeatures> lsf_like = FeaturesFromProto(proto);
  ASSERT_TRUE(lsf_like.ok()) << lsf_like.status();
  EXPECT_EQ(lsf_like->dimension, 32u);
  EXPECT_EQ(lsf_like->descriptors, other.descriptors);
}

TEST(ConvertTest, GraphsAreCheckedOnArrival) {
  PointGraph graph = MakePointGraph({Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(0, 1, 0)},
                                    {{0, 1}, {1, 2}});
  v1::PointGraph proto;
  GraphToProto(graph, &proto);
  auto back = GraphFromProto(proto);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->neighbors, graph.neighbors);
  proto.set_neighbors(0, 5);
  EXPECT_EQ(GraphFromProto(proto).status().code(), absl::StatusCode::kInvalidArgument);
}

TEST(ConvertTest, GraphOffsetsBeyondTheNeighboursAreRefusedBeforeTheyAreRead) {
  // offsets[n] equals the neighbour count, so only the later decrease shows
  // that offsets[1] points past the neighbours: it used to be read first.
  v1::PointGraph proto;
  for (float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f}) proto.add_positions(v);
  for (uint32_t o : {0u, 100u, 1u}) proto.add_offsets(o);
  proto.add_neighbors(1);
  const absl::Status status = GraphFromProto(proto).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(status.message()),
              ::testing::HasSubstr("offsets decrease at point 0 (0 to 100, 1 neighbours)"));
}

TEST(ConvertTest, NonFiniteKeypointsAreRefusedNamingTheKeypoint) {
  LocalFeatures features;
  features.keypoints.resize(2);
  features.keypoints[1].scale = std::numeric_limits<float>::quiet_NaN();
  features.descriptors.assign(2 * kSiftDimension, 1);
  v1::LocalFeatures proto;
  FeaturesToProto(features, &proto);
  EXPECT_THAT(std::string(FeaturesFromProto(proto).status().message()),
              ::testing::HasSubstr("keypoint 1 has a non-finite or negative value"));
  features.keypoints[1].scale = 1;
  features.keypoints[0].view.y = std::numeric_limits<float>::infinity();
  FeaturesToProto(features, &proto);
  EXPECT_THAT(std::string(FeaturesFromProto(proto).status().message()),
              ::testing::HasSubstr("keypoint 0 has"));
}

TEST(ConvertTest, MeshArraysNearTheFloatLimitOrBeyondTheLimitsAreRefused) {
  // Finite coordinates whose area overflows float: ValidateMesh's job, on
  // arrays as on files.
  v1::MeshInput input;
  for (float v : {0.f, 0.f, 0.f, 3.4e38f, 0.f, 0.f, 0.f, 3.4e38f, 0.f}) {
    input.mutable_mesh()->add_vertices(v);
  }
  for (uint32_t i : {0u, 1u, 2u}) input.mutable_mesh()->add_triangles(i);
  const absl::Status big = MeshFromProto(input).status();
  EXPECT_EQ(big.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(big.message()), ::testing::HasSubstr("overflows float"));
  // More vertices than a mesh file may hold (MeshReadOptions::max_vertices).
  input.mutable_mesh()->mutable_vertices()->Resize(3 * ((1 << 25) + 1), 0.0f);
  const absl::Status many = MeshFromProto(input).status();
  EXPECT_EQ(many.code(), absl::StatusCode::kResourceExhausted);
  EXPECT_THAT(std::string(many.message()), ::testing::HasSubstr("(max_vertices)"));
}

TEST(ConvertTest, HistogramsAreSparseAndExact) {
  const std::vector<float> dense = {0.0f, 0.25f, 0.0f, 0.75f};
  v1::SparseHistogram proto;
  HistogramToProto(dense, dense.size(), &proto);
  EXPECT_EQ(proto.bins_size(), 2);
  auto back = SparseHistogramFromProto(proto, "h");
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(DenseFromSparse(*back), dense);
  v1::SparseHistogram again;
  SparseHistogramToProto(*back, &again);
  EXPECT_EQ(again.SerializeAsString(), proto.SerializeAsString());
  HistogramToProto({}, 4, &proto);
  EXPECT_TRUE(SparseHistogramFromProto(proto, "h")->empty());  // a model without features
  proto.add_bins(4);
  proto.add_weights(1.0f);
  EXPECT_EQ(SparseHistogramFromProto(proto, "h").status().code(),
            absl::StatusCode::kInvalidArgument);
  // A declared size of four billion is refused before anything is allocated.
  proto.Clear();
  proto.set_size(4000000000u);
  proto.add_bins(7);
  proto.add_weights(1.0f);
  EXPECT_THAT(std::string(SparseHistogramFromProto(proto, "model 'x'").status().message()),
              ::testing::HasSubstr("model 'x' has vocabulary size 4000000000"));
}

TEST(ConvertTest, NamedValuesAndTheirCanonicalFormReadBackTheSameOptions) {
  v1::PipelineParams params;
  for (const auto& [name, value] : std::vector<std::pair<std::string, std::string>>{
           {"method", "rld"}, {"rld_samples", "5000"}, {"vocabulary", "300"}}) {
    v1::ParamValue* v = params.add_values();
    v->set_name(name);
    v->set_value(value);
  }
  const auto options = PipelineOptionsFromParams(params);
  ASSERT_TRUE(options.ok()) << options.status();
  EXPECT_EQ(options->extractor.rld.num_samples, 5000);
  EXPECT_EQ(options->kmeans.num_centroids, 300);
  v1::PipelineParams canonical;
  PipelineParamsToProto(*options, &canonical);
  EXPECT_GT(canonical.values_size(), 10);
  EXPECT_EQ(canonical.method(), v1::FEATURE_METHOD_UNSPECIFIED);  // legacy fields stay empty
  const auto back = PipelineOptionsFromParams(canonical);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->ToJson().Dump(), options->ToJson().Dump());
  // The same collection written with legacy fields means the same.
  v1::PipelineParams legacy;
  legacy.set_method(v1::FEATURE_METHOD_RLD);
  legacy.set_rld_samples(5000);
  legacy.set_vocabulary(300);
  legacy.set_num_points(64);  // DLD-SIFT's: ignored for RLD-SIFT, as it always was
  const auto old = PipelineOptionsFromParams(legacy);
  ASSERT_TRUE(old.ok()) << old.status();
  EXPECT_EQ(old->ToJson().Dump(), options->ToJson().Dump());
  // A named value that does not apply is an error (it would be ignored).
  v1::ParamValue* wrong = params.add_values();
  wrong->set_name("points");
  wrong->set_value("64");
  EXPECT_NE(PipelineOptionsFromParams(params).status().message().find(
                "params: parameter points does not apply to method rld"),
            std::string::npos);
}

TEST(ConvertTest, UnsetParamsAreTheCoreDefaults) {
  auto options = PipelineOptionsFromParams(v1::PipelineParams());
  ASSERT_TRUE(options.ok()) << options.status();
  EXPECT_EQ(options->ToJson().Dump(), RetrievalPipelineOptions().ToJson().Dump());
  v1::PipelineParams params;
  params.set_method(v1::FEATURE_METHOD_RLD);
  params.set_vocabulary(64);
  params.set_weighted_frame(false);
  options = PipelineOptionsFromParams(params);
  ASSERT_TRUE(options.ok());
  EXPECT_EQ(options->extractor.method, FeatureMethod::kRldSift);
  EXPECT_EQ(options->kmeans.num_centroids, 64);
  EXPECT_FALSE(options->extractor.rld.weighted_frame);
  EXPECT_EQ(options->extractor.rld.scale_space.scale_factor, 15.0);
  EXPECT_EQ(options->extractor.ld.scale_space.scale_factor, 20.0);
  params.set_orientation("sideways");
  EXPECT_NE(PipelineOptionsFromParams(params).status().message().find("sideways"),
            std::string::npos);
}

}  // namespace
}  // namespace meshseek::wire
