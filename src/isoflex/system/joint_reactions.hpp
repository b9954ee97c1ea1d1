#pragma once
// Joint reactions from the multipliers (a user sizes a bearing from them): with the equations of
// motion M q̈ + ∇V − f_ext + Gᵀλ = 0 (DNSM-III (9); statics without M q̈) the rows of a joint J
// exert the generalized force −G_Jᵀ λ_J on its nodes. On a frame node (φ, d₁, d₂, d₃) a
// generalized force (f_φ, f₁, f₂, f₃) is the force F = f_φ and the moment Σ dᵢ × fᵢ about φ
// (a force F at x = φ + Xⁱ dᵢ has fᵢ = Xⁱ F). The reaction is reported on the model's body_b at
// its joint point, in global components and in body_b's joint frame (b_k = C_B(I, k) d_I).
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
};

// The reactions of the joints between frame nodes (bodies, beam nodes) at q for the multipliers
// λ of the selected rows (System::selected_rows order). A joint whose rows are partly redundant
// (not selected) gets the part its selected rows carry.
std::vector<JointReaction> joint_reactions(const System& sys, const VecX& q, const VecX& lambda);

}  // namespace isoflex::system
