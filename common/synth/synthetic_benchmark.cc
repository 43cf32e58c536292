#include "common/synth/synthetic_benchmark.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <limits>
#include <set>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "common/base/status_macros.h"
#include "common/eval/class_file.h"
#include "common/eval/manifest.h"
#include "common/synth/shapes.h"
#include "common/synth/synthetic_classes.h"

namespace meshseek {
namespace {

struct FileFormat {
  MeshFormat format;
  bool binary;
};

// One slot per model, cycling with the model's position. Eight slots, so that
// with 8 models per class every class gets each slot once; ASCII STL (about
// 200 bytes per triangle) gets one slot so that the benchmark stays small.
constexpr FileFormat kFormatCycle[8] = {{MeshFormat::kOff, false},
                                        {MeshFormat::kPly, true},
                                        {MeshFormat::kObj, false},
                                        {MeshFormat::kStl, true},
                                        {MeshFormat::kOff, true},
                                        {MeshFormat::kPly, false},
                                        {MeshFormat::kStl, false},
                                        {MeshFormat::kObj, false}};

// Independent random streams derived from a model's seed.
enum Stream : uint64_t { kShapeStream = 1, kPoseStream = 2, kClassStream = 3 };

const char* Extension(MeshFormat format) {
  switch (format) {
    case MeshFormat::kOff:
      return "off";
    case MeshFormat::kObj:
      return "obj";
    case MeshFormat::kPly:
      return "ply";
    case MeshFormat::kStl:
      return "stl";
  }
  return "off";
}

// Uniformly random rotation: a normalised 4-D Gaussian vector is a uniformly
// random unit quaternion.
std::array<double, 9> RandomRotation(SynthRandom* rng) {
  double w, x, y, z, n;
  do {
    w = rng->Normal(), x = rng->Normal(), y = rng->Normal(), z = rng->Normal();
    n = std::sqrt(w * w + x * x + y * y + z * z);
  } while (n < 1e-6);
  w /= n, x /= n, y /= n, z /= n;
  return {1 - 2 * (y * y + z * z),
          2 * (x * y - w * z),
          2 * (x * z + w * y),
          2 * (x * y + w * z),
          1 - 2 * (x * x + z * z),
          2 * (y * z - w * x),
          2 * (x * z - w * y),
          2 * (y * z + w * x),
          1 - 2 * (x * x + y * y)};
}

// Centres the bounding box at the origin and scales its diagonal to 2, so
// that the pose's scale means the same for every class.
void NormalizeSize(TriangleMesh* mesh) {
  Vec3d lo(std::numeric_limits<double>::infinity(),
           std::numeric_limits<double>::infinity(),
           std::numeric_limits<double>::infinity());
  Vec3d hi = -lo;
  for (const Vec3f& v : mesh->vertices) {
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], static_cast<double>(v[a]));
      hi[a] = std::max(hi[a], static_cast<double>(v[a]));
    }
  }
  const double diagonal = Distance(lo, hi);
  const double s = diagonal > 0 ? 2 / diagonal : 1;
  TransformMesh({1, 0, 0, 0, 1, 0, 0, 0, 1}, s, (lo + hi) * (-0.5 * s), mesh);
}

std::vector<int> Permutation(int n, SynthRandom* rng) {
  std::vector<int> p(n);
  for (int i = 0; i < n; ++i) p[i] = i;
  for (int i = n - 1; i > 0; --i) std::swap(p[i], p[rng->UniformInt(0, i)]);
  return p;
}

int CountOf(double fraction, int n) { return static_cast<int>(std::floor(fraction * n + 0.5)); }

absl::Status CheckRange(const char* name, double value, double lo, double hi) {
  if (!(value >= lo && value <= hi)) {
    return absl::InvalidArgumentError(
        absl::StrCat(name, " must be in [", lo, ", ", hi, "], got ", value));
  }
  return absl::OkStatus();
}

}  // namespace

absl::Status SyntheticBenchmarkOptions::Validate() const {
  if (models_per_class < 1 || models_per_class > 10000) {
    return absl::InvalidArgumentError(
        absl::StrCat("models_per_class must be in [1, 10000], got ", models_per_class));
  }
  MESHSEEK_RETURN_IF_ERROR(CheckRange("soup_fraction", soup_fraction, 0, 1));
  MESHSEEK_RETURN_IF_ERROR(CheckRange("multi_component_fraction", multi_component_fraction, 0, 1));
  if (soup_fraction + multi_component_fraction > 1 + 1e-12) {
    return absl::InvalidArgumentError(
        absl::StrCat("soup_fraction + multi_component_fraction must not exceed 1, got ",
                     soup_fraction,
                     " + ",
                     multi_component_fraction));
  }
  MESHSEEK_RETURN_IF_ERROR(CheckRange("min_density", min_density, 0.1, 10));
  MESHSEEK_RETURN_IF_ERROR(CheckRange("max_density", max_density, min_density, 10));
  MESHSEEK_RETURN_IF_ERROR(CheckRange("min_scale", min_scale, 1e-6, 1e6));
  MESHSEEK_RETURN_IF_ERROR(CheckRange("max_scale", max_scale, min_scale, 1e6));
  MESHSEEK_RETURN_IF_ERROR(CheckRange("max_translation", max_translation, 0, 1e6));
  const std::vector<std::string> known = SyntheticClassNames();
  std::set<std::string> seen;
  for (const std::string& name : classes) {
    if (std::find(known.begin(), known.end(), name) == known.end()) {
      return absl::InvalidArgumentError(
          absl::StrCat("unknown class '", name, "'; known: ", absl::StrJoin(known, ", ")));
    }
    if (!seen.insert(name).second) {
      return absl::InvalidArgumentError(absl::StrCat("class '", name, "' listed twice"));
    }
  }
  return absl::OkStatus();
}

