// A small, labelled, synthetic 3D shape benchmark, generated deterministically.
//
// meshseek's tests and its README demo need a retrieval benchmark that can
// live in the repository, and no licensed data may. This generates one: the
// procedural classes of synthetic_classes.h (snake, octopus, spider,
// humanoid, teddy, pliers, spectacles, table, vase), each model with its own
// non-rigid variation, random rotation, scale and translation and tessellation
// density, some stored as polygon soups and some as unwelded parts, written in
// a rotating mix of OFF, OBJ, PLY and STL, ASCII and binary, with a manifest
// and a PSB class file (docs/design.md 3.1).
//
// Determinism: the same options give byte-identical files. The random draws
// are the same on every platform (see SynthRandom); the geometry computed from
// them may differ in the last bits where libm's sin and cos do. Model k of a
// class depends only on (seed, class name, k, models_per_class), so editing
// one class changes no other class's models, and selecting classes changes no
// model. The default benchmark (9 classes x 8 models, 196 to 6,000 vertices a
// model) takes about 0.2 s on one core and 12 MB.
#ifndef MESHSEEK_COMMON_SYNTH_SYNTHETIC_BENCHMARK_H_
#define MESHSEEK_COMMON_SYNTH_SYNTHETIC_BENCHMARK_H_

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "common/geometry/mesh.h"
#include "common/geometry/mesh_io.h"

namespace meshseek {

struct SyntheticBenchmarkOptions {
  // Models generated per class, >= 1 (at most 10000).
  int models_per_class = 8;
  // Seed of every random choice. Different seeds give different benchmarks.
  uint64_t seed = 1;
  // Share of each class's models stored as polygon soups (every triangle with
  // its own three vertices), in [0, 1]; rounded to a count per class, so the
  // default gives 1 of 8.
  double soup_fraction = 0.125;
  // Share of each class's models built from unwelded, overlapping parts
  // (several connected components), in [0, 1]; rounded per class like
  // soup_fraction (default 2 of 8). The two sets are disjoint, so
  // soup_fraction + multi_component_fraction must not exceed 1.
  double multi_component_fraction = 0.25;
  // Range of the linear tessellation density (SyntheticShapeParams::density),
  // 0.1 <= min_density <= max_density <= 10. The models of a class are spread
  // over the range on a log scale (stratified, so each class spans it), and
  // vertex counts grow as density^2: the default range gives a few hundred to
  // about 5,000 vertices, a spread of about 9 within each class.
  double min_density = 1.0;
  double max_density = 3.0;
  // Whether models get a uniformly random rotation, scale and translation.
  // Off, every model is centred at the origin with bounding-box diagonal 2 in
  // its class's canonical orientation (z up): handy for looking at shapes.
  bool random_pose = true;
  // Range of the random uniform scale (log-uniform), applied to the model
  // normalised to bounding-box diagonal 2; 0 < min_scale <= max_scale.
  double min_scale = 0.5;
  double max_scale = 2.0;
  // Each coordinate of the random translation is uniform in
  // [-max_translation, max_translation]; >= 0.
  double max_translation = 5.0;
  // Classes to generate, by name (SyntheticClassNames()); empty means all.
  // Order and model contents do not depend on this list.
  std::vector<std::string> classes;

  // OK, or InvalidArgument naming the first bad field and its value.
  absl::Status Validate() const;
};

struct SyntheticModel {
  std::string id;     // "0", "1", ... in class order; also the file's stem
  std::string label;  // class name
  TriangleMesh mesh;
  bool is_soup = false;             // stored as a polygon soup
  bool is_multi_component = false;  // unwelded parts (several components)
  MeshFormat format = MeshFormat::kOff;
  bool binary = false;  // encoding in its file (OBJ is always ASCII)

  // "models/<id>.<ext>", relative to the benchmark folder.
  std::string RelativePath() const;
};

// All models in memory, grouped by class in SyntheticClassNames() order,
// ids numbered from 0 in that order. Fails on invalid options (or, as an
// internal error, if a class cannot build a model).
absl::StatusOr<std::vector<SyntheticModel>> MakeSyntheticModels(
    const SyntheticBenchmarkOptions& options);

// Generates the benchmark under out_dir (created if needed):
//   out_dir/models/<id>.<ext>   every model, in its format and encoding;
//   out_dir/manifest.csv        header "id,class,path", paths relative to
//                               out_dir, rows grouped by class;
//   out_dir/synthetic.cla       PSB 1 class file listing the same ids.
// Files of an earlier generation with other names are left alone.
absl::Status GenerateSyntheticBenchmark(const SyntheticBenchmarkOptions& options,
                                        const std::string& out_dir);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_SYNTH_SYNTHETIC_BENCHMARK_H_
