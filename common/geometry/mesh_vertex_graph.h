// A mesh's own vertex connectivity, as LD-SIFT (Darom & Keller 2012) uses it:
// the 1-ring graph of the vertices, the open-boundary vertices and the vertex
// normals, all from OpenMesh's halfedge structure.
//
// The mesh is loaded into an OpenMesh triangle mesh face by face, the way
// OpenMesh's own importer does: a face that would make an edge non-manifold
// gets fresh copies of its three vertices. So a polygon soup becomes a set of
// disconnected triangles and a non-manifold seam is cut open, which is exactly
// why LD-SIFT needs clean, dense manifold meshes and why the paper's methods
// exist. Nothing here repairs that.
#ifndef MESHSEEK_COMMON_GEOMETRY_MESH_VERTEX_GRAPH_H_
#define MESHSEEK_COMMON_GEOMETRY_MESH_VERTEX_GRAPH_H_

#include <vector>

#include "common/geometry/mesh.h"
#include "common/geometry/point_graph.h"

namespace meshseek {

struct MeshVertexGraph {
  PointGraph graph;            // vertices of the OpenMesh mesh (copies included)
  std::vector<Vec3f> normals;  // unit vertex normals (OpenMesh: normalised sum of face normals)
  std::size_t duplicated_vertices;  // copies made for faces OpenMesh could not add
};

// Builds the graph of `mesh` (which must be valid). Zero-area triangles are
// skipped, as OpenMesh cannot orient them.
MeshVertexGraph BuildMeshVertexGraph(const TriangleMesh& mesh);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_GEOMETRY_MESH_VERTEX_GRAPH_H_