std::string SyntheticModel::RelativePath() const {
  return absl::StrCat("models/", id, ".", Extension(format));
}

absl::StatusOr<std::vector<SyntheticModel>> MakeSyntheticModels(
    const SyntheticBenchmarkOptions& options) {
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  const int n = options.models_per_class;
  const int soups = CountOf(options.soup_fraction, n);
  const int multis = std::min(CountOf(options.multi_component_fraction, n), n - soups);
  const std::vector<SyntheticClass>& classes = SyntheticClasses();
  std::vector<SyntheticModel> models;
  for (std::size_t c = 0; c < classes.size(); ++c) {
    const std::string name = classes[c].name;
    if (!options.classes.empty() &&
        std::find(options.classes.begin(), options.classes.end(), name) == options.classes.end()) {
      continue;
    }
    const uint64_t class_seed = MixSeed(options.seed, HashName(name));
    // Per class: which density stratum and which role (soup, unwelded, plain)
    // each model gets, so that every class spans the density range and has
    // its share of soups and multi-component models.
    SynthRandom class_rng(MixSeed(class_seed, kClassStream));
    const std::vector<int> stratum = Permutation(n, &class_rng);
    const std::vector<int> role = Permutation(n, &class_rng);
    for (int k = 0; k < n; ++k) {
      const uint64_t model_seed = MixSeed(class_seed, static_cast<uint64_t>(k));
      SynthRandom shape_rng(MixSeed(model_seed, kShapeStream));
      SynthRandom pose_rng(MixSeed(model_seed, kPoseStream));
      SyntheticModel model;
      const std::size_t position = c * n + k;  // independent of options.classes
      model.id = absl::StrCat(position);
      model.label = name;
      model.is_soup = role[k] < soups;
      model.is_multi_component = !model.is_soup && role[k] < soups + multis;
      model.format = kFormatCycle[position % 8].format;
      model.binary = kFormatCycle[position % 8].binary;
      SyntheticShapeParams params;
      const double q = (stratum[k] + pose_rng.Uniform()) / n;
      params.density = options.min_density * std::pow(options.max_density / options.min_density, q);
      params.welded = !model.is_multi_component;
      absl::StatusOr<TriangleMesh> mesh = classes[c].build(params, &shape_rng);
      if (!mesh.ok()) {
        return absl::InternalError(absl::StrCat("synthetic ",
                                                name,
                                                " model ",
                                                k,
                                                " (seed ",
                                                options.seed,
                                                "): ",
                                                mesh.status().message()));
      }
      model.mesh = *std::move(mesh);
      NormalizeSize(&model.mesh);
      if (options.random_pose) {
        const std::array<double, 9> rotation = RandomRotation(&pose_rng);
        const double scale =
            options.min_scale * std::pow(options.max_scale / options.min_scale, pose_rng.Uniform());
        Vec3d translation;
        for (int a = 0; a < 3; ++a) {
          translation[a] = pose_rng.Uniform(-options.max_translation, options.max_translation);
        }
        TransformMesh(rotation, scale, translation, &model.mesh);
      }
      if (model.is_soup) model.mesh = MakePolygonSoup(model.mesh);
      const absl::Status valid = ValidateMesh(model.mesh);
      if (!valid.ok()) {
        return absl::InternalError(
            absl::StrCat("synthetic ", name, " model ", k, ": ", valid.message()));
      }
      models.push_back(std::move(model));
    }
  }
  return models;
}

absl::Status GenerateSyntheticBenchmark(const SyntheticBenchmarkOptions& options,
                                        const std::string& out_dir) {
  MESHSEEK_ASSIGN_OR_RETURN(const std::vector<SyntheticModel> models, MakeSyntheticModels(options));
  std::error_code error;
  std::filesystem::create_directories(std::filesystem::path(out_dir) / "models", error);
  if (error) {
    return absl::PermissionDeniedError(
        absl::StrCat(out_dir, ": cannot create the models folder (", error.message(), ")"));
  }
  std::vector<ManifestEntry> manifest;
  std::vector<std::string> ids, labels;
  for (const SyntheticModel& m : models) {
    MeshWriteOptions write;
    write.binary = m.binary;
    MESHSEEK_RETURN_IF_ERROR(WriteMesh(out_dir + "/" + m.RelativePath(), m.mesh, write));
    manifest.push_back({m.id, m.label, m.RelativePath(), 0});
    ids.push_back(m.id);
    labels.push_back(m.label);
  }
  MESHSEEK_RETURN_IF_ERROR(WriteManifest(out_dir + "/manifest.csv", manifest));
  MESHSEEK_ASSIGN_OR_RETURN(const ClassFile class_file, MakeFlatClassFile(ids, labels));
  return WritePsbClassFile(out_dir + "/synthetic.cla", class_file);
}

}  // namespace meshseek
