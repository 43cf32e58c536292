#include "common/synth/synthetic_benchmark.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "common/geometry/principal_axes.h"
#include "common/synth/synthetic_classes.h"

namespace meshseek {
namespace {

namespace fs = std::filesystem;

std::string ReadFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// A fresh, empty folder under the test's temporary directory.
std::string FreshDir(const std::string& name) {
  const fs::path dir = fs::path(testing::TempDir()) / ("synth_" + name);
  fs::remove_all(dir);
  return dir.string();
}

// Relative path -> contents of every file under `dir`.
std::map<std::string, std::string> Snapshot(const std::string& dir) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    if (entry.is_regular_file()) {
      files[fs::relative(entry.path(), dir).string()] = ReadFile(entry.path());
    }
  }
  return files;
}

TEST(SyntheticBenchmarkOptionsTest, DefaultsArePinnedAndValid) {
  const SyntheticBenchmarkOptions o;
  EXPECT_TRUE(o.Validate().ok()) << o.Validate();
  EXPECT_EQ(o.models_per_class, 8);
  EXPECT_EQ(o.seed, 1u);
  EXPECT_EQ(o.soup_fraction, 0.125);
  EXPECT_EQ(o.multi_component_fraction, 0.25);
  EXPECT_EQ(o.min_density, 1.0);
  EXPECT_EQ(o.max_density, 3.0);
  EXPECT_TRUE(o.random_pose);
  EXPECT_EQ(o.min_scale, 0.5);
  EXPECT_EQ(o.max_scale, 2.0);
  EXPECT_EQ(o.max_translation, 5.0);
  EXPECT_TRUE(o.classes.empty());
}

TEST(SyntheticBenchmarkOptionsTest, RejectsBadValues) {
  const std::vector<std::pair<const char*, void (*)(SyntheticBenchmarkOptions*)>> cases = {
      {"models_per_class", [](SyntheticBenchmarkOptions* o) { o->models_per_class = 0; }},
      {"models_per_class", [](SyntheticBenchmarkOptions* o) { o->models_per_class = 20000; }},
      {"soup_fraction", [](SyntheticBenchmarkOptions* o) { o->soup_fraction = -0.1; }},
      {"soup_fraction", [](SyntheticBenchmarkOptions* o) { o->soup_fraction = std::nan(""); }},
      {"multi_component_fraction",
       [](SyntheticBenchmarkOptions* o) { o->multi_component_fraction = 1.5; }},
      {"must not exceed 1",
       [](SyntheticBenchmarkOptions* o) {
         o->soup_fraction = 0.6;
         o->multi_component_fraction = 0.6;
       }},
      {"min_density", [](SyntheticBenchmarkOptions* o) { o->min_density = 0; }},
      {"max_density", [](SyntheticBenchmarkOptions* o) { o->max_density = 0.5; }},
      {"max_density", [](SyntheticBenchmarkOptions* o) { o->max_density = 11; }},
      {"min_scale", [](SyntheticBenchmarkOptions* o) { o->min_scale = 0; }},
      {"max_scale", [](SyntheticBenchmarkOptions* o) { o->max_scale = 0.1; }},
      {"max_translation", [](SyntheticBenchmarkOptions* o) { o->max_translation = -1; }},
      {"unknown class",
       [](SyntheticBenchmarkOptions* o) {
         o->classes = {"snake", "cat"};
       }},
      {"listed twice",
       [](SyntheticBenchmarkOptions* o) {
         o->classes = {"vase", "vase"};
       }},
  };
  for (const auto& [message, mutate] : cases) {
    SyntheticBenchmarkOptions o;
    mutate(&o);
    const absl::Status status = o.Validate();
    EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument) << message;
    EXPECT_NE(status.message().find(message), absl::string_view::npos) << status;
    EXPECT_FALSE(MakeSyntheticModels(o).ok());
  }
}

class SyntheticModelsTest : public testing::Test {
 protected:
  static void SetUpTestSuite() {
    auto models = MakeSyntheticModels(SyntheticBenchmarkOptions());
    ASSERT_TRUE(models.ok()) << models.status();
    models_ = new std::vector<SyntheticModel>(*std::move(models));
  }
  static void TearDownTestSuite() { delete models_; }
  void SetUp() override { ASSERT_NE(models_, nullptr) << "generation failed"; }
  static std::vector<SyntheticModel>* models_;
};
std::vector<SyntheticModel>* SyntheticModelsTest::models_ = nullptr;

TEST_F(SyntheticModelsTest, CountsLabelsAndIds) {
  const std::vector<std::string> classes = SyntheticClassNames();
  ASSERT_EQ(models_->size(), classes.size() * 8);
  for (std::size_t i = 0; i < models_->size(); ++i) {
    const SyntheticModel& m = (*models_)[i];
    EXPECT_EQ(m.id, std::to_string(i));
    EXPECT_EQ(m.label, classes[i / 8]);  // grouped by class, in class order
    EXPECT_TRUE(ValidateMesh(m.mesh).ok()) << m.id << ": " << ValidateMesh(m.mesh);
  }
}

