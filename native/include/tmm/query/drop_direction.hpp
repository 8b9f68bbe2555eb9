// Drop along any direction with the cutter axis in any orientation (seed 000 eq. 3.126-3.188: clean-up by
// translating the cutter along a vector V; fixed tilted axes give 3+2 machining).
//
// The cutter solid is its cutting part only, in the tool frame (tip at the origin, axis +z):
//   K = { h(rho) <= z <= L_C, rho <= max_radius }.
// The shank and holder above L_C are NOT checked. For beta2 < 0 (inward taper) K is the cylinder of radius
// max_radius above the arc's widest point: larger than the real tool there, so the answer is conservative.
// K is convex (h is convex and non-decreasing), which is what makes every contact below exact and robust.
//
// The cutter moves with its tip at start + t V from t = -inf; the travel of the first contact is returned
// (+inf when it never touches). For V = -Z the travel is start.z minus the usual drop-cutter tip height.
// See docs/drop_direction.md for the method and the tolerances.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "tmm/cutter/cutter.hpp"
#include "tmm/query/drop_cutter.hpp"
#include "tmm/mesh/mesh.hpp"
#include "tmm/mesh/mesh_index.hpp"

namespace tmm {

constexpr double kNoTravel = std::numeric_limits<double>::infinity();

// Orthonormal tool frame (e1, e2, axis) for a unit axis.
struct ToolFrame {
  Eigen::Vector3d e1, e2, a;
  explicit ToolFrame(const Eigen::Vector3d& axis);
  Eigen::Vector3d to_tool(const Eigen::Vector3d& w) const { return {e1.dot(w), e2.dot(w), a.dot(w)}; }
  Eigen::Vector3d to_world(const Eigen::Vector3d& q) const { return e1 * q.x() + e2 * q.y() + a * q.z(); }
};

// First-contact travel of the cutter against one triangle. axis and V must be unit vectors
// (std::invalid_argument otherwise). When V = -axis the existing exact -Z contacts are used in the tool frame
// (edge_drop's concave form); otherwise drop_along_general.
double drop_along(const Cutter& cutter, const Eigen::Vector3d& tip_start, const Eigen::Vector3d& axis,
                  const Eigen::Vector3d& V, const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
                  const Eigen::Vector3d& p2);
double drop_along(const Cutter& cutter, const Eigen::Vector3d& tip_start, const Eigen::Vector3d& axis,
                  const Eigen::Vector3d& V, const IndexedTriangle& t);
// The convex formulation for any V and axis, without the V = -axis shortcut (exposed for cross-checks).
double drop_along_general(const Cutter& cutter, const Eigen::Vector3d& tip_start, const Eigen::Vector3d& axis,
                          const Eigen::Vector3d& V, const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
                          const Eigen::Vector3d& p2);

// Pieces of the general method, in the tool frame with the start tip at the origin; W = V in tool coordinates.
namespace direction_detail {
// |axis + V| below which the axis counts as opposite to the direction (the -Z drop in the rotated frame).
constexpr double kParallelAxisTol = 1e-12;
// std::invalid_argument naming `what` unless v is a finite unit vector (within 1e-9).
void require_unit(const Eigen::Vector3d& v, const char* what);
// Point of K extreme in direction d (maximising d . X); value = d . X (+inf when unbounded: L_C = inf).
struct Support {
  Eigen::Vector3d point;
  double value;
};
Support support(const Cutter& c, const Eigen::Vector3d& d);
// Each returns the first-contact travel if it is below `cap`, else kNoTravel (only earlier contacts matter
// in a mesh query, which lets most candidates stop early).
double vertex_travel(const Cutter& c, const Eigen::Vector3d& q, const Eigen::Vector3d& W, double cap = kNoTravel);
// normal (or null): set to K's outward normal at the contact when one is returned.
double edge_travel(const Cutter& c, const Eigen::Vector3d& q1, const Eigen::Vector3d& q2, const Eigen::Vector3d& W,
                   double cap = kNoTravel, Eigen::Vector3d* normal = nullptr);
double facet_travel(const Cutter& c, const Eigen::Vector3d& q0, const Eigen::Vector3d& q1, const Eigen::Vector3d& q2,
                    const Eigen::Vector3d& W, double cap = kNoTravel);
// The triangle's first contact before cap (kNoTravel if none): facet, vertices and the edges selected by bit k
// of `edges` (corner k to k + 1; see IndexedTriangle::owned_edges). normal (or null): K's outward normal at
// that contact (a normal of its plane of support there; not unit), when one is returned.
double triangle_travel(const Cutter& c, const Eigen::Vector3d& q0, const Eigen::Vector3d& q1,
                       const Eigen::Vector3d& q2, const Eigen::Vector3d& W, double cap = kNoTravel,
                       unsigned edges = 7u, Eigen::Vector3d* normal = nullptr);
// std::invalid_argument for an endless cutter (L_C = inf): the general method needs a bounded solid.
void require_finite_length(const Cutter& c);
}  // namespace direction_detail

class DirectionalIndex;

namespace direction_detail {
// Start points seen in the frame where V = -Z: their (x, y) and heights, and each one's floor max_travel below.
struct RotatedStarts {
  std::vector<double> xy, z, floors;
  RotatedStarts(const DirectionalIndex& index, const double* starts, std::size_t n, double max_travel);
  // The travel to tip height `tip` of start i: max_travel where nothing lifted it above the floor.
  double travel(std::size_t i, double tip, double max_travel) const {
    return tip <= floors[i] ? max_travel : z[i] - tip;
  }
};
}  // namespace direction_detail

// A mesh indexed for drops along one direction V: the mesh rotated so that V = -Z' and indexed by MeshIndex
// (XY' bounding volume hierarchy with heights). Built once per direction (3+2 jobs keep it fixed).
class DirectionalIndex {
 public:
  // V must be a unit vector; std::invalid_argument otherwise or for a bad mesh. For V = -Z exactly the
  // rotation is the identity and the index is the plain drop-cutter index. threads: as for MeshIndex.
  DirectionalIndex(const VerticesRef& vertices, const TrianglesRef& triangles, const Eigen::Vector3d& V,
                   int threads = 0);

