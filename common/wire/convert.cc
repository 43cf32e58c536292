#include "common/wire/convert.h"

#include <cmath>
#include <cstdint>
#include <optional>

#include "absl/strings/str_cat.h"
#include "common/base/status_macros.h"
#include "common/geometry/mesh_io.h"
#include "common/pipeline/pipeline_params.h"

namespace meshseek::wire {
namespace {

std::optional<MeshFormat> FormatOf(v1::MeshFormat format) {
  switch (format) {
    case v1::MESH_FORMAT_OFF: return MeshFormat::kOff;
    case v1::MESH_FORMAT_OBJ: return MeshFormat::kObj;
    case v1::MESH_FORMAT_PLY: return MeshFormat::kPly;
    case v1::MESH_FORMAT_STL: return MeshFormat::kStl;
    default: return std::nullopt;
  }
}

// Reads a mesh file sent as bytes with the same parsers as files on disk,
// from memory. The declared format is the format tag, else the name's
// extension; the content decides where it is recognisable (ParseMesh). The
// default MeshReadOptions bound what the bytes may make the server allocate
// (the message itself is bounded by gRPC's maximum message size).
absl::StatusOr<TriangleMesh> ReadMeshFile(const v1::MeshFile& file, const MeshReadOptions& limits) {
  const std::string name = file.name().empty() ? "mesh file" : file.name();
  std::optional<MeshFormat> declared = FormatOf(file.format());
  if (!declared) {
    const absl::StatusOr<MeshFormat> by_name = MeshFormatFromPath(name);
    if (!by_name.ok() && !DetectMeshFormat(file.data())) return by_name.status();
    if (by_name.ok()) declared = *by_name;
  }
  return ParseMesh(file.data(), name, declared, limits);
}

}  // namespace

absl::StatusOr<TriangleMesh> MeshFromProto(const v1::MeshInput& input,
                                           const MeshReadOptions& limits) {
  TriangleMesh mesh;
  switch (input.source_case()) {
    case v1::MeshInput::kFile: {
      MESHSEEK_ASSIGN_OR_RETURN(mesh, ReadMeshFile(input.file(), limits));
      break;
    }
    case v1::MeshInput::kMesh: {
      const v1::Mesh& m = input.mesh();
      if (m.vertices_size() % 3 != 0 || m.triangles_size() % 3 != 0) {
        return absl::InvalidArgumentError(
            absl::StrCat("mesh: ", m.vertices_size(), " vertex values and ", m.triangles_size(),
                         " triangle indices; both must be multiples of 3"));
      }
      // The same limits as a mesh sent as a file: arrays are already in
      // memory, but every later stage allocates a multiple of their size.
      if (static_cast<uint64_t>(m.vertices_size() / 3) > limits.max_vertices ||
          static_cast<uint64_t>(m.triangles_size() / 3) > limits.max_triangles) {
        return absl::ResourceExhaustedError(absl::StrCat(
            "mesh: ", m.vertices_size() / 3, " vertices and ", m.triangles_size() / 3,
            " triangles, more than the limits of ", limits.max_vertices, " (max_vertices) and ",
            limits.max_triangles, " (max_triangles)"));
      }
      mesh.vertices.resize(m.vertices_size() / 3);
      for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
        mesh.vertices[i] = Vec3f(m.vertices(3 * i), m.vertices(3 * i + 1), m.vertices(3 * i + 2));
      }
      mesh.triangles.resize(m.triangles_size() / 3);
      for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
        mesh.triangles[t] = {m.triangles(3 * t), m.triangles(3 * t + 1), m.triangles(3 * t + 2)};
      }
      break;
    }
    default:
      return absl::InvalidArgumentError("mesh: neither arrays nor a file were given");
  }
  if (absl::Status valid = ValidateMesh(mesh); !valid.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("mesh: ", valid.message()));
  }
  return mesh;
}

void MeshToProto(const TriangleMesh& mesh, v1::Mesh* out) {
  out->Clear();
  out->mutable_vertices()->Reserve(static_cast<int>(3 * mesh.vertices.size()));
  for (const Vec3f& v : mesh.vertices) {
    out->add_vertices(v.x);
    out->add_vertices(v.y);
    out->add_vertices(v.z);
  }
  out->mutable_triangles()->Reserve(static_cast<int>(3 * mesh.triangles.size()));
  for (const Triangle& t : mesh.triangles) {
    for (uint32_t v : t) out->add_triangles(v);
  }
}

