// Indexed triangle meshes: welding a triangle soup, face and vertex normals, triangle adjacency.
#pragma once

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string_view>

namespace tmm {

using Vertices = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;    // n x 3
using Triangles = Eigen::Matrix<int32_t, Eigen::Dynamic, 3, Eigen::RowMajor>;  // m x 3, indices into Vertices
// A triangle soup: one row per triangle, x1 y1 z1 x2 y2 z2 x3 y3 z3.
using Soup = Eigen::Matrix<double, Eigen::Dynamic, 9, Eigen::RowMajor>;
using Normals = Vertices;                                                      // unit vectors, one per row
using Adjacency = Triangles;                                                   // neighbour triangle or -1

// Read-only views, so numpy arrays and Eigen matrices are both taken without a copy.
using SoupRef = Eigen::Ref<const Soup>;
using VerticesRef = Eigen::Ref<const Vertices>;
using TrianglesRef = Eigen::Ref<const Triangles>;

struct Mesh {
  Vertices V;
  Triangles F;
};

// Welds the corners of `soup` into shared vertices: a corner joins the nearest existing vertex within
// distance `tol` (>= 0; 0 merges only identical points), else it starts a new vertex at its own position.
// Clustering is greedy in input order, so a chain of points each within `tol` of the next is not merged
// transitively beyond `tol` of its first point. Expected O(m): a hash grid of cells 16*tol wide, each
// holding a bounded number of vertices since vertices are created more than `tol` apart.
// Triangles that become degenerate (a repeated vertex, or zero area up to rounding) are dropped; their
// number is stored in `*degenerate_removed` when given. Triangle order is kept; vertices are numbered in
// order of first use, and only vertices of kept triangles are returned (every vertex is referenced).
// Throws std::invalid_argument for an empty soup, a non-finite coordinate (naming the triangle), a bad
// tolerance, too many triangles for 32-bit indices (3m > 2^31-1), a coordinate outside the kernel's range
// (tmm/util/range.hpp) or when no non-degenerate triangle remains.
// Here and below, progress(fraction) is called now and then from the calling thread (tmm::SerialProgress:
// every 20 ms, and 1.0 at the end); false cancels: throws tmm::Cancelled. Meshes of millions of triangles
// take seconds.
Mesh weld(const SoupRef& soup, double tol, std::size_t* degenerate_removed = nullptr,
          const std::function<bool(double)>& progress = {});

// Throws std::invalid_argument naming the first triangle with an index outside [0, V.rows()) or the
// first vertex with a non-finite coordinate or one outside the kernel's range. face_normals and
// vertex_normals validate with it.
void validate(const VerticesRef& V, const TrianglesRef& F);

// Throws std::invalid_argument naming the first vertex with a coordinate outside the kernel's range
// (|x| < kMaxCoordinate, tmm/util/range.hpp), its value and the range.
void require_vertices_in_range(const VerticesRef& V);

// Unit normal of each triangle, (p1 - p0) x (p2 - p0) normalised; (0, 0, 0) for a zero-area triangle.
Normals face_normals(const VerticesRef& V, const TrianglesRef& F, const std::function<bool(double)>& progress = {});
inline Normals face_normals(const Mesh& m) { return face_normals(m.V, m.F); }

// For triangle t and edge i = (F(t,i), F(t,(i+1)%3)): the other triangle sharing that edge (orientation
// is not required to agree), or -1 when the edge is a boundary edge or is non-manifold (shared by more
// than two triangles: no single neighbour exists, so it is reported like a boundary).
// Expected O(m) for bounded vertex valence. Indices must be >= 0 (std::invalid_argument otherwise).
Adjacency triangle_adjacency(const TrianglesRef& F, const std::function<bool(double)>& progress = {});
inline Adjacency triangle_adjacency(const Mesh& m) { return triangle_adjacency(m.F); }

// Vertex normal weightings of seed 000 section 3.2.
enum class NormalWeighting {
  Angle,  // MWA, eq 3.1: sum of incident face normals weighted by the corner angle at the vertex
  Area,   // MWAAT, eq 3.2: weighted by the incident face areas
  Meyer,  // eq 3.3-3.4: direction of the cotangent mean-curvature normal (see mesh.cpp for the fallbacks)
};

// "angle", "area" or "meyer"; std::invalid_argument naming the allowed values otherwise.
NormalWeighting parse_weighting(std::string_view name);
const char* weighting_name(NormalWeighting w);

// Unit normal per vertex, oriented like the incident face normals (which follow the triangle winding).
// A vertex used by no triangle of non-zero area gets (0, 0, 0).
Normals vertex_normals(const VerticesRef& V, const TrianglesRef& F, NormalWeighting w,
                       const std::function<bool(double)>& progress = {});
inline Normals vertex_normals(const Mesh& m, NormalWeighting w) { return vertex_normals(m.V, m.F, w); }

}  // namespace tmm