  const Eigen::Vector3d& direction() const { return V_; }
  const Eigen::Matrix3d& rotation() const { return rot_; }  // world -> frame in which V = -Z'
  const MeshIndex& index() const { return *index_; }

 private:
  Eigen::Vector3d V_;
  Eigen::Matrix3d rot_;
  std::shared_ptr<const MeshIndex> index_;
};

// One start point: the smallest travel of a contact with any triangle, capped at max_travel (returned when
// nothing is touched before it). With axis = -V (any V) this is drop_point in the rotated frame; otherwise the
// cutter must have a finite cutting length (std::invalid_argument). `hint` as for drop_point.
double drop_along_point(const DirectionalIndex& index, const Cutter& cutter, const Eigen::Vector3d& start,
                        const Eigen::Vector3d& axis, double max_travel = kNoTravel, DropStats* stats = nullptr,
                        int32_t* hint = nullptr);

// A cutter set up for drops along the index's direction with one tool axis that is not -V (the general
// method): the per-axis work of drop_along_point done once (the tool frame, the motion in it, the solid's
// lowest point, its supporting planes from below that bound the walk of the index). The index must outlive it.
class AlongCutter {
 public:
  // axis: a unit vector in the model's frame, not -V; std::invalid_argument otherwise or for an endless cutter.
  // fine_planes: also set up planes under K every few degrees around the axis (some 700 support values,
  // worth it when many starts share the set-up), so that each candidate triangle meets the few facing it.
  AlongCutter(const DirectionalIndex& index, const Cutter& cutter, const Eigen::Vector3d& axis,
              bool fine_planes = false);
  // drop_along_point with this cutter and axis.
  double drop(const Eigen::Vector3d& start, double max_travel = kNoTravel, DropStats* stats = nullptr,
              int32_t* hint = nullptr) const;