absl::StatusOr<LocalFeatures> FeaturesFromProto(const v1::LocalFeatures& f) {
  const std::size_t n = f.count();
  // An empty set may leave the dimension unset.
  const std::size_t dim = n == 0 && f.dimension() == 0 ? kSiftDimension : f.dimension();
  if (dim == 0 || dim > kMaxDescriptorDimension) {
    return absl::InvalidArgumentError(absl::StrCat(
        "local features: descriptor dimension ", dim, ", expected 1 to ", kMaxDescriptorDimension));
  }
  if (f.descriptors().size() != n * dim) {
    return absl::InvalidArgumentError(absl::StrCat("local features: ",
                                                   f.descriptors().size(),
                                                   " descriptor bytes for ",
                                                   n,
                                                   " features of ",
                                                   dim,
                                                   " (need ",
                                                   n * dim,
                                                   ")"));
  }
  const bool has_keypoints = f.positions_size() > 0;
  if (has_keypoints &&
      (static_cast<std::size_t>(f.positions_size()) != 3 * n ||
       static_cast<std::size_t>(f.views_size()) != 3 * n ||
       static_cast<std::size_t>(f.ups_size()) != 3 * n ||
       static_cast<std::size_t>(f.scales_size()) != n ||
       static_cast<std::size_t>(f.levels_size()) != n)) {
    return absl::InvalidArgumentError(
        absl::StrCat("local features: keypoint arrays do not match the count ", n));
  }
  LocalFeatures features;
  features.dimension = dim;
  features.descriptors.assign(f.descriptors().begin(), f.descriptors().end());
  features.keypoints.resize(n);
  if (has_keypoints) {
    for (std::size_t i = 0; i < n; ++i) {
      Keypoint& k = features.keypoints[i];
      k.position = Vec3f(f.positions(3 * i), f.positions(3 * i + 1), f.positions(3 * i + 2));
      k.view = Vec3f(f.views(3 * i), f.views(3 * i + 1), f.views(3 * i + 2));
      k.up = Vec3f(f.ups(3 * i), f.ups(3 * i + 1), f.ups(3 * i + 2));
      k.scale = f.scales(i);
      k.level = f.levels(i);
      // Keypoints are drawn and stored; a NaN would travel silently.
      if (!IsFinite(k.position) || !IsFinite(k.view) || !IsFinite(k.up) ||
          !std::isfinite(k.scale) || k.scale < 0 || k.level < 0) {
        return absl::InvalidArgumentError(absl::StrCat(
            "local features: keypoint ", i, " has a non-finite or negative value (position ",
            k.position.x, " ", k.position.y, " ", k.position.z, ", view ", k.view.x, " ",
            k.view.y, " ", k.view.z, ", up ", k.up.x, " ", k.up.y, " ", k.up.z, ", scale ",
            k.scale, ", level ", k.level, ")"));
      }
    }
  }
  return features;
}

void FeaturesToProto(const LocalFeatures& features, v1::LocalFeatures* out) {
  out->Clear();
  out->set_count(static_cast<uint32_t>(features.size()));
  out->set_dimension(static_cast<uint32_t>(features.dimension));
  out->set_descriptors(features.descriptors.data(), features.descriptors.size());
  for (const Keypoint& k : features.keypoints) {
    for (const Vec3f* v : {&k.position, &k.view, &k.up}) {
      auto* field = v == &k.position ? out->mutable_positions()
                    : v == &k.view   ? out->mutable_views()
                                     : out->mutable_ups();
      field->Add(v->x);
      field->Add(v->y);
      field->Add(v->z);
    }
    out->add_scales(k.scale);
    out->add_levels(k.level);
  }
}

absl::StatusOr<PointGraph> GraphFromProto(const v1::PointGraph& g) {
  if (g.positions_size() % 3 != 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("point graph: ", g.positions_size(), " position values, not a multiple of 3"));
  }
  PointGraph graph;
  graph.positions.resize(g.positions_size() / 3);
  for (std::size_t i = 0; i < graph.positions.size(); ++i) {
    graph.positions[i] = Vec3f(g.positions(3 * i), g.positions(3 * i + 1), g.positions(3 * i + 2));
  }
  graph.offsets.assign(g.offsets().begin(), g.offsets().end());
  graph.neighbors.assign(g.neighbors().begin(), g.neighbors().end());
  graph.boundary.assign(graph.positions.size(), 0);
  MESHSEEK_RETURN_IF_ERROR(ValidatePointGraph(graph));
  return graph;
}

void GraphToProto(const PointGraph& graph, v1::PointGraph* out) {
  out->Clear();
  out->mutable_positions()->Reserve(static_cast<int>(3 * graph.size()));
  for (const Vec3f& p : graph.positions) {
    out->add_positions(p.x);
    out->add_positions(p.y);
    out->add_positions(p.z);
  }
  out->mutable_offsets()->Add(graph.offsets.begin(), graph.offsets.end());
  out->mutable_neighbors()->Add(graph.neighbors.begin(), graph.neighbors.end());
}

absl::StatusOr<SparseHistogram> SparseHistogramFromProto(const v1::SparseHistogram& h,
                                                         absl::string_view name) {
  SparseHistogram histogram;
  histogram.vocabulary = h.size();
  histogram.words.assign(h.bins().begin(), h.bins().end());
  histogram.weights.assign(h.weights().begin(), h.weights().end());
  // The weights of a histogram sum to 1; the tolerance is the core's default.
  MESHSEEK_RETURN_IF_ERROR(histogram.Validate(name, KlDivergenceOptions().sum_tolerance));
  return histogram;
}

