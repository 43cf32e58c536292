// LSF: local statistical features, in the spirit of Ohkita, Ohishi, Furuya &
// Ohbuchi (ICME workshops 2012; DESIGN.md 2.7b). Each feature is a histogram of
// geometric relations among oriented surface samples inside a sphere about a
// feature centre; bag of features over a k-means codebook and symmetric KL
// ranking integrate them per model, as for the SIFT methods. The original
// paper's details are not available here: every choice below was made by
// measurement on McGill articulated (bench/lsf_eval.cc, bench/results/lsf.txt).
//
// Per model:
//   1. R = radius of the minimum enclosing sphere; support radius
//      s = scale * R (as DLD-SIFT's E: scale 1 is the sphere itself).
//   2. Oriented samples: SampleSurface with its face normals, about
//      `samples_per_support` samples in a flat disc of radius s (area-uniform,
//      Sobol, so independent of tessellation and connectivity: a polygon soup
//      or a model of many components gives the same samples as the welded
//      mesh).
//   3. Feature centres: SampleSurface(mesh, num_points), area-uniform.
//   4. Support: the oriented samples within s of the centre (PointGrid).
//      Fewer than min_support_samples: no feature (a centre on a sliver of
//      the model says nothing statistical). More than max_support_samples: an
//      evenly strided subset (time bound for huge or dense models).
//   5. Relations of each pair of oriented points (p_i, n_i), (p_j, n_j), with
//      v = p_j - p_i (every unordered pair of support samples with kPairs, or
//      the centre with each support sample with kCentre):
//        d     = |v| / (2 s)  (kPairs) or |v| / s (kCentre), in [0, 1];
//        a_nn  = angle between the normals' lines, acos |n_i . n_j|;
//        a_nl  = angle between a normal's line and v, acos |n . v / |v||,
//                for n_i and for n_j (an unordered pair gives both).
//      Absolute values make every relation blind to the sign of a normal:
//      polygon soups flip triangles freely, and inside/outside means nothing
//      for an open or non-solid model. All relations are distances and angles,
//      so the feature is invariant to rotation, translation (and, with s tied
//      to R, scale) by construction; only sampling noise remains.
//   6. Histogram (LsfOptions::Layout), then normalised: optional square root
//      (Hellinger: k-means' Euclidean distance then compares histograms as the
//      Bhattacharyya coefficient does, and dominant bins stop swamping the
//      rest), L2 normalisation, bytes = min(255, round(512 v)) as SIFT
//      quantises.
// Deterministic; single-threaded per model (meshseek parallelises across
// models).
#ifndef MESHSEEK_COMMON_FEATURES_LSF_H_
#define MESHSEEK_COMMON_FEATURES_LSF_H_

#include <cstddef>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "common/features/local_features.h"
#include "common/geometry/mesh.h"

namespace meshseek {

struct LsfOptions {
  /// Which pairs of oriented points the relations are taken from.
  enum class Relations {
    /// Every unordered pair of support samples: statistics of the local
    /// surface as a whole (local D2 / A3-style), independent of where in the
    /// support the centre sample happens to fall.
    kPairs = 0,
    /// The centre sample with each support sample (PPF / spin-image style):
    /// fewer relations, tied to the centre's own normal.
    kCentre = 1,
    /// Both descriptors concatenated (twice the layout's bytes).
    kBoth = 2,
  };
  /// How the relations are binned into one descriptor.
  enum class Layout {
    /// One 1-D histogram per relation, concatenated:
    /// distance_bins + 2 * angle_bins bytes.
    kConcatenated = 0,
    /// Two joint 2-D histograms, (d, a_nn) and (d, a_nl), concatenated:
    /// 2 * distance_bins * angle_bins bytes. Keeps how angles change with
    /// distance (curvature) that 1-D histograms lose.
    kDistanceJoint = 1,
    /// One joint 4-D histogram of (d, a_nn, smaller a_nl, larger a_nl):
    /// distance_bins * angle_bins^3 bytes.
    kFullJoint = 2,
  };

  /// Feature centres per model (area-uniform samples). Chosen by the sweep.
  int num_points = 1024;
  /// Support radius relative to the minimum enclosing sphere's radius R:
  /// s = scale * R. Chosen by the sweep.
  double scale = 0.3;
  /// Further support radii (relative to R, as scale): every centre also
  /// gets a feature at each, all in the one set (keypoint level = 1 + the
  /// index here; the scale's own features have level 0). The codebook then
  /// holds words of every radius: thin parts and whole limbs at once.
  std::vector<double> extra_scales;
  /// Target number of oriented samples in a flat disc of radius s; the model
  /// gets this times area / (pi s^2) samples, clamped to
  /// [min_samples, max_samples].
  int samples_per_support = 96;
  /// Bounds on the oriented sample count (time and memory guard for very
  /// small supports or huge models).
  int min_samples = 2048;
  int max_samples = 100000;
  /// A centre with fewer support samples than this yields no feature.
  int min_support_samples = 8;
  /// At most this many support samples enter the relations (evenly strided
  /// subset); kPairs costs their square.
  int max_support_samples = 192;
  Relations relations = Relations::kPairs;
  Layout layout = Layout::kDistanceJoint;
  /// Bins over d in [0, 1] (uniform).
  int distance_bins = 8;
  /// Bins over each angle in [0, pi/2], uniform in sqrt(1 - |cos|) =
  /// sqrt(2) sin(angle / 2) (within 10% of uniform in angle, no acos).
  int angle_bins = 8;
  /// Split each relation linearly between the two nearest bins of every
  /// coordinate instead of all into one: a support holds only about a hundred
  /// samples, and hard bin edges turn small sampling differences into
  /// different bins.
  bool soft_binning = false;
  /// The centre's normal for its relations (and the keypoint's view): the
  /// smallest axis of the support samples' PCA, weighted by (s - distance)
  /// about the centre (SHOT's frame), instead of the face normal under the
  /// centre sample: smoother, and the same for a coarse or a fine
  /// tessellation of the surface.
  bool pca_centre_normal = false;
  /// Square-root (Hellinger) normalisation before L2.
  bool root = true;

  /// Bytes per descriptor that these options give.
  std::size_t Dimension() const;
  /// Bytes of the pairs' part (centre = false) or the centre's part of the
  /// descriptor; Dimension() is their sum for kBoth.
  std::size_t PartDimension(bool centre) const;
  /// InvalidArgument naming the first bad field and its value (also when the
  /// dimension exceeds kMaxDescriptorDimension).
  absl::Status Validate() const;
};

// Extracts LSF features: one keypoint per usable centre (position = the
// centre, view = its sample's face normal, up = a unit vector normal to it,
// scale = s, level 0) and a descriptor of options.Dimension() bytes.
// Errors (InvalidArgument): invalid options; an invalid mesh (ValidateMesh;
// e.g. a mesh without area); a model of zero extent; no centre with enough
// support.
absl::StatusOr<LocalFeatures> ExtractLsf(const TriangleMesh& mesh, const LsfOptions& options);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_FEATURES_LSF_H_