  // Below the XY' offset p from the tip, K is no lower than c - g . p (a plane under K).
  struct Plane {
    double c, gx, gy;
  };
  // The candidate triangles of a group of nearby starts (a tile), kept from tile to tile: each with its
  // bounds and two planes under K it is most nearly below (at the group's worst start, at its centre), by
  // which most of them are proven missed from one start in a few products.
  struct Candidate {
    int32_t tri;
    double zmax, xmin, xmax, ymin, ymax;
    double h[2], gx[2], gy[2];  // planes under K, c - g . p: max over the corners of z + g . xy, less c
    double key;                 // h of the key plane
    double wlo, whi;            // the XY' bounds' range across the axis's shadow (AlongCutter::across)
    Eigen::Vector3d plane;      // the normal (tool frame) that last proved it clear of a start, or zero
  };
  struct Candidates {
    // In runs of one centre plane (h[1]'s slope), each by decreasing h[1]: a start leaves a run at its first
    // entry below that plane (the rest lie lower), so most of a list is passed over a run at a time.
    std::vector<Candidate> list;
    struct Run {
      double gx, gy;
      std::size_t begin, end;
    };
    std::vector<Run> runs;
    // The plane under K along its axis (a flat end, which a tilted holder meets first; the key is the height
    // over it); without one (axis level) K's lowest point, the key the highest point.
    Plane key_plane{0.0, 0.0, 0.0};
    std::vector<double> offsets;  // per plane under K: the lowest over the starts of top + g . tip
    std::vector<Eigen::Vector3d> tips;  // the starts' tips at their caps (index frame)
    Eigen::Vector3d centre;             // their mean
    std::vector<char> fine_done;        // per azimuth: its fine planes' offsets are in
    std::vector<std::pair<double, Candidate*>> open;  // a start's scratch: the entries left, by their bound
  };
  // One walk of the index for m starts (model frame) with their caps (finite): into `out` every triangle
  // that may stop K before its cap from one of them, less those below one of K's planes at every start.
  // False, the list unfinished, when it would hold more than `limit` triangles.
  bool gather(const Eigen::Vector3d* starts, const double* caps, std::size_t m, Candidates& out,
              std::size_t limit) const;
  // drop() over a list gathered for this start with a cap of at least max_travel, in place of the walk: the
  // same travel. Each candidate keeps the plane that proved it clear, which the next start tries first.
  // `known` (or -1): a triangle already solved from this start (drop_on) with a cap of at least max_travel;
  // `tangent` (or null): the plane of support drop_on found with it.
  double drop_listed(const Eigen::Vector3d& start, double max_travel, Candidates& cands,
                     DropStats* stats = nullptr, int32_t* hint = nullptr, int32_t known = -1,
                     const Eigen::Vector4d* tangent = nullptr) const;
  // The first contact with the index's triangle `tri` alone, below max_travel (else max_travel): the travel a
  // walk finds for it, so an upper bound of drop() that is a contact of this solid. tangent (or null): set to
  // K's plane of support there (index frame: normal, level; level +inf for none), which proves every triangle
  // beyond it missed before that travel.
  double drop_on(const Eigen::Vector3d& start, double max_travel, int32_t tri, DropStats* stats = nullptr,
                 Eigen::Vector4d* tangent = nullptr) const;

