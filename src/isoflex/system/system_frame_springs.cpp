// Force elements between two frames (docs/theory/coupling.md §7–§8): the bushings (model
// `bushings`) and the springs of revolute and prismatic joints (joints `spring`), each an element
// on the frame nodes of its two bodies — not a part of the joint's constraint, so they act alike
// in every formulation. The frames are the joint's: its point and axes at t = 0
// (joint_frames.hpp), fixed in each body (elements/frame_pair.hpp). The drivers of revolute and
// prismatic joints (joints `driver`, joint_drivers.hpp) measure their angle and slide on the
// same frames.
#include <fmt/format.h>

#include <cmath>
#include <memory>
#include <utility>

#include "isoflex/elements/frame_pair.hpp"
#include "isoflex/elements/invariant_spring_damper.hpp"
#include "isoflex/elements/revolute_spring.hpp"
#include "isoflex/system/compile_error.hpp"
#include "isoflex/system/joint_drivers.hpp"
#include "isoflex/system/joint_frames.hpp"
#include "isoflex/system/system.hpp"

namespace isoflex::system {

namespace fn = frame_node;

namespace {

// The frame (point p, axes E: columns, global at t = 0) attached to the node with q0 = q, or
// fixed in space on the ground.
elements::AttachedFrame attached(const fn::Q& q, bool ground, const Vec3& p, const Mat3& E) {
  if (ground) return {p, E, true};
  const Mat3 R = fn::directors(q);
  return {R.transpose() * (p - fn::phi(q)), R.transpose() * E, false};
}

}  // namespace

void System::add_frame_springs(const model::Model& m, const NodeFinder& find) {
  // The element of joint or bushing J with frame axes E, made by `make(nodes, pair, q0)`.
  const auto add = [&](const model::Joint& J, const std::string& what, const auto& axes,
                       const auto& make, FrameSpringInstance record) {
    const int a = find(J.body_a, J.source, what + ".body_a");
    const int b = find(J.body_b, J.source, what + ".body_b");
    for (const int node : {a, b})
      if (node >= 0 && node_kind(node) != NodeKind::frame)
        compile_fail(J.source, what,
                     fmt::format("'{}' is not a body or a beam node: a spring between frames "
                                 "needs frame nodes",
                                 node_names_[node]));
    const fn::Q qa = node_q(q0_, a), qb = node_q(q0_, b);
    const JointFrameAtStart f = joint_frame_at_start(J, qa, qb);
    const Mat3 E = axes(f);
    std::vector<int> nodes;
    for (const int node : {a, b})
      if (node >= 0) nodes.push_back(node);
    const elements::FramePair pair(attached(qa, a < 0, f.point, E),
                                   attached(qb, b < 0, f.point, E));
    try {
      std::unique_ptr<elements::Element> e = make(nodes, pair, stacked(q0_, nodes));
      viscous_ = viscous_ || e->viscous();
      record.element_index = static_cast<int>(elements_.size());
      frame_springs_.push_back(std::move(record));
      elements_.push_back(std::move(e));
    } catch (const std::invalid_argument& e) {
      compile_fail(J.source, what, e.what());
    }
  };

  for (std::size_t j = 0; j < m.joints.size(); ++j) {
    const model::Joint& J = m.joints[j];
    if (!J.spring) continue;
    const model::JointSpring S = *J.spring;
    const std::string what = fmt::format("joints[{}].spring", j);
    const auto axes = [&](const JointFrameAtStart& f) {
      if (!f.axis || !(f.axis->norm() > 0.0))
        compile_fail(J.source, what, "the joint needs an axis");
      return frame_about(*f.axis);
    };
    if (J.type == model::JointType::revolute) {
      add(J, what, axes,
          [&](const std::vector<int>& nodes, const elements::FramePair& pair,
              const VecX& q0) -> std::unique_ptr<elements::Element> {
            return std::make_unique<elements::RevoluteSpring>(nodes, pair, S.stiffness, S.damping,
                                                              S.free_value, q0);
          },
          {J.name, -1, FrameSpringInstance::Kind::revolute, S.free_value});
    } else if (J.type == model::JointType::prismatic) {
      add(J, what, axes,
          [&](const std::vector<int>& nodes, const elements::FramePair& pair,
              const VecX& q0) -> std::unique_ptr<elements::Element> {
            return std::make_unique<elements::InvariantSpringDamper>(
                nodes, std::vector<elements::QuadraticInvariant>{pair.displacement(2)},
                MatX::Constant(1, 1, S.stiffness), MatX::Constant(1, 1, S.damping), q0,
                VecX::Constant(1, S.free_value));
          },
          {J.name, -1, FrameSpringInstance::Kind::prismatic, S.free_value});
    } else {
      compile_fail(J.source, what, "a spring is built for revolute and prismatic joints only");
    }
  }

  for (std::size_t k = 0; k < m.bushings.size(); ++k) {
    const model::Bushing& B = m.bushings[k];
    const std::string what = fmt::format("bushings[{}]", k);
    // e₃ = axis, e₁ = axis2 (⊥ axis), e₂ = e₃ × e₁; axis alone: frame_about; none: global.
    const auto axes = [&](const JointFrameAtStart& f) {
      if (!f.axis) return Mat3::Identity().eval();
      if (!f.axis2) return frame_about(*f.axis);
      const Vec3 e3 = f.axis->normalized(), e1 = f.axis2->normalized();
      if (!(std::abs(e1.dot(e3)) < 1e-9))
        compile_fail(B.source, what + ".axis2",
                     fmt::format("axis2 must be perpendicular to axis at t = 0 (cosine {:.3g})",
                                 e1.dot(e3)));
      Mat3 E;
      E << e1, e3.cross(e1), e3;
      return E;
    };
    add(B.frame, what, axes,
        [&](const std::vector<int>& nodes, const elements::FramePair& pair,
            const VecX& q0) -> std::unique_ptr<elements::Element> {
          std::vector<elements::QuadraticInvariant> strains;
          for (int i = 0; i < 3; ++i) strains.push_back(pair.displacement(i));
          for (int i = 0; i < 3; ++i) strains.push_back(pair.rotation(i));
          return std::make_unique<elements::InvariantSpringDamper>(
              nodes, std::move(strains), MatX(B.stiffness), MatX(B.damping), q0);
        },
        {B.name, -1, FrameSpringInstance::Kind::bushing, 0.0});
  }
}

// A driver of a revolute or prismatic joint: one rheonomic row θ(q) = f(t) or s(q) = f(t) on the
// frames its spring would have (joint_drivers.hpp), an n-ary constraint. f(0) must be the angle
// or slide of the configuration at t = 0, which is 0. A spherical joint's driver moves its ground
// point: its own rows, made rheonomic with the joint (system_compile.cpp).
void System::add_joint_drivers(const model::Model& m, const NodeFinder& find,
                               std::vector<int>& driver_of_joint) {
  driver_of_joint.assign(m.joints.size(), -1);
  for (std::size_t j = 0; j < m.joints.size(); ++j) {
    const model::Joint& J = m.joints[j];
    if (J.driver.empty()) continue;
    const std::string what = fmt::format("joints[{}].driver", j);
    const int a = find(J.body_a, J.source, fmt::format("joints[{}].body_a", j));
    const int b = find(J.body_b, J.source, fmt::format("joints[{}].body_b", j));
    for (const int node : {a, b})
      if (node >= 0 && node_kind(node) != NodeKind::frame)
        compile_fail(J.source, what,
                     fmt::format("'{}' is not a body or a beam node: a driver moves frame nodes",
                                 node_names_[node]));
    rheonomic_ = true;
    const bool revolute = J.type == model::JointType::revolute;
    if (!revolute && J.type != model::JointType::prismatic) {
      if (J.type == model::JointType::spherical && a < 0 && J.driver.size() == 3) continue;
      compile_fail(J.source, what,
                   "a driver is built for revolute and prismatic joints and spherical joints to "
                   "the ground");
    }
    if (J.driver.size() != 1)
      compile_fail(J.source, what, "a revolute or prismatic joint's driver is one time function");
    const fn::Q qa = node_q(q0_, a), qb = node_q(q0_, b);
    const JointFrameAtStart f = joint_frame_at_start(J, qa, qb);
    if (!f.axis || !(f.axis->norm() > 0.0)) compile_fail(J.source, what, "the joint needs an axis");
    const Mat3 E = frame_about(*f.axis);
    std::vector<int> nodes;
    for (const int node : {a, b})
      if (node >= 0) nodes.push_back(node);
    const elements::FramePair pair(attached(qa, a < 0, f.point, E),
                                   attached(qb, b < 0, f.point, E));
    std::shared_ptr<const JointDriver> driver;
    try {
      driver = std::make_shared<JointDriver>(
          nodes, pair, revolute ? JointDriver::Coordinate::angle : JointDriver::Coordinate::slide,
          stacked(q0_, nodes), J.driver.front());
    } catch (const std::invalid_argument& e) {
      compile_fail(J.source, what, e.what());
    }
    // The joint's angle or slide at t = 0 is 0 (its frames are built to coincide there).
    const double f0 = driver->prescribed(0.0)(0);
    if (!(std::abs(f0) <= kDriverTolerance))
      compile_fail(J.source, what,
                   fmt::format("'{}' is {:.6g} at t = 0, but the joint's {} in the configuration "
                               "at t = 0 is 0 (it is measured from there): inconsistent by {:.3g} "
                               "{}",
                               J.driver.front(), f0, revolute ? "angle" : "slide", std::abs(f0),
                               revolute ? "rad" : "(length)"));
    driver_of_joint[j] = static_cast<int>(nary_.size());
    nary_.push_back(
        {what, revolute ? "revolute_driver" : "prismatic_driver", std::move(driver), 0, J.source});
  }
}

}  // namespace isoflex::system