TEST_F(SyntheticModelsTest, SoupsAndMultiComponentModelsShowInTheTopology) {
  std::map<std::string, int> soups, multis;
  for (const SyntheticModel& m : *models_) {
    const MeshTopologyStats stats = ComputeTopologyStats(m.mesh);
    if (m.is_soup) {
      ++soups[m.label];
      EXPECT_FALSE(m.is_multi_component);
      EXPECT_EQ(m.mesh.vertices.size(), 3 * m.mesh.triangles.size()) << m.id;
      EXPECT_EQ(stats.components, m.mesh.triangles.size()) << m.id;
    } else if (m.is_multi_component) {
      ++multis[m.label];
      EXPECT_GT(stats.components, 1u) << m.id;
    } else {
      EXPECT_EQ(stats.components, 1u) << m.id;
      EXPECT_EQ(stats.non_manifold_edges, 0u) << m.id;
    }
  }
  for (const std::string& name : SyntheticClassNames()) {
    EXPECT_EQ(soups[name], 1) << name;   // round(0.125 * 8)
    EXPECT_EQ(multis[name], 2) << name;  // round(0.25 * 8)
  }
}

TEST_F(SyntheticModelsTest, TessellationDensityVariesWithinEachClass) {
  std::map<std::string, std::pair<std::size_t, std::size_t>> range;  // min, max triangles
  for (const SyntheticModel& m : *models_) {
    auto [it, inserted] = range.try_emplace(m.label, m.mesh.triangles.size(), 0);
    it->second.first = std::min(it->second.first, m.mesh.triangles.size());
    it->second.second = std::max(it->second.second, m.mesh.triangles.size());
  }
  std::size_t fewest = SIZE_MAX, most = 0;
  for (const auto& [name, r] : range) {
    EXPECT_GE(r.second, 4 * r.first) << name << ": " << r.first << " to " << r.second;
    fewest = std::min(fewest, r.first);
    most = std::max(most, r.second);
  }
  EXPECT_LT(fewest, 1000u);  // a few hundred vertices
  EXPECT_GT(most, 8000u);    // several thousand
}

TEST_F(SyntheticModelsTest, PosesAreRandom) {
  // First principal axes of the models of one class point every which way
  // (the mean |cos| of random directions is 0.5); without random poses, the
  // long axis of a table is the same in every model.
  SyntheticBenchmarkOptions canonical;
  canonical.random_pose = false;
  canonical.classes = {"table"};
  auto aligned = MakeSyntheticModels(canonical);
  ASSERT_TRUE(aligned.ok());
  auto mean_abs_cos = [](const std::vector<SyntheticModel>& models, const std::string& label) {
    std::vector<Vec3d> axes;
    for (const SyntheticModel& m : models) {
      if (m.label == label) axes.push_back(ComputePrincipalAxes(m.mesh.vertices).axes[0]);
    }
    double sum = 0;
    int pairs = 0;
    for (std::size_t i = 0; i < axes.size(); ++i) {
      for (std::size_t j = i + 1; j < axes.size(); ++j, ++pairs) {
        sum += std::abs(Dot(axes[i], axes[j]));
      }
    }
    return sum / pairs;
  };
  EXPECT_GT(mean_abs_cos(*aligned, "table"), 0.95);
  for (const std::string& name : SyntheticClassNames()) {
    EXPECT_LT(mean_abs_cos(*models_, name), 0.8) << name;
  }
  // Scale and position vary too.
  std::set<float> extents;
  for (const SyntheticModel& m : *models_) {
    float lo = m.mesh.vertices[0].x, hi = lo;
    for (const Vec3f& v : m.mesh.vertices) lo = std::min(lo, v.x), hi = std::max(hi, v.x);
    extents.insert(hi - lo);
    EXPECT_LT(std::abs(lo + hi) / 2, 5 + 2.0f);  // translation within the box
  }
  EXPECT_EQ(extents.size(), models_->size());
}

TEST_F(SyntheticModelsTest, ClassSelectionKeepsIdsAndShapes) {
  SyntheticBenchmarkOptions some;
  some.classes = {"vase", "snake"};
  auto selected = MakeSyntheticModels(some);
  ASSERT_TRUE(selected.ok());
  ASSERT_EQ(selected->size(), 16u);
  for (const SyntheticModel& m : *selected) {
    const SyntheticModel& full = (*models_)[std::stoul(m.id)];
    EXPECT_EQ(m.label, full.label);
    EXPECT_EQ(m.mesh.vertices, full.mesh.vertices);
    EXPECT_EQ(m.format, full.format);
  }
  EXPECT_EQ(selected->front().label, "snake");  // class order, not list order
}

TEST_F(SyntheticModelsTest, SameOptionsSameModelsOtherSeedOtherModels) {
  auto again = MakeSyntheticModels(SyntheticBenchmarkOptions());
  SyntheticBenchmarkOptions other;
  other.seed = 2;
  auto different = MakeSyntheticModels(other);
  ASSERT_TRUE(again.ok() && different.ok());
  for (std::size_t i = 0; i < models_->size(); ++i) {
    EXPECT_EQ((*again)[i].mesh.vertices, (*models_)[i].mesh.vertices);
    EXPECT_EQ((*again)[i].mesh.triangles, (*models_)[i].mesh.triangles);
    EXPECT_NE((*different)[i].mesh.vertices, (*models_)[i].mesh.vertices);
  }
}

