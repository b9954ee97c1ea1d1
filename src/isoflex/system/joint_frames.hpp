#pragma once
// The point and axes of a joint (or of a bushing, given like a joint) at t = 0 in global
// coordinates, from the model entry's point/point_a/point_b and axis/axis_a, axis2/axis2_b and
// the initial configurations of its bodies a and b (the ground: φ = 0, d = I).
#include <optional>

#include "isoflex/math/frame_node.hpp"
#include "isoflex/math/types.hpp"
#include "isoflex/model/model.hpp"

namespace isoflex::system {

struct JointFrameAtStart {
  Vec3 point = Vec3::Zero();  // default: body b's node origin (centre of mass)
  std::optional<Vec3> axis, axis2;
};

JointFrameAtStart joint_frame_at_start(const model::Joint& J, const frame_node::Q& qa,
                                       const frame_node::Q& qb);

// A right-handed orthonormal frame whose third axis is e3 (normalized); the first axis is the
// projection of x (or y, when e3 is close to x) onto the plane normal to it.
Mat3 frame_about(const Vec3& e3);

}  // namespace isoflex::system
