#include "common/features/lsf.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "absl/strings/str_cat.h"
#include "common/base/status_macros.h"
#include "common/geometry/enclosing_sphere.h"
#include "common/geometry/point_grid.h"
#include "common/geometry/principal_axes.h"
#include "common/geometry/surface_sampler.h"

namespace meshseek {
namespace {

// A value in [0, 1] spread over `bins` bins: all of it into its bin (hard),
// or split linearly between the two nearest bin centres (soft; the outer half
// bins keep what lies beyond their centre).
struct BinWeights {
  int bin[2];
  float weight[2];
};
BinWeights Spread(float x, int bins, bool soft) {
  if (!soft || bins == 1) {
    const int b = std::min(bins - 1, static_cast<int>(x * bins));
    return {{b, b}, {1.0f, 0.0f}};
  }
  const float u = std::clamp(x * bins - 0.5f, 0.0f, static_cast<float>(bins - 1));
  const int b = std::min(bins - 2, static_cast<int>(u));
  const float f = u - b;
  return {{b, b + 1}, {1.0f - f, f}};
}

// The angle coordinate of an absolute cosine c = cos(theta), theta in
// [0, pi/2]: sqrt(1 - c) = sqrt(2) sin(theta / 2), within 10% of theta / (pi/2)
// and linear near 0 where most normal pairs of a smooth surface lie, at the
// cost of one square root instead of an acos per relation.
float AngleCoordinate(float abs_cos) {
  return std::sqrt(std::max(0.0f, 1.0f - std::min(1.0f, abs_cos)));
}

// Any unit vector normal to unit n (the keypoint's image up axis is not used
// by LSF, but Keypoint promises one).
Vec3f Perpendicular(const Vec3f& n) {
  const Vec3f other = std::fabs(n.x) < 0.9f ? Vec3f(1, 0, 0) : Vec3f(0, 1, 0);
  return Normalized(Cross(n, other));
}

class Histogrammer {
 public:
  // `ordered`: the relations are the centre's with a support sample, whose
  // two normal-line angles mean different things and get histograms of their
  // own; a pair of support samples is unordered and pools them.
  Histogrammer(const LsfOptions& options, bool ordered)
      : options_(options), ordered_(ordered), histogram_(options.PartDimension(ordered)) {}

  void Clear() { std::fill(histogram_.begin(), histogram_.end(), 0.0f); }

  // One relation; d in [0, 1], cosines as |n_i . n_j|, |n_i . v|, |n_j . v|.
  // Each pair counts 2 in the (d, a_nn) part and 1 per normal in the (d, a_nl)
  // part, so both parts weigh the same.
  void Add(float d, float cos_nn, float cos_il, float cos_jl) {
    const int nd = options_.distance_bins, na = options_.angle_bins;
    const bool soft = options_.soft_binning;
    const BinWeights wd = Spread(d, nd, soft);
    const BinWeights wnn = Spread(AngleCoordinate(cos_nn), na, soft);
    const BinWeights wi = Spread(AngleCoordinate(cos_il), na, soft);
    const BinWeights wj = Spread(AngleCoordinate(cos_jl), na, soft);
    float* h = histogram_.data();
    // Ordered: i's and j's line angles in parts of their own, each relation
    // counting once per part; unordered: one pooled part, the pair counting
    // 2 in the normal-normal part so that both parts weigh the same.
    const float nn_weight = ordered_ ? 1.0f : 2.0f;
    const int j_part = ordered_ ? 1 : 0;
    switch (options_.layout) {
      case LsfOptions::Layout::kConcatenated:
        for (int x = 0; x < 2; ++x) {
          h[wd.bin[x]] += nn_weight * wd.weight[x];
          h[nd + wnn.bin[x]] += nn_weight * wnn.weight[x];
          h[nd + na + wi.bin[x]] += wi.weight[x];
          h[nd + (1 + j_part) * na + wj.bin[x]] += wj.weight[x];
        }
        break;
      case LsfOptions::Layout::kDistanceJoint:
        for (int x = 0; x < 2; ++x) {
          for (int y = 0; y < 2; ++y) {
            const int row = wd.bin[x] * na;
            h[row + wnn.bin[y]] += nn_weight * wd.weight[x] * wnn.weight[y];
            h[nd * na + row + wi.bin[y]] += wd.weight[x] * wi.weight[y];
            h[(1 + j_part) * nd * na + row + wj.bin[y]] += wd.weight[x] * wj.weight[y];
          }
        }
        break;
      case LsfOptions::Layout::kFullJoint: {
        // Unordered pairs: (smaller, larger) normal-line angle.
        const bool swap = !ordered_ && cos_il < cos_jl;
        const BinWeights& lo = swap ? wj : wi;
        const BinWeights& hi = swap ? wi : wj;
        for (int x = 0; x < 2; ++x)
          for (int y = 0; y < 2; ++y)
            for (int z = 0; z < 2; ++z)
              for (int w = 0; w < 2; ++w) {
                h[((wd.bin[x] * na + wnn.bin[y]) * na + lo.bin[z]) * na + hi.bin[w]] +=
                    wd.weight[x] * wnn.weight[y] * lo.weight[z] * hi.weight[w];
              }
        break;
      }
    }
  }

