#include "isoflex/joints/point_joints.hpp"

#include <cassert>
#include <stdexcept>

#include "isoflex/math/skew.hpp"

namespace isoflex::joints {

namespace fn = frame_node;

namespace {
// ρ_A = X_I d_I^A: linear in q_A, and ρ̇_A = ω_A × ρ_A for every q_A ∈ R¹² (q̇_A = P_int(q_A) t_A
// means ḋ_I = ω_A × d_I, DNSM-III (31)), orthonormality not used.
Vec3 arm(const Eigen::Ref<const VecX>& qa, const Vec3& X) {
  assert(qa.size() == fn::kCoords);
  return qa.segment<3>(3) * X(0) + qa.segment<3>(6) * X(1) + qa.segment<3>(9) * X(2);
}
}  // namespace

// --- PointOnFrame ------------------------------------------------------------------------------
// q = (φ_A, d₁^A, d₂^A, d₃^A, φ_B) ∈ R¹⁵.

PointOnFrame::PointOnFrame(const fn::Q& qa0, const Vec3& phi_b0) {
  if (!qa0.allFinite() || !phi_b0.allFinite()) {
    throw std::invalid_argument("point on frame: non-finite coordinates at t = 0");
  }
  X_ = fn::directors(qa0).transpose() * (phi_b0 - fn::phi(qa0));
}

VecX PointOnFrame::constraints(CRef qa, CRef qb) const {
  assert(qa.size() == fn::kCoords && qb.size() == 3);
  const Vec3 phi = qb.head<3>() - qa.head<3>() - arm(qa, X_);
  return phi;
}

MatX PointOnFrame::jacobian(CRef qa, CRef qb) const {
  assert(qa.size() == fn::kCoords && qb.size() == 3);
  (void)qa;
  (void)qb;
  Mat<3, 15> G;
  G << -Mat3::Identity(), -X_(0) * Mat3::Identity(), -X_(1) * Mat3::Identity(),
      -X_(2) * Mat3::Identity(), Mat3::Identity();
  return G;
}

void PointOnFrame::add_constraint_hessian(CRef lambda, MatX& H) const {
  // Linear rows: Φ(q_{n+1}) − Φ(q_n) = G (q_{n+1} − q_n) exactly, 𝖦 = G (DNSM-III (23)).
  assert(lambda.size() == 3 && H.rows() == 15 && H.cols() == 15);
  (void)lambda;
  (void)H;
}

Mat<6, 6> PointOnFrame::parent_block(CRef qa, CRef) const {
  // φ̇_B = φ̇_A + ω_A × ρ_A with ρ_A = X_I d_I^A built from A's directors (not φ_B − φ_A): the rate
  // of the rows is φ̇_B − φ̇_A − ρ̇_A = 0 for every q ∈ R¹⁵, on the manifold or not. ω_B = ω_A
  // (P_int of a point node ignores it).
  Mat<6, 6> A = Mat<6, 6>::Identity();
  A.block<3, 3>(0, 3) = -skew(arm(qa, X_));
  return A;
}

FreedomBlock PointOnFrame::freedom_block(CRef, CRef) const {
  return MatX::Zero(6, 0);
}

NodeVec PointOnFrame::update(CRef, CRef qa_n1, const Mat3& step_a, CRef, CRef tau, Mat3* step_b,
                             const StepIncrement* parent, StepIncrement* child) const {
  assert(tau.size() == 0);
  (void)tau;
  // From A at t_{n+1} directly: the rows hold to round-off and do not drift. The derivative
  // w.r.t. A's motion δφ_A, δd_I = δω × d_I is δφ_A + δω × ρ_A: the block A at t_{n+1}.
  if (step_b) *step_b = step_a;
  if (child) {  // Δφ_A + ΔR_A X, ΔR_A the parent's director increments
    child->dq = parent->dq.head<3>() + Eigen::Map<const Mat3>(parent->dq.data() + 3) * X_;
    child->dQ = parent->dQ;
  }
  const Vec3 phi = qa_n1.head<3>() + arm(qa_n1, X_);
  return phi;
}

FreedomBlock PointOnFrame::update_freedom_block(CRef, CRef, CRef, CRef) const {
  return MatX::Zero(6, 0);
}

}  // namespace isoflex::joints
