#include "tmm/position/pose.hpp"

#include <Eigen/Geometry>

namespace tmm {

using Eigen::Matrix3d;
using Eigen::Vector3d;

PseudoInsert::PseudoInsert(const Vector3d& tip, const Vector3d& dir, const TorusTool& tool)
    : tip0(tip), e(dir), u1(Vector3d::UnitZ().cross(dir)), v1(-dir), O1(tip + tool.Ri * Vector3d::UnitZ() + tool.Ro * dir) {}

ToolPose PseudoInsert::tilted(double beta) const {
  const Matrix3d R = Eigen::AngleAxisd(-beta, u1).toRotationMatrix();
  return {O1 + R * (tip0 - O1), R * Vector3d::UnitZ()};
}

Vector3d PseudoInsert::local(const Vector3d& p) const {
  const Vector3d d = p - O1;
  return {d.dot(u1), d.dot(v1), d.dot(Vector3d::UnitZ())};
}

}  // namespace tmm
