#pragma once
// The mesh's passes that report into a caller's SerialProgress (mesh.cpp), shared with vertex_normals.cpp so that
// each normal weighting reports its parts of one job.
#include <cstdint>

#include "tmm/mesh/mesh.hpp"
#include "tmm/util/parallel.hpp"

namespace tmm::mesh_passes {

inline constexpr int32_t kNone = -1;  // no vertex, no neighbour

inline Eigen::Vector3d vertex(const VerticesRef& V, int32_t i) { return V.row(i).transpose(); }

// validate(), ticking over the triangles.
void check_mesh(const VerticesRef& V, const TrianglesRef& F, SerialProgress& progress);

// Face normals without validation; zero rows for zero-area faces.
Normals unit_face_normals(const VerticesRef& V, const TrianglesRef& F, SerialProgress& progress);

// triangle_adjacency, reporting within [lo, hi] of the job.
Adjacency adjacency(const TrianglesRef& F, SerialProgress& progress, double lo, double hi);

}  // namespace tmm::mesh_passes
