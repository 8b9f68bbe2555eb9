// Vertex normals of a triangle mesh by seed 000's weightings (section 3.2): MWA, MWAAT and Meyer's.
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "mesh_passes.hpp"
#include "tmm/mesh/mesh.hpp"
#include "tmm/util/parallel.hpp"

namespace tmm {
using mesh_passes::adjacency;
using mesh_passes::check_mesh;
using mesh_passes::kNone;
using mesh_passes::unit_face_normals;
using mesh_passes::vertex;

namespace {
using Vec3 = Eigen::Vector3d;
}  // namespace

NormalWeighting parse_weighting(std::string_view name) {
  if (name == "angle") return NormalWeighting::Angle;
  if (name == "area") return NormalWeighting::Area;
  if (name == "meyer") return NormalWeighting::Meyer;
  throw std::invalid_argument("unknown vertex normal weighting '" + std::string(name) +
                              "' (allowed: 'angle', 'area', 'meyer')");
}

const char* weighting_name(NormalWeighting w) {
  switch (w) {
    case NormalWeighting::Angle: return "angle";
    case NormalWeighting::Area: return "area";
    case NormalWeighting::Meyer: return "meyer";
  }
  return "?";
}

// Seed 000 section 3.2 and where it is vague:
// - MWA (eq 3.1) and MWAAT (eq 3.2) are implemented as written, then normalised.
// - Meyer (eq 3.3) is the cotangent discretisation of the mean-curvature normal K = 2 H n of Meyer et
//   al. 2002, K(v) = 1/(2 A_mixed) * sum_j (cot a_ij + cot b_ij) (v - v_j). The seed calls K itself the
//   normal, but K vanishes where H = 0 (planes; saddles with opposite principal curvatures), flips its
//   sign between convex and concave regions, is only valid on a closed one-ring, and on irregular
//   tessellations has a tangential error of the order of the principal curvatures (it does not converge
//   pointwise). So only K's direction is used, oriented like the angle-weighted normal, and the
//   angle-weighted normal is kept instead when
//     * the vertex is on a boundary or non-manifold edge, or touches a zero-area triangle;
//     * |K| * sqrt(A_mixed) < 1e-6: flat up to rounding;
//     * |K| * sqrt(A_mixed) < the spread of the incident face normals around the angle-weighted normal
//       (max |n_f - n_angle|, about principal curvature x ring size): the mean curvature is too small
//       for K's direction to beat its tangential error (on a saddle it would be off by tens of degrees);
//     * K's direction is more than 60 degrees from the angle-weighted normal (a last sanity check).
// - The seed's A_mixed rule (eq 3.4 and text) says "the facet's area" for a non-obtuse triangle, where
//   Meyer et al. use the Voronoi area (1/8) (|v-v_j|^2 cot(angle at k) + |v-v_k|^2 cot(angle at j)); the
//   Voronoi area is used here; obtuse triangles contribute A/2 (obtuse at v) or A/4 as in the seed.
//   A_mixed only scales K, so it matters for the tests above, not for the direction.
namespace {

// Eq 3.1 (angle) or eq 3.2 (area), normalised.
Normals weighted_normals(const VerticesRef& V, const TrianglesRef& F, const Normals& FN, NormalWeighting w,
                         SerialProgress& progress) {
  Normals sum = Normals::Zero(V.rows(), 3);
  const auto items = static_cast<std::size_t>(F.rows() + V.rows());
  for (Eigen::Index t = 0; t < F.rows(); ++t) {
    progress.tick(static_cast<std::size_t>(t), items);
    const Vec3 p[3] = {vertex(V, F(t, 0)), vertex(V, F(t, 1)), vertex(V, F(t, 2))};
    const Vec3 c = (p[1] - p[0]).cross(p[2] - p[0]);
    for (int i = 0; i < 3; ++i) {
      const Vec3 u = p[(i + 1) % 3] - p[i], x = p[(i + 2) % 3] - p[i];
      if (w == NormalWeighting::Area)
        sum.row(F(t, i)) += 0.5 * c.transpose();  // area x unit normal
      else
        sum.row(F(t, i)) += std::atan2(u.cross(x).norm(), u.dot(x)) * FN.row(t);  // robust for any angle
    }
  }
  for (Eigen::Index v = 0; v < sum.rows(); ++v) {
    progress.tick(static_cast<std::size_t>(F.rows() + v), items);
    const double len = sum.row(v).norm();
    sum.row(v) = (len > 0 ? Vec3(sum.row(v).transpose() / len) : Vec3::Zero()).transpose();
  }
  return sum;
}

// Replaces the angle-weighted normals N by the direction of Meyer's K where it is meaningful; reports
// within [lo, hi] of the job (the adjacency is about half of the time).
void apply_meyer(const VerticesRef& V, const TrianglesRef& F, const Normals& FN, Normals& N,
                 SerialProgress& progress, double lo, double hi) {
  const Eigen::Index n = V.rows();
  Normals K = Normals::Zero(n, 3);
  Eigen::VectorXd mixed_area = Eigen::VectorXd::Zero(n);
  Eigen::VectorXd spread = Eigen::VectorXd::Zero(n);  // max |n_f - N(v)| over the incident faces
  std::vector<char> usable(static_cast<std::size_t>(n), 1);

  const double third = (hi - lo) / 3;
  progress.part(lo, lo + third);
  for (Eigen::Index t = 0; t < F.rows(); ++t) {
    progress.tick(static_cast<std::size_t>(t), static_cast<std::size_t>(F.rows()));
    const Vec3 p[3] = {vertex(V, F(t, 0)), vertex(V, F(t, 1)), vertex(V, F(t, 2))};
    const double twice_area = (p[1] - p[0]).cross(p[2] - p[0]).norm();
    if (!(twice_area > 0)) {  // cotangents undefined
      for (int i = 0; i < 3; ++i) usable[static_cast<std::size_t>(F(t, i))] = 0;
      continue;
    }
    double dot[3], cot[3];
    for (int i = 0; i < 3; ++i) {
      dot[i] = (p[(i + 1) % 3] - p[i]).dot(p[(i + 2) % 3] - p[i]);
      cot[i] = dot[i] / twice_area;  // |u x v| is twice the area at every corner
    }
    const bool obtuse = dot[0] < 0 || dot[1] < 0 || dot[2] < 0;
    for (int i = 0; i < 3; ++i) {
      const int j = (i + 1) % 3, k = (i + 2) % 3;
      const int32_t v = F(t, i);
      // Edge v-p[j] is opposite corner k in this triangle, edge v-p[k] opposite corner j.
      K.row(v) += (cot[k] * (p[i] - p[j]) + cot[j] * (p[i] - p[k])).transpose();
      mixed_area[v] += !obtuse ? ((p[j] - p[i]).squaredNorm() * cot[k] + (p[k] - p[i]).squaredNorm() * cot[j]) / 8
                               : (dot[i] < 0 ? twice_area / 4 : twice_area / 8);
      spread[v] = std::max(spread[v], (FN.row(t) - N.row(v)).norm());
    }
  }
  const Adjacency adj = adjacency(F, progress, lo + third, hi - third);
  progress.part(hi - third, hi);
  for (Eigen::Index t = 0; t < F.rows(); ++t) {
    progress.tick(static_cast<std::size_t>(t), static_cast<std::size_t>(F.rows() + n));
    for (int i = 0; i < 3; ++i)
      if (adj(t, i) == kNone) {  // both ends of a boundary or non-manifold edge
        usable[static_cast<std::size_t>(F(t, i))] = 0;
        usable[static_cast<std::size_t>(F(t, (i + 1) % 3))] = 0;
      }
  }
  for (Eigen::Index v = 0; v < n; ++v) {
    progress.tick(static_cast<std::size_t>(F.rows() + v), static_cast<std::size_t>(F.rows() + n));
    if (!usable[static_cast<std::size_t>(v)] || !(mixed_area[v] > 0) || N.row(v).isZero()) continue;
    const Vec3 nv = N.row(v).transpose();
    const Vec3 kv = K.row(v).transpose() / (2 * mixed_area[v]);
    const double size = kv.norm() * std::sqrt(mixed_area[v]);  // ~ |H| x ring size, dimensionless
    if (size < 1e-6 || size < spread[v]) continue;
    const Vec3 dir = (kv.dot(nv) < 0 ? -kv : kv).normalized();
    if (dir.dot(nv) >= 0.5) N.row(v) = dir.transpose();
  }
}

}  // namespace

Normals vertex_normals(const VerticesRef& V, const TrianglesRef& F, NormalWeighting w,
                       const std::function<bool(double)>& progress) {
  // Parts by their measured share of the time: the face normals are nearly half of the plain weightings.
  const bool meyer = w == NormalWeighting::Meyer;
  SerialProgress reporter(progress);
  reporter.part(0.0, 0.02);
  check_mesh(V, F, reporter);
  reporter.part(0.02, meyer ? 0.25 : 0.45);
  const Normals FN = unit_face_normals(V, F, reporter);
  reporter.part(meyer ? 0.25 : 0.45, meyer ? 0.55 : 1.0);
  Normals N = weighted_normals(V, F, FN, w == NormalWeighting::Area ? NormalWeighting::Area : NormalWeighting::Angle,
                               reporter);
  if (meyer) apply_meyer(V, F, FN, N, reporter, 0.55, 1.0);
  reporter.finish();
  return N;
}

}  // namespace tmm
