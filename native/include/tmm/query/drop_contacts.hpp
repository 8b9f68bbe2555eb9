// Exact contacts of a cutter dropped along -Z onto one vertex, edge or facet (seed 003 chapter 3,
// seed 000 section 3.5.4). Each returns the tip height at which the cutter centred over (x, y) first
// touches the element, or -inf if it cannot touch it. Heights are tip heights (CL points).
#pragma once

#include <cmath>
#include <limits>

#include "tmm/cutter/cutter.hpp"
#include "tmm/util/constants.hpp"

namespace tmm {

constexpr double kNoContact = -std::numeric_limits<double>::infinity();

// Does (cx, cy) lie in the XY projection of triangle p0 p1 p2 (either orientation)? Barycentric signs with a
// relative tolerance, so a point on an edge counts as inside.
inline bool inside_xy(const double* p0, const double* p1, const double* p2, double cx, double cy) {
  const double ax = p0[0] - cx, ay = p0[1] - cy;
  const double bx = p1[0] - cx, by = p1[1] - cy;
  const double qx = p2[0] - cx, qy = p2[1] - cy;
  const double w0 = bx * qy - by * qx;
  const double w1 = qx * ay - qy * ax;
  const double w2 = ax * by - ay * bx;
  const double area = w0 + w1 + w2;
  const double eps = 1e-12 * std::fabs(area);
  return area > 0 ? (w0 >= -eps && w1 >= -eps && w2 >= -eps) : (w0 <= eps && w1 <= eps && w2 <= eps);
}

// Vertex p: tip = p.z - h(rho).
inline double vertex_drop(const Cutter& c, double x, double y, const double* p) {
  const double dx = p[0] - x, dy = p[1] - y;
  const double rho2 = dx * dx + dy * dy;
  const double R = c.max_radius();
  if (rho2 > R * R) return kNoContact;
  return p[2] - c.height(std::sqrt(rho2));
}

// Facet with corners p0, p1, p2 and unit normal n (n_z > 0 faces up). The contact point is where the
// cutter's outward normal is -n: rho = facet_contact_radius(|n_xy|, n_z) uphill of the axis. Valid only if
// that point lies inside the triangle; otherwise an edge or vertex gives the contact.
// `above`: a height the caller already has; the contact is only computed when its cheap upper bound
// (the facet's highest corner `zmax` lowered by h at the contact radius) exceeds it, else -inf.
double facet_drop(const Cutter& c, double x, double y, const double* p0, const double* p1,
                  const double* p2, const double* n, double zmax = kInf, double above = kNoContact);

// The drop onto the whole plane of a facet (unit normal n, n_z > 0), which bounds the drop onto the facet
// from above; `inside` tells whether the contact point lies in the triangle, in which case it is the facet's
// (and the whole triangle's) contact. -inf for vertical or downward-facing planes.
double plane_drop(const Cutter& c, double x, double y, const double* p0, const double* p1, const double* p2,
                  const double* n, bool& inside);

// Edge p1-p2: the maximum over the edge of z_edge(u) - h(rho(u)), a concave function of the
// position u along the edge (h is convex and increasing, rho(u) is convex), endpoints included, so
// this also covers both vertices. Ball and flat have closed forms; other profiles are solved by
// safeguarded Newton on the derivative to 1e-12 mm in u.
// `above`: as for facet_drop; the bound is the higher end lowered by h at the axis' distance to the edge.
double edge_drop(const Cutter& c, double x, double y, const double* p1, const double* p2,
                 double above = kNoContact);

}  // namespace tmm
