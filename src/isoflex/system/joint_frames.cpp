#include "isoflex/system/joint_frames.hpp"

#include <cmath>

namespace isoflex::system {

namespace fn = frame_node;

JointFrameAtStart joint_frame_at_start(const model::Joint& J, const fn::Q& qa, const fn::Q& qb) {
  const Mat3 RA = fn::directors(qa), RB = fn::directors(qb);
  JointFrameAtStart f;
  f.point = fn::phi(qb);
  if (J.point)
    f.point = *J.point;
  else if (J.point_a)
    f.point = fn::phi(qa) + RA * *J.point_a;
  else if (J.point_b)
    f.point = fn::phi(qb) + RB * *J.point_b;
  f.axis = J.axis_a ? std::optional<Vec3>(RA * *J.axis_a) : J.axis;
  f.axis2 = J.axis2_b ? std::optional<Vec3>(RB * *J.axis2_b) : J.axis2;
  return f;
}

Mat3 frame_about(const Vec3& e3) {
  const Vec3 n = e3.normalized();
  const Vec3 a = std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  const Vec3 e1 = (a - a.dot(n) * n).normalized();
  Mat3 E;
  E << e1, n.cross(e1), n;
  return E;
}

}  // namespace isoflex::system
