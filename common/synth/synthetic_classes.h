// The shape classes of the synthetic benchmark, in the spirit of the McGill
// articulated shape benchmark (snakes, octopuses, spiders, humans, teddy bears,
// pliers, spectacles) plus two rigid, man-made classes (tables, vases), and the
// deterministic random numbers they are drawn with.
//
// Each class builder makes one random member of its class in a canonical pose
// (z up, roughly unit size); synthetic_benchmark.h normalises, poses and
// writes them. Variation inside a class is non-rigid on purpose (joint angles,
// bends, stretched parts, proportions), so that a descriptor must recognise
// local surface shape rather than a global outline. Which pairs are hard:
// snake / octopus arms / spider legs are all tubes (radius, taper and joints
// tell them apart); humanoid / teddy / spider are bodies with limbs (thin
// jointed limbs vs fat blobs); pliers / spectacles are thin rods (tapered
// jaws and a hinge vs rings). Tables (planes, right angles) and vases (an open,
// doubly curved sheet) are the easy ones.
#ifndef MESHSEEK_COMMON_SYNTH_SYNTHETIC_CLASSES_H_
#define MESHSEEK_COMMON_SYNTH_SYNTHETIC_CLASSES_H_

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "common/geometry/mesh.h"

namespace meshseek {

// Random numbers that are the same on every platform. std::mt19937_64's output
// sequence is fixed by the C++ standard, but std::uniform_real_distribution and
// std::normal_distribution are implementation-defined (libstdc++ and libc++
// differ), so the transforms here are meshseek's own.
class SynthRandom {
 public:
  explicit SynthRandom(uint64_t seed) : engine_(seed) {}

  uint64_t Next() { return engine_(); }
  // Uniform in [0, 1) with 53 random bits.
  double Uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  // Uniform in [lo, hi).
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
  // Uniform integer in [lo, hi] (lo <= hi).
  int UniformInt(int lo, int hi);
  // Standard normal by the Box-Muller transform (one value per call).
  double Normal();
  bool Bernoulli(double p) { return Uniform() < p; }

 private:
  std::mt19937_64 engine_;
};

// SplitMix64 finaliser of a combined with b: derives independent seeds
// (per class, per model, per purpose) from one user seed.
uint64_t MixSeed(uint64_t a, uint64_t b);

// FNV-1a hash of a class name, so that a class's seeds depend on its name and
// not on its position in the class list.
uint64_t HashName(absl::string_view name);

// What a class builder is asked to make.
struct SyntheticShapeParams {
  // Linear tessellation density: target edge length is 0.12 / density in the
  // canonical pose (where models are about 2 units across), so vertex counts
  // grow about as density^2. 1 gives a few hundred vertices.
  double density = 1.0;
  // true: one connected surface (limbs are extruded from holes cut in the
  // body, see shapes.h). false: the same parts appended as separate,
  // overlapping components, as many downloaded models are built.
  bool welded = true;
};

using SyntheticShapeBuilder = absl::StatusOr<TriangleMesh> (*)(const SyntheticShapeParams& params,
                                                               SynthRandom* rng);

struct SyntheticClass {
  const char* name;         // class label, lower case, no spaces
  const char* description;  // one line: the parts and what varies
  SyntheticShapeBuilder build;
};

// The classes in benchmark order: snake, octopus, spider, humanoid, teddy,
// pliers, spectacles, table, vase.
const std::vector<SyntheticClass>& SyntheticClasses();

// Their names, in the same order.
std::vector<std::string> SyntheticClassNames();

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_SYNTH_SYNTHETIC_CLASSES_H_
