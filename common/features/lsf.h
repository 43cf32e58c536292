// LSF: local statistical features, in the spirit of Ohkita, Ohishi, Furuya &
// Ohbuchi (ICME workshops 2012; docs/design.md 2.7b). Each feature is a histogram of
// geometric relations among oriented surface samples inside a sphere about a
// feature centre; bag of features over a k-means codebook and symmetric KL
// ranking integrate them per model, as for the SIFT methods. The original
// paper's details are not available here: every choice below was made by
// measurement on McGill articulated (bench/lsf_eval.cc, bench/results/lsf.txt).
//
// Per model:
//   1. R = radius of the minimum enclosing sphere; support radius
//      s = scale * R (as DLD-SIFT's E: scale 1 is the sphere itself), and
//      each of extra_scales * R: every centre gets one feature per radius.
//   2. Oriented samples: SampleSurface with its face normals, about
//      `samples_per_support` samples in a flat disc of the smallest radius
//      (area-uniform, Sobol, so independent of connectivity: a polygon soup
//      gives the same samples as the welded mesh).
//   3. Feature centres: SampleSurface(mesh, num_points), area-uniform.
//   4. Support: the oriented samples within s of the centre (PointGrid).
//      Fewer than min_support_samples: no feature (a centre on a sliver of
//      the model says nothing statistical). More than max_support_samples: an
//      evenly strided subset (time bound for huge or dense models).
//   5. Relations of each pair of oriented points (p_i, n_i), (p_j, n_j), with
//      v = p_j - p_i: the centre with each support sample (kCentre, the
//      default), or every unordered pair of support samples (kPairs):
//        d     = |v| / s  (kCentre) or |v| / (2 s) (kPairs), in [0, 1];
//        a_nn  = angle between the normals' lines, acos |n_i . n_j|;
//        a_il, a_jl = angle between n_i's (n_j's) line and v, acos |n . v / |v||.
//      With kCentre these are the point-pair feature of Drost et al. (CVPR
//      2010; Wahl et al.'s surflet pair, 3DIM 2003) with unsigned normals,
//      taken from the centre: how the surface turns away from the centre's
//      tangent plane as it goes out to s (spin-image-like, with the normals).
//      Absolute values make every relation blind to the sign of a normal:
//      polygon soups flip triangles freely, and inside/outside means nothing
//      for an open or non-solid model. All relations are distances and angles,
//      so the feature is invariant to rotation, translation (and, with s tied
//      to R, scale) by construction; only sampling noise remains (a rotated,
//      scaled and moved copy gives bit-identical descriptors: the samples
//      are the same barycentric points).
//   6. Histogram (LsfOptions::Layout; default the joint 4-D histogram of
//      (d, a_nn, a_il, a_jl), 4 x 6 x 6 x 6 = 864 bytes, soft-binned), then
//      normalised: square root (Hellinger: k-means' Euclidean distance then
//      compares histograms as the Bhattacharyya coefficient does, and dominant
//      bins stop swamping the rest), L2 normalisation,
//      bytes = min(255, round(512 v)) as SIFT quantises.
//
// Measured on McGill articulated (255 models, first tier = R-precision; the
// whole sweep is in bench/results/lsf.txt): pairs of support samples 64.1 at
// their best scale, centre relations 73.6 with the same 2-D (d, angle)
// histograms at a sixteenth of the time (0.021 s against 0.34 s a model);
// the joint 4-D histogram 76.8 (concatenated 1-D histograms 74.6, three joint
// 2-D ones 73.6); soft binning 77.5 (V = 1,000); two radii, 0.3 R and 0.6 R,
// 78.5 at V = 1,000 and 79.7 at V = 2,000; 2,048 centres or 2.7 times denser
// supports gave nothing more; the PCA normal instead of the face normal lost
// 3.9. Extraction of the defaults: a median 0.055 s a model on one core.
// PSB train (mostly rigid) prefers larger radii: 34.5 with the defaults, 39.4
// with 0.5 R and 1.0 R (V = 2,000).
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
    /// tied to the centre's own normal, which orders the two line angles.
    /// The default: 9.4 points of first tier above kPairs on McGill at the
    /// same histograms, and linear instead of quadratic in the support.
    kCentre = 1,
    /// Both descriptors concatenated (72.0: no better than kCentre alone).
    kBoth = 2,
  };
  /// How the relations are binned into one descriptor.
  enum class Layout {
    /// One 1-D histogram per relation, concatenated:
    /// distance_bins + 2 * angle_bins bytes (kPairs pools a_il and a_jl) or
    /// distance_bins + 3 * angle_bins (kCentre).
    kConcatenated = 0,
    /// Joint 2-D histograms (d, a_nn), (d, a_l) (kPairs: a_il and a_jl
    /// pooled) or (d, a_nn), (d, a_il), (d, a_jl) (kCentre), concatenated:
    /// 2 or 3 * distance_bins * angle_bins bytes. Keeps how angles change with
    /// distance (curvature), which 1-D histograms lose.
    kDistanceJoint = 1,
    /// One joint 4-D histogram of (d, a_nn, a_il, a_jl) (kPairs: the smaller
    /// and the larger line angle, the pair being unordered):
    /// distance_bins * angle_bins^3 bytes. The default: the relations
    /// together say which surface the centre sees at which distance and
    /// slant, which their marginals cannot (76.8 against 73.6 and 74.6).
    kFullJoint = 2,
  };

  /// Feature centres per model (area-uniform samples). 2,048 measured the
  /// same (77.3 against 77.5) at twice the time.
  int num_points = 1024;
  /// Support radius relative to the minimum enclosing sphere's radius R:
  /// s = scale * R. Alone, McGill first tier (V = 1,000) is 76.6 / 77.5 /
  /// 77.7 / 77.3 at 0.4 / 0.45 / 0.5 / 0.6 (and 70.8 at 0.3 with 2-D
  /// histograms, 72.3 at 0.8): an articulated limb needs the support to
  /// reach past its own thickness, and a larger one mixes parts that
  /// articulation moves. With extra_scales the small radius adds the
  /// limbs' own shape to the larger one's context.
  double scale = 0.3;
  /// Further support radii (relative to R, as scale): every centre also
  /// gets a feature at each, all in the one set (keypoint level = 1 + the
  /// index here; the scale's own features have level 0). The codebook then
  /// holds words of every radius: thin parts and whole limbs at once.
  /// {0.6} with scale 0.3: 78.5 at V = 1,000 and 79.7 at V = 2,000, against
  /// 77.5 and 76.6 for 0.45 alone; three radii (0.25, 0.5, 0.75) measured the
  /// same (78.3, 79.8) at 1.5 times the features.
  std::vector<double> extra_scales = {0.6};
  /// Target number of oriented samples in a flat disc of radius s; the model
  /// gets this times area / (pi s^2) samples, clamped to
  /// [min_samples, max_samples]. 256 (with max_support_samples 1,024)
  /// measured the same (77.4).
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
  Relations relations = Relations::kCentre;
  Layout layout = Layout::kFullJoint;
  /// Bins over d in [0, 1] (uniform).
  int distance_bins = 4;
  /// Bins over each angle in [0, pi/2], uniform in sqrt(1 - |cos|) =
  /// sqrt(2) sin(angle / 2) (within 10% of uniform in angle, no acos).
  /// 4 x 5^3 = 500 bytes measured 76.8, 4 x 6^3 = 864 bytes 77.5.
  int angle_bins = 6;
  /// Split each relation linearly between the two nearest bins of every
  /// coordinate instead of all into one: a support holds only about a hundred
  /// samples, and hard bin edges turn small sampling differences into
  /// different bins. 77.5 against 76.8.
  bool soft_binning = true;
  /// The centre's normal for its relations (and the keypoint's view): the
  /// smallest axis of the support samples' PCA, weighted by (s - distance)
  /// about the centre (SHOT's frame), instead of the face normal under the
  /// centre sample: smoother, and the same for a coarse or a fine
  /// tessellation of the surface. Measured worse (72.9 against 76.8, hard
  /// binning): at s = 0.45 R the plane of the support is not the surface
  /// under the centre.
  bool pca_centre_normal = false;
  /// Square-root (Hellinger) normalisation before L2. 77.5 against 76.7.
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
