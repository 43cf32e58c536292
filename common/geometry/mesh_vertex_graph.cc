#include "common/geometry/mesh_vertex_graph.h"

#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>

namespace meshseek {
namespace {

using OmMesh = OpenMesh::TriMesh_ArrayKernelT<>;

}  // namespace

MeshVertexGraph BuildMeshVertexGraph(const TriangleMesh& mesh) {
  OmMesh om;
  om.request_vertex_normals();
  om.request_face_normals();
  std::vector<OmMesh::VertexHandle> handles;
  handles.reserve(mesh.vertices.size());
  for (const Vec3f& p : mesh.vertices)
    handles.push_back(om.add_vertex(OmMesh::Point(p.x, p.y, p.z)));
  MeshVertexGraph result;
  result.duplicated_vertices = 0;
  std::vector<OmMesh::VertexHandle> face(3);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    if (!(TriangleArea(mesh, t) > 0)) continue;
    for (int k = 0; k < 3; ++k) face[k] = handles[mesh.triangles[t][k]];
    if (om.add_face(face).is_valid()) continue;
    // Complex edge or vertex: separate the face, as OpenMesh's importer does.
    for (int k = 0; k < 3; ++k) face[k] = om.add_vertex(om.point(face[k]));
    result.duplicated_vertices += 3;
    om.add_face(face);
  }
  om.update_face_normals();
  om.update_vertex_normals();

  std::vector<Vec3f> positions;
  positions.reserve(om.n_vertices());
  std::vector<std::pair<uint32_t, uint32_t>> edges;
  edges.reserve(om.n_edges());
  for (const auto vh : om.vertices()) {
    const auto& p = om.point(vh);
    positions.emplace_back(p[0], p[1], p[2]);
  }
  for (const auto eh : om.edges()) {
    const auto heh = om.halfedge_handle(eh, 0);
    edges.emplace_back(om.from_vertex_handle(heh).idx(), om.to_vertex_handle(heh).idx());
  }
  result.graph = MakePointGraph(std::move(positions), edges);
  result.normals.reserve(om.n_vertices());
  for (const auto vh : om.vertices()) {
    result.graph.boundary[vh.idx()] = om.is_boundary(vh) ? 1 : 0;
    const auto& n = om.normal(vh);
    result.normals.push_back(Vec3f(Normalized(Vec3d(n[0], n[1], n[2]))));
  }
  return result;
}

}  // namespace meshseek
