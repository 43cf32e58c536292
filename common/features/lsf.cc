#include "common/features/lsf.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "absl/strings/str_cat.h"
#include "common/base/status_macros.h"
#include "common/geometry/enclosing_sphere.h"
#include "common/geometry/point_grid.h"
#include "common/geometry/surface_sampler.h"

namespace meshseek {
namespace {

// Angle bins are uniform in angle but the relations are cosines: the bin of
// |cos| c is the number of bin edges cos(k pi / (2 bins)), k = 1..bins-1, above
// c, which needs no acos per pair.
class AngleBinner {
 public:
  explicit AngleBinner(int bins) {
    for (int k = 1; k < bins; ++k) edges_.push_back(std::cos(k * M_PI / (2.0 * bins)));
  }
  int operator()(float abs_cos) const {
    int bin = 0;
    for (float edge : edges_) bin += abs_cos < edge;
    return bin;
  }

 private:
  std::vector<float> edges_;
};

// Any unit vector normal to unit n (the keypoint's image up axis is not used
// by LSF, but Keypoint promises one).
Vec3f Perpendicular(const Vec3f& n) {
  const Vec3f other = std::fabs(n.x) < 0.9f ? Vec3f(1, 0, 0) : Vec3f(0, 1, 0);
  return Normalized(Cross(n, other));
}

class Histogrammer {
 public:
  explicit Histogrammer(const LsfOptions& options)
      : options_(options), angle_(options.angle_bins), histogram_(options.Dimension()) {}

  void Clear() { std::fill(histogram_.begin(), histogram_.end(), 0.0f); }

  // One pair; d in [0, 1] (clamped), cosines as |n_i . n_j|, |n_i . v|, |n_j . v|.
  void Add(float d, float cos_nn, float cos_il, float cos_jl) {
    const int nd = options_.distance_bins, na = options_.angle_bins;
    const int bd = std::min(nd - 1, static_cast<int>(d * nd));
    const int bnn = angle_(cos_nn), bi = angle_(cos_il), bj = angle_(cos_jl);
    switch (options_.layout) {
      case LsfOptions::Layout::kConcatenated:
        histogram_[bd] += 2;
        histogram_[nd + bnn] += 2;
        histogram_[nd + na + bi] += 1;
        histogram_[nd + na + bj] += 1;
        break;
      case LsfOptions::Layout::kDistanceJoint:
        histogram_[bd * na + bnn] += 2;
        histogram_[nd * na + bd * na + bi] += 1;
        histogram_[nd * na + bd * na + bj] += 1;
        break;
      case LsfOptions::Layout::kFullJoint:
        histogram_[((bd * na + bnn) * na + std::min(bi, bj)) * na + std::max(bi, bj)] += 1;
        break;
    }
  }

  // Normalised and quantised onto the end of `out`.
  void Emit(std::vector<uint8_t>* out) const {
    double norm = 0;
    std::vector<double> v(histogram_.begin(), histogram_.end());
    for (double& x : v) {
      if (options_.root) x = std::sqrt(x);
      norm += x * x;
    }
    const double scale = norm > 0 ? 512.0 / std::sqrt(norm) : 0.0;
    for (double x : v) {
      out->push_back(static_cast<uint8_t>(std::min(255.0, std::round(x * scale))));
    }
  }

