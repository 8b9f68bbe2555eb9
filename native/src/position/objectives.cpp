#include "tmm/position/objectives.hpp"

#include <cmath>

#include "tmm/util/constants.hpp"

namespace tmm {

using Eigen::Matrix2d;
using Eigen::Matrix3d;
using Eigen::Vector2d;
using Eigen::Vector3d;

LocalModel drop_objective(const PatchSurface& s, const TorusTool& tool, double x, double y, const Vector2d& uv) {
  const SurfacePoint sp = s.eval(uv.x(), uv.y(), 2);
  const double dx = sp.S.x() - x, dy = sp.S.y() - y;
  const double rho = std::hypot(dx, dy);
  LocalModel L;
  const double Ro = tool.Ro, Ri = tool.Ri;
  if (rho > Ro + Ri) {
    L.f = kInf;
    return L;
  }
  double H = 0.0, H1 = 0.0, H2 = 0.0;
  const bool flat = (tool.shape == ToolShape::BullNose && rho <= Ro);
  const bool body = (tool.shape == ToolShape::RoundInsert && rho < Ro - Ri);
  if (body) {
    H = Ri;
  } else if (!flat) {
    const double t = rho - Ro;
    const double q = std::max(Ri * Ri - t * t, 1e-300);
    const double sq = std::sqrt(q);
    H = Ri - sq;
    H1 = t / sq;
    H2 = Ri * Ri / (q * sq);
  }
  L.f = -(sp.S.z() - H);
  Vector2d ru = Vector2d::Zero();
  Matrix2d rr = Matrix2d::Zero();
  if (rho > 1e-12 && (H1 != 0.0 || H2 != 0.0)) {
    const Eigen::Vector2d e(dx / rho, dy / rho);
    const Eigen::Vector2d su = sp.Su.head<2>(), sv = sp.Sv.head<2>();
    ru << e.dot(su), e.dot(sv);
    rr(0, 0) = (su.squaredNorm() - ru[0] * ru[0]) / rho + e.dot(sp.Suu.head<2>());
    rr(0, 1) = rr(1, 0) = (su.dot(sv) - ru[0] * ru[1]) / rho + e.dot(sp.Suv.head<2>());
    rr(1, 1) = (sv.squaredNorm() - ru[1] * ru[1]) / rho + e.dot(sp.Svv.head<2>());
  }
  L.g << -(sp.Su.z() - H1 * ru[0]), -(sp.Sv.z() - H1 * ru[1]);
  L.H(0, 0) = -(sp.Suu.z() - H2 * ru[0] * ru[0] - H1 * rr(0, 0));
  L.H(0, 1) = L.H(1, 0) = -(sp.Suv.z() - H2 * ru[0] * ru[1] - H1 * rr(0, 1));
  L.H(1, 1) = -(sp.Svv.z() - H2 * ru[1] * ru[1] - H1 * rr(1, 1));
  return L;
}

LocalModel distance_objective(const PatchSurface& s, const TorusTool& tool, const ToolPose& pose,
                              const Vector2d& uv) {
  const SurfacePoint sp = s.eval(uv.x(), uv.y(), 2);
  Vector3d g;
  Matrix3d H;
  LocalModel L;
  L.f = tool_distance(tool, pose.tip, pose.axis, sp.S, &g, &H);
  L.g << g.dot(sp.Su), g.dot(sp.Sv);
  L.H(0, 0) = sp.Su.dot(H * sp.Su) + g.dot(sp.Suu);
  L.H(0, 1) = L.H(1, 0) = sp.Su.dot(H * sp.Sv) + g.dot(sp.Suv);
  L.H(1, 1) = sp.Sv.dot(H * sp.Sv) + g.dot(sp.Svv);
  return L;
}

}  // namespace tmm