  // `parts` descriptors are concatenated (kBoth): each gets an L2 norm of
  // 512 / sqrt(parts), so the whole has SIFT's 512.
  void Emit(int parts, std::vector<uint8_t>* out) const {
    double norm = 0;
    std::vector<double> v(histogram_.begin(), histogram_.end());
    for (double& x : v) {
      if (options_.root) x = std::sqrt(x);
      norm += x * x;
    }
    const double scale = norm > 0 ? 512.0 / std::sqrt(parts * norm) : 0.0;
    for (double x : v) {
      out->push_back(static_cast<uint8_t>(std::min(255.0, std::round(x * scale))));
    }
  }

 private:
  const LsfOptions& options_;
  const bool ordered_;
  std::vector<float> histogram_;
};

}  // namespace

std::size_t LsfOptions::Dimension() const {
  return (relations != Relations::kCentre ? PartDimension(false) : 0) +
         (relations != Relations::kPairs ? PartDimension(true) : 0);
}

std::size_t LsfOptions::PartDimension(bool centre) const {
  const std::size_t nd = std::max(distance_bins, 0), na = std::max(angle_bins, 0);
  const std::size_t line_angles = centre ? 2 : 1;
  switch (layout) {
    case Layout::kConcatenated:
      return nd + (1 + line_angles) * na;
    case Layout::kDistanceJoint:
      return (1 + line_angles) * nd * na;
    case Layout::kFullJoint:
      return nd * na * na * na;
  }
  return 0;
}

absl::Status LsfOptions::Validate() const {
  auto bad = [](const char* field, auto value, const char* want) {
    return absl::InvalidArgumentError(
        absl::StrCat("LSF ", field, " must be ", want, ", got ", value));
  };
  if (num_points < 1 || num_points > 1000000)
    return bad("num_points", num_points, "in [1, 1000000]");
  if (!(scale > 0) || scale > 2) return bad("scale", scale, "in (0, 2]");
  if (extra_scales.size() > 8) return bad("extra_scales count", extra_scales.size(), "at most 8");
  for (double extra : extra_scales) {
    if (!(extra > 0) || extra > 2) return bad("extra_scales entry", extra, "in (0, 2]");
  }
  if (samples_per_support < 4) return bad("samples_per_support", samples_per_support, ">= 4");
  if (min_samples < 16) return bad("min_samples", min_samples, ">= 16");
  if (max_samples < min_samples || max_samples > 10000000) {
    return bad("max_samples", max_samples, "in [min_samples, 10000000]");
  }
  if (min_support_samples < 2) return bad("min_support_samples", min_support_samples, ">= 2");
  if (max_support_samples < min_support_samples || max_support_samples > 4096) {
    return bad("max_support_samples", max_support_samples, "in [min_support_samples, 4096]");
  }
  if (relations != Relations::kPairs && relations != Relations::kCentre &&
      relations != Relations::kBoth) {
    return bad("relations", static_cast<int>(relations), "a Relations value");
  }
  if (layout != Layout::kConcatenated && layout != Layout::kDistanceJoint &&
      layout != Layout::kFullJoint) {
    return bad("layout", static_cast<int>(layout), "a Layout value");
  }
  if (distance_bins < 1 || distance_bins > 64)
    return bad("distance_bins", distance_bins, "in [1, 64]");
  if (angle_bins < 1 || angle_bins > 64) return bad("angle_bins", angle_bins, "in [1, 64]");
  if (Dimension() > kMaxDescriptorDimension) {
    return bad("descriptor dimension",
               Dimension(),
               absl::StrCat("at most ", kMaxDescriptorDimension, " (fewer bins)").c_str());
  }
  return absl::OkStatus();
}

namespace {

// Sorts distinct indices below the bound given at construction into
// increasing order, as std::sort would: a large set through a bitmap (each
// index sets its bit, then the words between the smallest and the largest
// are read back in order and cleared), which costs a pass over the set and
// the range instead of n log n comparisons.
class DistinctIndexSorter {
 public:
  explicit DistinctIndexSorter(std::size_t bound) : bits_(bound / 64 + 1, 0) {}