 private:
  // A drop's state: the start (index frame), the best travel so far, its triangle, the lowest height a
  // triangle must reach to matter (K's lowest point at that travel).
  struct Search {
    Eigen::Vector3d s;
    double best, floor;
    int32_t winner = -1;
    std::size_t tested = 0;
    // K's plane of support at the best contact (index frame): n . X <= level holds on K at every earlier travel,
    // so a triangle with its corners on the far side (n . p >= level) is missed before the best. Unset: level
    // +inf.
    Eigen::Vector3d tangent = Eigen::Vector3d::Zero();
    double level = std::numeric_limits<double>::infinity();
  };
  Search search(const Eigen::Vector3d& start, double max_travel) const;
  static bool beyond(const Search& q, const IndexedTriangle& t);
  // q's tangent plane from K's outward normal n (tool frame) at its best contact.
  void set_tangent(Search& q, const Eigen::Vector3d& n) const;
  // Whether the point p (tool frame, the start at the origin) lies inside K at that travel or touches it.
  bool inside_at(const Eigen::Vector3d& p, double travel) const;
  // plane (or null): a candidate's last separating normal, tried first and updated. certify: false for a
  // triangle likely to touch (the clearance certificate would only fail before the exact contact).
  void consider(Search& q, const IndexedTriangle& t, int32_t i, Eigen::Vector3d* plane = nullptr,
                bool certify = true) const;
  // Over a gather's starts (g's offsets, filled for t's fine azimuth here): true when t lies below one of K's
  // planes at every start; else `best` gets the two planes nearest to that.
  bool below_everywhere(const IndexedTriangle& t, Candidates& g, Candidate& best) const;
  double rise(double d, double x0, double x1, double y0, double y1, double enough) const;
  Plane plane_under(const Eigen::Vector3d& n) const;  // n: unit, index frame, n.z > 0
  // True when one of the planes, with the tip `top` high over the XY' point (x, y), has all of t's corners
  // below it: then K, which lies above that plane and only rises as the travel shrinks, misses t before it.
  bool below_a_plane(const IndexedTriangle& t, double x, double y, double top) const;
  static bool below(const Plane& p, const IndexedTriangle& t, double x, double y, double top);
  // The fine planes' azimuth (0 to kFineAzimuths - 1) nearest to the direction c (index frame) around the axis.
  int azimuth(const Eigen::Vector3d& c) const;

  const DirectionalIndex* index_;
  Cutter cutter_;
  Eigen::Vector3d a_;   // the axis in the index's frame
  ToolFrame frame_;
  Eigen::Vector3d W_;   // the motion in tool coordinates
  double lowest_ = 0, reach_ = 0, axis_xy_ = 0;
  // K's shadow on XY' lies within mid_reach_ of the tip offset by (mid_x_, mid_y_) (its axis's midpoint).
  double mid_x_ = 0, mid_y_ = 0, mid_reach_ = 0;
  // And within the strip of half-width side_ about the axis's shadow: across = (across_x_, across_y_) . xy,
  // the XY' direction square to the axis's lean, is within side_ of the tip's (any XY' point of K).
  double across_x_ = 1, across_y_ = 0, side_ = 0;
  // The range of across over an XY' box.
  void across_range(double xmin, double xmax, double ymin, double ymax, double& lo, double& hi) const;
  double ahead_ = 0;  // max over K of X . W: a triangle's travel is at least min q . W - ahead_
  std::vector<Plane> planes_;
  // With fine planes: those along the axis (facing down), then kFineAzimuths per tilt from the axis
  // (kFineTilts of them), azimuth-major; a plane facing up has c = -inf (nothing lies below it).
  static constexpr int kFineAzimuths = 64, kFineTilts = 11;
  std::vector<Plane> axial_, fine_;
};

// starts: n points (x, y, z, ...); axes: one unit axis (axes_per_point = false) or n of them; travel_out: n.
// Threads, progress and cancel (Cancelled) as drop_batch.
void drop_along_batch(const DirectionalIndex& index, const Cutter& cutter, const double* starts,
                      const double* axes, bool axes_per_point, std::size_t n, double max_travel,
                      double* travel_out, const BatchOptions& options, DropStats* stats = nullptr);

}  // namespace tmm