TEST(GenerateSyntheticBenchmarkTest, WritesModelsManifestAndClassFile) {
  const std::string dir = FreshDir("files");
  ASSERT_TRUE(GenerateSyntheticBenchmark(SyntheticBenchmarkOptions(), dir).ok());
  auto models = MakeSyntheticModels(SyntheticBenchmarkOptions());
  ASSERT_TRUE(models.ok());
  const std::vector<std::string> classes = SyntheticClassNames();

  // Manifest: header, then one row per model in order.
  std::string expected_manifest = "id,class,path\n";
  for (const SyntheticModel& m : *models) {
    expected_manifest += m.id + "," + m.label + "," + m.RelativePath() + "\n";
  }
  EXPECT_EQ(ReadFile(fs::path(dir) / "manifest.csv"), expected_manifest);

  // Class file: PSB 1, counts, then each class with its ids.
  std::istringstream cla(ReadFile(fs::path(dir) / "synthetic.cla"));
  std::string magic, version;
  std::size_t num_classes = 0, num_models = 0;
  cla >> magic >> version >> num_classes >> num_models;
  EXPECT_EQ(magic + " " + version, "PSB 1");
  EXPECT_EQ(num_classes, classes.size());
  EXPECT_EQ(num_models, models->size());
  for (std::size_t c = 0; c < classes.size(); ++c) {
    std::string name;
    int parent = -1;
    std::size_t count = 0;
    cla >> name >> parent >> count;
    EXPECT_EQ(name, classes[c]);
    EXPECT_EQ(parent, 0);
    ASSERT_EQ(count, 8u);
    for (std::size_t k = 0; k < count; ++k) {
      std::string id;
      cla >> id;
      EXPECT_EQ(id, std::to_string(c * 8 + k));
    }
  }

  // Every model reads back with its triangles and area; all encodings occur.
  std::set<std::pair<MeshFormat, bool>> encodings;
  uintmax_t bytes = 0;
  for (const SyntheticModel& m : *models) {
    const std::string path = dir + "/" + m.RelativePath();
    bytes += fs::file_size(path);
    encodings.insert({m.format, m.format != MeshFormat::kObj && m.binary});
    MeshReadReport report;
    absl::StatusOr<TriangleMesh> read = ReadMesh(path, &report);
    ASSERT_TRUE(read.ok()) << read.status();
    EXPECT_EQ(read->triangles.size(), m.mesh.triangles.size()) << path;
    EXPECT_NEAR(SurfaceArea(*read), SurfaceArea(m.mesh), 1e-6 * SurfaceArea(m.mesh)) << path;
    EXPECT_EQ(report.faces_dropped, 0u) << path;
    if (m.format != MeshFormat::kStl) {  // STL readers merge coincident vertices
      EXPECT_EQ(read->vertices, m.mesh.vertices) << path;
    } else if (!m.is_soup) {
      EXPECT_EQ(report.topology.components, ComputeTopologyStats(m.mesh).components) << path;
    }
  }
  EXPECT_EQ(encodings.size(), 7u);  // OFF, PLY, STL x ASCII, binary; OBJ
  EXPECT_LT(bytes, 15u << 20);      // the benchmark stays small
}

TEST(GenerateSyntheticBenchmarkTest, IsByteForByteDeterministic) {
  SyntheticBenchmarkOptions options;
  options.models_per_class = 3;
  const std::string a = FreshDir("a"), b = FreshDir("b"), c = FreshDir("c");
  ASSERT_TRUE(GenerateSyntheticBenchmark(options, a).ok());
  ASSERT_TRUE(GenerateSyntheticBenchmark(options, b).ok());
  options.seed = 99;
  ASSERT_TRUE(GenerateSyntheticBenchmark(options, c).ok());
  const auto first = Snapshot(a), second = Snapshot(b), other = Snapshot(c);
  EXPECT_EQ(first.size(), 9u * 3 + 2);
  EXPECT_TRUE(first == second);
  ASSERT_EQ(first.size(), other.size());
  for (const auto& [name, contents] : first) {
    if (name.rfind("models", 0) == 0) {
      EXPECT_NE(contents, other.at(name)) << name;
    }
  }
}

TEST(GenerateSyntheticBenchmarkTest, ReportsUnwritableFolders) {
  const std::string dir = FreshDir("blocked");
  fs::create_directories(dir);
  std::ofstream(fs::path(dir) / "models") << "a file where the folder should be";
  EXPECT_FALSE(GenerateSyntheticBenchmark(SyntheticBenchmarkOptions(), dir).ok());
  SyntheticBenchmarkOptions bad;
  bad.models_per_class = 0;
  EXPECT_EQ(GenerateSyntheticBenchmark(bad, FreshDir("bad")).code(),
            absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace meshseek