void SparseHistogramToProto(const SparseHistogram& histogram, v1::SparseHistogram* out) {
  out->Clear();
  out->set_size(histogram.vocabulary);
  out->mutable_bins()->Add(histogram.words.begin(), histogram.words.end());
  out->mutable_weights()->Add(histogram.weights.begin(), histogram.weights.end());
}

void HistogramToProto(const std::vector<float>& dense,
                      std::size_t vocabulary_size,
                      v1::SparseHistogram* out) {
  out->Clear();
  out->set_size(static_cast<uint32_t>(vocabulary_size));
  for (std::size_t i = 0; i < dense.size(); ++i) {
    if (dense[i] != 0.0f) {
      out->add_bins(static_cast<uint32_t>(i));
      out->add_weights(dense[i]);
    }
  }
}

namespace {

// The named values of a message written before PipelineParams.values: each
// nonzero legacy field that applies to the method, in its old meaning (one
// field set a value for every method that has it; zero kept the default).
// Frozen: new parameters exist only as names.
absl::StatusOr<ParamValues> LegacyValues(const v1::PipelineParams& p) {
  ParamValues values;
  FeatureMethod method = FeatureMethod::kDldSift;
  switch (p.method()) {
    case v1::FEATURE_METHOD_UNSPECIFIED:
    case v1::FEATURE_METHOD_DLD:
      method = FeatureMethod::kDldSift;
      break;
    case v1::FEATURE_METHOD_LD:
      method = FeatureMethod::kLdSift;
      break;
    case v1::FEATURE_METHOD_RLD:
      method = FeatureMethod::kRldSift;
      break;
    default:
      return absl::InvalidArgumentError(absl::StrCat("params: unknown method ", p.method()));
  }
  values.emplace_back("method", FeatureMethodName(method));
  auto add = [&](const char* name, auto value) {
    const ParamSpec* spec = FindPipelineParam(name);
    if (value != decltype(value){} && spec != nullptr && spec->AppliesTo(method)) {
      values.emplace_back(name, absl::StrCat(value));
    }
  };
  add("scale", p.scale());
  add("points", p.num_points());
  add("frame_samples", p.frame_samples_per_support());
  add("frame_radius", p.frame_radius_factor());
  if (p.has_weighted_frame()) add("weighted_frame", p.weighted_frame() ? "true" : "false");
  add("rld_samples", p.rld_samples());
  add("rld_neighbors", p.rld_neighbors());
  add("levels", p.levels());
  add("scale_factor",
      method == FeatureMethod::kLdSift ? p.ld_scale_factor() : p.rld_scale_factor());
  add("image_size", p.image_size());
  add("orientation", p.orientation());
  add("depth_to_gray", p.depth_to_gray());
  add("blur_sigma", p.blur_sigma());
  add("max_orientations", p.max_orientations());
  add("vocabulary", p.vocabulary());
  add("kmeans_points_per_centroid", p.kmeans_points_per_centroid());
  add("kmeans_iterations", p.kmeans_iterations());
  add("seed", p.seed());
  add("kl_epsilon", p.kl_epsilon());
  add("kmeans_assignment", p.kmeans_assignment());
  return values;
}

}  // namespace

namespace {

absl::StatusOr<ParamValues> AllValues(const v1::PipelineParams& p) {
  MESHSEEK_ASSIGN_OR_RETURN(ParamValues values, LegacyValues(p));
  for (const v1::ParamValue& value : p.values()) values.emplace_back(value.name(), value.value());
  return values;
}

template <typename T>
absl::StatusOr<T> Prefixed(absl::StatusOr<T> options) {
  if (options.ok()) return options;
  return absl::Status(options.status().code(),
                      absl::StrCat("params: ", options.status().message()));
}

void ValuesToProto(const ParamValues& values, v1::PipelineParams* out) {
  out->Clear();
  for (const auto& [name, value] : values) {
    v1::ParamValue* v = out->add_values();
    v->set_name(name);
    v->set_value(value);
  }
}

}  // namespace

absl::StatusOr<CollectionOptions> CollectionOptionsFromParams(const v1::PipelineParams& p) {
  MESHSEEK_ASSIGN_OR_RETURN(const ParamValues values, AllValues(p));
  return Prefixed(CollectionOptionsFromValues(values));
}

void CollectionParamsToProto(const CollectionOptions& options, v1::PipelineParams* out) {
  ValuesToProto(CollectionValuesOf(options), out);
}

absl::StatusOr<RetrievalPipelineOptions> PipelineOptionsFromParams(const v1::PipelineParams& p) {
  MESHSEEK_ASSIGN_OR_RETURN(const ParamValues values, AllValues(p));
  return Prefixed(PipelineOptionsFromValues(values));
}

void PipelineParamsToProto(const RetrievalPipelineOptions& options, v1::PipelineParams* out) {
  ValuesToProto(PipelineValuesOf(options), out);
}

}  // namespace meshseek::wire