 private:
  const LsfOptions& options_;
  AngleBinner angle_;
  std::vector<float> histogram_;
};

}  // namespace

std::size_t LsfOptions::Dimension() const {
  const std::size_t nd = std::max(distance_bins, 0), na = std::max(angle_bins, 0);
  switch (layout) {
    case Layout::kConcatenated:
      return nd + 2 * na;
    case Layout::kDistanceJoint:
      return 2 * nd * na;
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
  if (num_points < 1 || num_points > 1000000) return bad("num_points", num_points, "in [1, 1000000]");
  if (!(scale > 0) || scale > 2) return bad("scale", scale, "in (0, 2]");
  if (samples_per_support < 4) return bad("samples_per_support", samples_per_support, ">= 4");
  if (min_samples < 16) return bad("min_samples", min_samples, ">= 16");
  if (max_samples < min_samples || max_samples > 10000000) {
    return bad("max_samples", max_samples, "in [min_samples, 10000000]");
  }
  if (min_support_samples < 2) return bad("min_support_samples", min_support_samples, ">= 2");
  if (max_support_samples < min_support_samples || max_support_samples > 4096) {
    return bad("max_support_samples", max_support_samples, "in [min_support_samples, 4096]");
  }
  if (relations != Relations::kPairs && relations != Relations::kCentre) {
    return bad("relations", static_cast<int>(relations), "kPairs or kCentre");
  }
  if (layout != Layout::kConcatenated && layout != Layout::kDistanceJoint &&
      layout != Layout::kFullJoint) {
    return bad("layout", static_cast<int>(layout), "a Layout value");
  }
  if (distance_bins < 1 || distance_bins > 64) return bad("distance_bins", distance_bins, "in [1, 64]");
  if (angle_bins < 1 || angle_bins > 64) return bad("angle_bins", angle_bins, "in [1, 64]");
  if (Dimension() > kMaxDescriptorDimension) {
    return bad("descriptor dimension", Dimension(),
               absl::StrCat("at most ", kMaxDescriptorDimension, " (fewer bins)").c_str());
  }
  return absl::OkStatus();
}

absl::StatusOr<LocalFeatures> ExtractLsf(const TriangleMesh& mesh, const LsfOptions& options) {
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  MESHSEEK_RETURN_IF_ERROR(ValidateMesh(mesh));
  MESHSEEK_ASSIGN_OR_RETURN(const Sphere sphere, MinimumEnclosingSphere(mesh));
  const double s = options.scale * sphere.radius;
  if (!(s > 0)) {
    return absl::InvalidArgumentError("model has zero extent (all vertices coincide)");
  }
  const double area = SurfaceArea(mesh);
  const double wanted = options.samples_per_support * area / (M_PI * s * s);
  const int64_t count = static_cast<int64_t>(
      std::clamp<double>(std::ceil(wanted), options.min_samples, options.max_samples));
  MESHSEEK_ASSIGN_OR_RETURN(const SurfacePoints samples, SampleSurface(mesh, count));
  MESHSEEK_ASSIGN_OR_RETURN(const SurfacePoints centres, SampleSurface(mesh, options.num_points));
  const PointGrid grid(samples.positions, static_cast<float>(s));

  const bool pairs = options.relations == LsfOptions::Relations::kPairs;
  // Pairs span up to the support's diameter, centre relations its radius.
  const float inv_span = static_cast<float>(1.0 / (pairs ? 2 * s : s));
  const std::size_t dim = options.Dimension();
  Histogrammer histogram(options);
  LocalFeatures features;
  features.dimension = dim;
  features.keypoints.reserve(centres.size());
  features.descriptors.reserve(centres.size() * dim);
  std::vector<uint32_t> support, chosen;
  for (std::size_t c = 0; c < centres.size(); ++c) {
    support.clear();
    grid.RadiusQuery(centres.positions[c], static_cast<float>(s), &support);
    if (support.size() < static_cast<std::size_t>(options.min_support_samples)) continue;
    // The grid returns indices cell by cell; sorting makes the strided subset
    // (and the float sums) independent of the grid's cell order.
    std::sort(support.begin(), support.end());
    const std::size_t m = std::min<std::size_t>(support.size(), options.max_support_samples);
    chosen.resize(m);
    for (std::size_t k = 0; k < m; ++k) chosen[k] = support[k * support.size() / m];

    histogram.Clear();
    auto relate = [&](const Vec3f& pi, const Vec3f& ni, const Vec3f& pj, const Vec3f& nj) {
      const Vec3f v = pj - pi;
      const float length = Norm(v);
      if (!(length > 0)) return;  // coincident samples have no direction
      const Vec3f u = v * (1.0f / length);
      histogram.Add(std::min(1.0f, length * inv_span),
                    std::fabs(Dot(ni, nj)),
                    std::fabs(Dot(ni, u)),
                    std::fabs(Dot(nj, u)));
    };
    if (pairs) {
      for (std::size_t a = 0; a < m; ++a) {
        const Vec3f& pa = samples.positions[chosen[a]];
        const Vec3f& na = samples.normals[chosen[a]];
        for (std::size_t b = a + 1; b < m; ++b) {
          relate(pa, na, samples.positions[chosen[b]], samples.normals[chosen[b]]);
        }
      }
    } else {
      for (uint32_t j : chosen) {
        relate(centres.positions[c], centres.normals[c], samples.positions[j], samples.normals[j]);
      }
    }
    histogram.Emit(&features.descriptors);
    const Vec3f n = centres.normals[c];
    features.keypoints.push_back({centres.positions[c], n, Perpendicular(n), static_cast<float>(s), 0});
  }
  if (features.keypoints.empty()) {
    return absl::InvalidArgumentError(absl::StrCat(
        "LSF found no feature centre with at least ", options.min_support_samples,
        " support samples (", count, " samples, support radius ", s, ")"));
  }
  return features;
}

}  // namespace meshseek