  void Sort(std::vector<uint32_t>* indices) {
    if (indices->size() < 64) {
      std::sort(indices->begin(), indices->end());
      return;
    }
    uint32_t lo = std::numeric_limits<uint32_t>::max(), hi = 0;
    for (const uint32_t i : *indices) {
      bits_[i / 64] |= uint64_t{1} << (i % 64);
      lo = std::min(lo, i);
      hi = std::max(hi, i);
    }
    uint32_t* out = indices->data();
    for (uint32_t w = lo / 64; w <= hi / 64; ++w) {
      for (uint64_t word = bits_[w]; word != 0; word &= word - 1) {
        *out++ = w * 64 + static_cast<uint32_t>(__builtin_ctzll(word));
      }
      bits_[w] = 0;
    }
  }

 private:
  std::vector<uint64_t> bits_;
};

// The features of every centre at support radius s, appended to `features`
// (keypoint level `level`).
void DescribeAtRadius(const LsfOptions& options,
                      const SurfacePoints& samples,
                      const SurfacePoints& centres,
                      double s,
                      int level,
                      LocalFeatures* features) {
  const PointGrid grid(samples.positions, static_cast<float>(s));
  const bool pairs = options.relations != LsfOptions::Relations::kCentre;
  const bool centre = options.relations != LsfOptions::Relations::kPairs;
  const int parts = pairs + centre;
  // Pairs span up to the support's diameter, centre relations its radius.
  const float inv_diameter = static_cast<float>(1.0 / (2 * s));
  const float inv_radius = static_cast<float>(1.0 / s);
  Histogrammer pair_histogram(options, false), centre_histogram(options, true);
  std::vector<uint32_t> support, chosen;
  DistinctIndexSorter sorter(samples.size());
  auto relate = [](const Vec3f& pi,
                   const Vec3f& ni,
                   const Vec3f& pj,
                   const Vec3f& nj,
                   float inv_span,
                   Histogrammer& histogram) {
    const Vec3f v = pj - pi;
    const float length = Norm(v);
    if (!(length > 0)) return;  // coincident samples have no direction
    const Vec3f u = v * (1.0f / length);
    histogram.Add(std::min(1.0f, length * inv_span),
                  std::fabs(Dot(ni, nj)),
                  std::fabs(Dot(ni, u)),
                  std::fabs(Dot(nj, u)));
  };
  for (std::size_t c = 0; c < centres.size(); ++c) {
    support.clear();
    grid.RadiusQuery(centres.positions[c], static_cast<float>(s), &support);
    if (support.size() < static_cast<std::size_t>(options.min_support_samples)) continue;
    // The grid returns indices cell by cell (each once); sorting makes the
    // strided subset (and the float sums) independent of the grid's cell order.
    sorter.Sort(&support);
    const std::size_t m = std::min<std::size_t>(support.size(), options.max_support_samples);
    chosen.resize(m);
    for (std::size_t k = 0; k < m; ++k) chosen[k] = support[k * support.size() / m];

    if (pairs) {
      pair_histogram.Clear();
      for (std::size_t a = 0; a < m; ++a) {
        const Vec3f& pa = samples.positions[chosen[a]];
        const Vec3f& na = samples.normals[chosen[a]];
        for (std::size_t b = a + 1; b < m; ++b) {
          relate(pa,
                 na,
                 samples.positions[chosen[b]],
                 samples.normals[chosen[b]],
                 inv_diameter,
                 pair_histogram);
        }
      }
      pair_histogram.Emit(parts, &features->descriptors);
    }
    Vec3f n = centres.normals[c];
    if (options.pca_centre_normal) {
      n = Vec3f(
          ComputeWeightedPrincipalAxes(samples.positions, support, Vec3d(centres.positions[c]), s)
              .axes[2]);
    }
    if (centre) {
      centre_histogram.Clear();
      for (uint32_t j : chosen) {
        relate(centres.positions[c],
               n,
               samples.positions[j],
               samples.normals[j],
               inv_radius,
               centre_histogram);
      }
      centre_histogram.Emit(parts, &features->descriptors);
    }
    features->keypoints.push_back(
        {centres.positions[c], n, Perpendicular(n), static_cast<float>(s), level});
  }
}

}  // namespace

absl::StatusOr<LocalFeatures> ExtractLsf(const TriangleMesh& mesh, const LsfOptions& options) {
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  MESHSEEK_RETURN_IF_ERROR(ValidateMesh(mesh));
  MESHSEEK_ASSIGN_OR_RETURN(const Sphere sphere, MinimumEnclosingSphere(mesh));
  std::vector<double> scales = {options.scale};
  scales.insert(scales.end(), options.extra_scales.begin(), options.extra_scales.end());
  const double smallest = *std::min_element(scales.begin(), scales.end()) * sphere.radius;
  if (!(smallest > 0)) {
    return absl::InvalidArgumentError("model has zero extent (all vertices coincide)");
  }
  // Sample density for the smallest support; larger ones hold more samples
  // and are strided down to max_support_samples.
  const double area = SurfaceArea(mesh);
  const double wanted = options.samples_per_support * area / (M_PI * smallest * smallest);
  const int64_t count = static_cast<int64_t>(
      std::clamp<double>(std::ceil(wanted), options.min_samples, options.max_samples));
  MESHSEEK_ASSIGN_OR_RETURN(const SurfacePoints samples, SampleSurface(mesh, count));
  MESHSEEK_ASSIGN_OR_RETURN(const SurfacePoints centres, SampleSurface(mesh, options.num_points));

  LocalFeatures features;
  features.dimension = options.Dimension();
  features.keypoints.reserve(centres.size() * scales.size());
  features.descriptors.reserve(centres.size() * scales.size() * features.dimension);
  for (std::size_t k = 0; k < scales.size(); ++k) {
    DescribeAtRadius(
        options, samples, centres, scales[k] * sphere.radius, static_cast<int>(k), &features);
  }
  if (features.keypoints.empty()) {
    return absl::InvalidArgumentError(absl::StrCat("LSF found no feature centre with at least ",
                                                   options.min_support_samples,
                                                   " support samples (",
                                                   count,
                                                   " samples, smallest support radius ",
                                                   smallest,
                                                   ")"));
  }
  return features;
}

}  // namespace meshseek
