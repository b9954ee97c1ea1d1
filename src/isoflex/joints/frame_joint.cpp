#include "isoflex/joints/frame_joint.hpp"

#include <cassert>

#include "isoflex/math/rotation.hpp"
#include "isoflex/math/skew.hpp"

namespace isoflex::joints {

namespace fn = frame_node;

namespace {
// Linear maps L (3 × 24) with L·(q_A, q_B) = a body vector; every constraint row is L₁q or
// (L₁q)·(L₂q), which makes Φ, G and the constant Hessian uniform.
using L = Mat<3, 24>;

L director_combination(const Vec3& c, int node) {
  L l = L::Zero();
  for (int I = 0; I < 3; ++I) l.block<3, 3>(0, 12 * node + 3 + 3 * I) = c(I) * Mat3::Identity();
  return l;
}

L point_map(const Vec3& X, int node) {
  L l = director_combination(X, node);
  l.block<3, 3>(0, 12 * node).setIdentity();
  return l;
}

// r = x_B − x_A.
L relative_point_map(const Vec3& X_A, const Vec3& X_B) {
  return point_map(X_B, 1) - point_map(X_A, 0);
}

Vec<24> stack(const fn::Q& qa, const fn::Q& qb) {
  Vec<24> q;
  q << qa, qb;
  return q;
}

Vec3 body_vector(const fn::Q& q, const Vec3& c) {
  return c(0) * fn::director(q, 0) + c(1) * fn::director(q, 1) + c(2) * fn::director(q, 2);
}
}  // namespace

FrameJoint::FrameJoint(Kind kind, const FrameJointGeometry& g)
    : kind_(kind), g_(g), locked_(g.C_A * g.C_B.transpose()) {
  switch (kind) {
    case Kind::spherical:
      point_rows_ = true;
      r_ = 3;
      rotvec_ = 0;
      break;
    case Kind::revolute:
      point_rows_ = true;
      frame_rows_ = {{2, 0}, {2, 1}};
      r_ = 1;
      break;
    case Kind::universal:
      point_rows_ = true;
      frame_rows_ = {{0, 1}};
      r_ = 2;
      break;
    case Kind::cylindrical:
      frame_rows_ = {{2, 0}, {2, 1}};
      plane_rows_ = {0, 1};
      slides_ = true;
      r_ = 2;
      break;
    case Kind::prismatic:
      frame_rows_ = {{0, 1}, {1, 2}, {2, 0}};
      plane_rows_ = {0, 1};
      slides_ = true;
      r_ = 1;
      break;
    case Kind::planar:
      frame_rows_ = {{2, 0}, {2, 1}};
      plane_rows_ = {2};
      slides_ = true;
      r_ = 3;
      break;
    case Kind::rigid:
      point_rows_ = true;
      frame_rows_ = {{0, 1}, {1, 2}, {2, 0}};
      r_ = 0;
      break;
    case Kind::point_on_line:
      plane_rows_ = {0, 1};
      slides_ = true;
      r_ = 4;
      rotvec_ = 0;
      break;
  }
  m_ = (point_rows_ ? 3 : 0) + static_cast<int>(frame_rows_.size() + plane_rows_.size());
}

FrameJoint::FrameVectors FrameJoint::vectors(const Q& qa, const Q& qb) const {
  FrameVectors v;
  v.rho_a = body_vector(qa, g_.X_A);
  v.rho_b = body_vector(qb, g_.X_B);
  v.x_a = fn::phi(qa) + v.rho_a;
  v.x_b = fn::phi(qb) + v.rho_b;
  v.r = v.x_b - v.x_a;
  for (int k = 0; k < 3; ++k) {
    v.a.col(k) = body_vector(qa, g_.C_A.col(k));
    v.b.col(k) = body_vector(qb, g_.C_B.col(k));
  }
  return v;
}

VecX FrameJoint::constraints(CRef qa, CRef qb) const {
  const FrameVectors v = vectors(qa, qb);
  VecX c(m_);
  int row = 0;
  if (point_rows_) c.segment<3>(row) = v.r, row += 3;
  for (auto [i, j] : frame_rows_) c(row++) = v.a.col(i).dot(v.b.col(j));
  for (int i : plane_rows_) c(row++) = v.r.dot(v.a.col(i));
  return c;
}

MatX FrameJoint::jacobian(CRef qa, CRef qb) const {
  return fixed_jacobian(Q(qa), Q(qb));
}

FrameJoint::Rows FrameJoint::fixed_jacobian(const Q& qa, const Q& qb) const {
  const Vec<24> q = stack(qa, qb);
  const L lr = relative_point_map(g_.X_A, g_.X_B);
  Rows G(m_, 24);
  int row = 0;
  if (point_rows_) G.middleRows<3>(row) = lr, row += 3;
  for (auto [i, j] : frame_rows_) {
    const L la = director_combination(g_.C_A.col(i), 0),
            lb = director_combination(g_.C_B.col(j), 1);
    G.row(row++) = (la * q).transpose() * lb + (lb * q).transpose() * la;
  }
  for (int i : plane_rows_) {
    const L la = director_combination(g_.C_A.col(i), 0);
    G.row(row++) = (la * q).transpose() * lr + (lr * q).transpose() * la;
  }
  return G;
}

void FrameJoint::add_constraint_hessian(CRef lambda, Mat<24, 24>& H) const {
  assert(lambda.size() == m_);
  // Each L is c ⊗ I₃ over the 8 points (φ, d₁, d₂, d₃ of both nodes), so LₐᵀL_b = (c_a c_bᵀ) ⊗ I₃:
  // the Hessian is h ⊗ I₃ with h (8 × 8) summed from the coefficients (no 24 × 3 by 3 × 24
  // products).
  using C8 = Vec<8>;
  const auto director = [](const Vec3& c, int node) {
    C8 a = C8::Zero();
    a.segment<3>(4 * node + 1) = c;
    return a;
  };
  C8 lr;
  lr << -1.0, -g_.X_A, 1.0, g_.X_B;  // relative_point_map
  Mat<8, 8> h = Mat<8, 8>::Zero();
  int row = point_rows_ ? 3 : 0;
  for (auto [i, j] : frame_rows_) {
    const C8 la = director(g_.C_A.col(i), 0), lb = director(g_.C_B.col(j), 1);
    h += lambda(row++) * (la * lb.transpose() + lb * la.transpose());
  }
  for (int i : plane_rows_) {
    const C8 la = director(g_.C_A.col(i), 0);
    h += lambda(row++) * (la * lr.transpose() + lr * la.transpose());
  }
  for (int c = 0; c < 8; ++c)
    for (int b = 0; b < 8; ++b) H.block<3, 3>(3 * b, 3 * c).diagonal().array() += h(b, c);
}

namespace {
using Directions = FrameJoint::Directions;
Directions columns(const Vec3& x) {
  Directions d(3, 1);
  d.col(0) = x;
  return d;
}
Directions columns(const Vec3& x, const Vec3& y) {
  Directions d(3, 2);
  d << x, y;
  return d;
}
}  // namespace

Directions FrameJoint::translation_directions(const Mat3& a) const {
  // Directions orthogonal to the constrained a_i for every q, not only on the manifold.
  switch (kind_) {
    case Kind::prismatic:
    case Kind::cylindrical:
    case Kind::point_on_line:
      return columns(a.col(0).cross(a.col(1)));
    case Kind::planar:
      return columns(a.col(2).cross(a.col(0)), a.col(1).cross(a.col(2)));
    default:
      return Directions(3, 0);
  }
}

namespace {
// Relative rotation axes (ω_B = ω_A + Σ axis τ) of a joint.
Directions relative_axes(Kind kind, const Mat3& a, const Mat3& b) {
  switch (kind) {
    case Kind::revolute:
    case Kind::cylindrical:
    case Kind::planar:
      return columns(a.col(2));
    case Kind::universal:
      return columns(a.col(0), b.col(1));
    default:
      return Directions(3, 0);
  }
}
bool absolute_rotation(Kind kind) {
  return kind == Kind::spherical || kind == Kind::point_on_line;
}
}  // namespace

Mat<6, 6> FrameJoint::parent_block(CRef qa, CRef qb) const {
  const FrameVectors v = vectors(qa, qb);
  const double follow = absolute_rotation(kind_) ? 0.0 : 1.0;  // ω_B contains ω_A
  const Vec3 arm = v.rho_a + (slides_ ? v.r : Vec3::Zero());
  Mat<6, 6> A = Mat<6, 6>::Zero();
  A.block<3, 3>(0, 0).setIdentity();
  A.block<3, 3>(0, 3) = -skew(arm) + follow * skew(v.rho_b);
  A.block<3, 3>(3, 3) = follow * Mat3::Identity();
  return A;
}

FreedomBlock FrameJoint::freedom_block(CRef qa, CRef qb) const {
  const FrameVectors v = vectors(qa, qb);
  FreedomBlock B = FreedomBlock::Zero(6, r_);
  int col = 0;
  const Mat3 rb = skew(v.rho_b);
  if (absolute_rotation(kind_)) {
    B.block<3, 3>(0, 0) = rb;
    B.block<3, 3>(3, 0).setIdentity();
    col = 3;
  }
  const Directions axes = relative_axes(kind_, v.a, v.b);
  for (int k = 0; k < axes.cols(); ++k) {
    B.block<3, 1>(0, col) = rb * axes.col(k);
    B.block<3, 1>(3, col) = axes.col(k);
    ++col;
  }
  const Directions slides = translation_directions(v.a);
  for (int k = 0; k < slides.cols(); ++k) B.block<3, 1>(0, col++) = slides.col(k);
  assert(col == r_);
  return B;
}

FrameJoint::Q FrameJoint::update(const Q& qa_n, const Q& qa_n1, const Mat3& QA, const Q& qb_n,
                                 const VecX& tau, Mat3* step_b) const {
  return fixed_update(qa_n, qa_n1, QA, qb_n, tau, step_b);
}

FrameJoint::Q FrameJoint::fixed_update(const Q& qa_n, const Q& qa_n1, const Mat3& QA, const Q& qb_n,
                                       CRef tau, Mat3* step_b, const StepIncrement* parent,
                                       StepIncrement* child) const {
  assert(tau.size() == r_);
  assert(!child || parent);
  const FrameVectors vn = vectors(qa_n, qb_n);
  const Mat3 Rb_n = fn::directors(qb_n);
  // The child turns by the product of exact rotations, never by R_A,n+1 R_A,nᵀ: that carries the
  // parent's orthonormality round-off (20) into the child at every step, and a chain's directors
  // then drift linearly with the step count (10⁻¹¹ in 3000 steps of Andrews' squeezer).
  // With `child`, each rotation's increment (exp − I) comes from the same factors.
  Mat3 step, dstep, A1, A2;
  const auto turn = [&](const Vec3& theta, Mat3& A) {
    return rodrigues(theta, child ? &A : nullptr);
  };
  int k = 0;
  if (absolute_rotation(kind_)) {
    step = turn(tau.head<3>(), dstep);
    k = 3;
  } else if (kind_ == Kind::universal) {
    const Vec3 a1 = body_vector(qa_n1, g_.C_A.col(0));
    const Vec3 b2 = vn.b.col(1);
    step = turn(tau(0) * a1, A1) * QA * turn(tau(1) * b2, A2);
    if (child) dstep = compose_increments(compose_increments(A1, parent->dQ), A2);
    k = 2;
  } else if (kind_ == Kind::revolute || kind_ == Kind::cylindrical || kind_ == Kind::planar) {
    const Vec3 a3 = body_vector(qa_n1, g_.C_A.col(2));
    step = turn(tau(0) * a3, A1) * QA;
    if (child) dstep = compose_increments(A1, parent->dQ);
    k = 1;
  } else {
    step = QA;
    if (child) dstep = parent->dQ;
  }
  // Rotation locked: R_B = R_A C_A C_Bᵀ (the joint frames coincide) rather than Q_A R_B,n, so
  // that the round-off of the orthonormality (20) does not accumulate step after step.
  const Mat3& C = locked_;
  const Mat3 Rb = k > 0 ? Mat3(step * Rb_n) : Mat3(fn::directors(qa_n1) * C);
  if (step_b) *step_b = step;
  Mat3 a_n1;
  for (int i = 0; i < 3; ++i) a_n1.col(i) = body_vector(qa_n1, g_.C_A.col(i));
  Vec3 x_b = fn::phi(qa_n1) + body_vector(qa_n1, g_.X_A);
  if (slides_) x_b += QA * vn.r;
  const Directions slides = translation_directions(a_n1);
  const int k_rotation = k;
  for (int c = 0; c < slides.cols(); ++c) x_b += tau(k++) * slides.col(c);
  assert(k == r_);
  if (child) {
    // The same terms less those at tₙ: Δφ_A + ΔR_A X_A (+ (Q_A − I) rₙ) + Σ τ s − ΔR_B X_B, with
    // ΔR_A the parent's director increments and ΔR_B = (Q_B − I) R_B,n (ΔR_A C when locked).
    const Mat3 dRa = Eigen::Map<const Mat3>(parent->dq.data() + 3);
    const Mat3 dRb = k_rotation > 0 ? Mat3(dstep * Rb_n) : Mat3(dRa * C);
    Vec3 dx = parent->dq.head<3>() + dRa * g_.X_A;
    if (slides_) dx += parent->dQ * vn.r;
    for (int c = 0; c < slides.cols(); ++c) dx += tau(k_rotation + c) * slides.col(c);
    child->dq = fn::make(dx - dRb * g_.X_B, dRb);
    child->dQ = dstep;
  }
  return fn::make(x_b - Rb * g_.X_B, Rb);
}

void FrameJoint::add_constraint_hessian(CRef lambda, MatX& H) const {
  Mat<24, 24> h = Mat<24, 24>::Zero();
  add_constraint_hessian(lambda, h);
  H += h;
}

NodeVec FrameJoint::update(CRef qa_n, CRef qa_n1, const Mat3& step_a, CRef qb_n, CRef tau,
                           Mat3* step_b, const StepIncrement* parent, StepIncrement* child) const {
  return fixed_update(Q(qa_n), Q(qa_n1), step_a, Q(qb_n), tau, step_b, parent, child);
}

FreedomBlock FrameJoint::update_freedom_block(CRef qa_n1, CRef, CRef qb_n1, CRef tau) const {
  FreedomBlock B = freedom_block(qa_n1, qb_n1);
  if (rotvec_ >= 0)
    B.middleCols<3>(rotvec_) =
        B.middleCols<3>(rotvec_) * rodrigues_tangent(Vec3(tau.segment<3>(rotvec_)));
  return B;
}

FrameJointGeometry geometry_from_global(const fn::Q& qa0, const fn::Q& qb0, const Vec3& p,
                                        const Mat3& E) {
  const Mat3 Ra = fn::directors(qa0), Rb = fn::directors(qb0);
  FrameJointGeometry g;
  g.X_A = Ra.transpose() * (p - fn::phi(qa0));
  g.C_A = Ra.transpose() * E;
  g.X_B = Rb.transpose() * (p - fn::phi(qb0));
  g.C_B = Rb.transpose() * E;
  return g;
}

}  // namespace isoflex::joints
