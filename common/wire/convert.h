// Protobuf messages (proto/meshseek/v1) <-> the algorithm core's types.
// Every conversion from the wire checks what the core relies on and returns
// InvalidArgument naming the field and the bad value; conversions to the wire
// cannot fail.
#ifndef MESHSEEK_COMMON_WIRE_CONVERT_H_
#define MESHSEEK_COMMON_WIRE_CONVERT_H_

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "common/features/local_features.h"
#include "common/geometry/mesh.h"
#include "common/geometry/mesh_io.h"
#include "common/geometry/point_graph.h"
#include "common/pipeline/collection_options.h"
#include "common/pipeline/retrieval_pipeline.h"
#include "common/search/sparse_histogram.h"
#include "meshseek/v1/types.pb.h"

namespace meshseek::wire {

// A mesh from arrays or from a file's bytes (read by the same readers as
// ReadMesh; errors name the file by MeshFile.name), within `limits`.
// Validated (ValidateMesh).
absl::StatusOr<TriangleMesh> MeshFromProto(const v1::MeshInput& input,
                                           const MeshReadOptions& limits = {});
void MeshToProto(const TriangleMesh& mesh, v1::Mesh* out);

absl::StatusOr<LocalFeatures> FeaturesFromProto(const v1::LocalFeatures& features);
void FeaturesToProto(const LocalFeatures& features, v1::LocalFeatures* out);

// Checked with ValidatePointGraph; boundary flags are all 0 (point clouds).
absl::StatusOr<PointGraph> GraphFromProto(const v1::PointGraph& graph);
void GraphToProto(const PointGraph& graph, v1::PointGraph* out);

// The histogram as sent (no bins: a model without features), checked with
// SparseHistogram::Validate under `name` (which bounds the declared size
// before anything depends on it).
absl::StatusOr<SparseHistogram> SparseHistogramFromProto(const v1::SparseHistogram& histogram,
                                                         absl::string_view name);
void SparseHistogramToProto(const SparseHistogram& histogram, v1::SparseHistogram* out);
// The non-zero bins of `dense` (length = vocabulary size; empty = no features).
void HistogramToProto(const std::vector<float>& dense,
                      std::size_t vocabulary_size,
                      v1::SparseHistogram* out);

// A collection's options from parameters (the legacy fields, then the named
// values; common/pipeline/pipeline_params.h): parameters not given take the
// methods' defaults. Validated; InvalidArgument names the parameter.
absl::StatusOr<CollectionOptions> CollectionOptionsFromParams(const v1::PipelineParams& params);
// The canonical parameters of `options` (CollectionValuesOf): every
// parameter by name, nothing in the legacy fields. CollectionOptionsFromParams
// reads back the same options.
void CollectionParamsToProto(const CollectionOptions& options, v1::PipelineParams* out);

// One method's options: parameters that name one method without re-ranking
// (what extract and codebook requests carry); InvalidArgument otherwise.
absl::StatusOr<RetrievalPipelineOptions> PipelineOptionsFromParams(const v1::PipelineParams& params);
// The canonical parameters of one method as a collection of its own.
void PipelineParamsToProto(const RetrievalPipelineOptions& options, v1::PipelineParams* out);

}  // namespace meshseek::wire

#endif  // MESHSEEK_COMMON_WIRE_CONVERT_H_
