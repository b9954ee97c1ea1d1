#pragma once
// Joint reactions from the multipliers (a user sizes a bearing from them): with the equations of
// motion M q̈ + ∇V − f_ext + Gᵀλ = 0 (DNSM-III (9); statics without M q̈) the rows of a joint J
// exert the generalized force −G_Jᵀ λ_J on its nodes. On a frame node (φ, d₁, d₂, d₃) a
// generalized force (f_φ, f₁, f₂, f₃) is the force F = f_φ and the moment Σ dᵢ × fᵢ about φ
// (a force F at x = φ + Xⁱ dᵢ has fᵢ = Xⁱ F). The reaction is reported on the model's body_b at
// its joint point, in global components and in body_b's joint frame (b_k = C_B(I, k) d_I).
#include <optional>
#include <string>
#include <vector>

#include "isoflex/math/types.hpp"
#include "isoflex/system/system.hpp"

namespace isoflex::system {

struct JointReaction {
  std::string joint;
  Vec3 point = Vec3::Zero();                                     // the joint point on body_b
  Vec3 force = Vec3::Zero(), moment = Vec3::Zero();              // global, moment about point
  Vec3 force_local = Vec3::Zero(), moment_local = Vec3::Zero();  // in body_b's joint frame
  // A driven revolute or prismatic joint (system/joint_drivers.hpp): the driving torque about
  // the axis (force along it) on body_b, −λ of the driver row; its force is also part of
  // force/moment above.
  std::optional<double> driver;
};

// The reactions of the joints at q for the multipliers λ of the selected rows
// (System::selected_rows order): joints between frame nodes (bodies, beam nodes) as above; joints
// with a director-shell node or a KL control point on body_b's side (or the other side, negated,
// with the ground as body_b): the force and the moment d × f_d about the node (global components
// in the local columns too); joints at KL shell points: on the shell at its material point (the
// rows' net force and moment on the control points). A joint whose rows are partly redundant
// (not selected) gets the part its selected rows carry. A driven joint's reaction includes its
// driver row's force (the driving torque or force), also given alone (JointReaction::driver).
std::vector<JointReaction> joint_reactions(const System& sys, const VecX& q, const VecX& lambda);

}  // namespace isoflex::system
