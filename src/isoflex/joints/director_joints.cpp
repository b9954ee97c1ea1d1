#include "isoflex/joints/director_joints.hpp"

#include <cassert>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

#include "isoflex/math/rotation.hpp"
#include "isoflex/math/skew.hpp"

namespace isoflex::joints {

namespace dn = director_node;
namespace fn = frame_node;

// --- detail::QuadraticRows ---------------------------------------------------------------------

namespace detail {

template <int N>
void QuadraticRows<N>::add_linear(const Vec<N>& g, double c) {
  Row row;
  row.g = g;
  row.c = c;
  rows_.push_back(row);
}

template <int N>
void QuadraticRows<N>::add_vector(const Map& L) {
  for (int k = 0; k < 3; ++k) add_linear(L.row(k).transpose());
}

template <int N>
void QuadraticRows<N>::add_product(const Map& L1, const Map& L2, double c) {
  Row row;
  row.product = true;
  row.L1 = L1;
  row.L2 = L2;
  row.c = c;
  rows_.push_back(row);
}

template <int N>
double QuadraticRows<N>::value(const Row& row, const Vec<N>& q) const {
  return (row.product ? (row.L1 * q).dot(row.L2 * q) : row.g.dot(q)) - row.c;
}

template <int N>
VecX QuadraticRows<N>::values(const Vec<N>& q) const {
  VecX c(size());
  for (int i = 0; i < size(); ++i) c(i) = value(rows_[i], q);
  return c;
}

template <int N>
MatX QuadraticRows<N>::jacobian(const Vec<N>& q) const {
  MatX G(size(), N);
  for (int i = 0; i < size(); ++i) {
    const Row& row = rows_[i];
    if (row.product) {
      G.row(i) = (row.L1 * q).transpose() * row.L2 + (row.L2 * q).transpose() * row.L1;
    } else {
      G.row(i) = row.g.transpose();
    }
  }
  return G;
}

template <int N>
void QuadraticRows<N>::add_hessian(const Eigen::Ref<const VecX>& lambda, MatX& H) const {
  assert(lambda.size() == size() && H.rows() == N && H.cols() == N);
  for (int i = 0; i < size(); ++i) {
    const Row& row = rows_[i];
    if (row.product) H += lambda(i) * (row.L1.transpose() * row.L2 + row.L2.transpose() * row.L1);
  }
}

template class QuadraticRows<12>;
template class QuadraticRows<18>;

}  // namespace detail

namespace {

// Linear maps q ↦ R³ on q = (q_A, q_B) ∈ R^N; `offset` is the node's first coordinate in q.
template <int N>
Mat<3, N> slot(int offset) {  // q.segment<3>(offset): φ of either node kind, d of a director node
  Mat<3, N> L = Mat<3, N>::Zero();
  L.template block<3, 3>(0, offset).setIdentity();
  return L;
}

template <int N>
Mat<3, N> body_vector_map(const Vec3& c, int offset) {  // c_I d_I of a frame node
  Mat<3, N> L = Mat<3, N>::Zero();
  for (int I = 0; I < 3; ++I) {
    L.template block<3, 3>(0, offset + 3 + 3 * I) = c(I) * Mat3::Identity();
  }
  return L;
}

template <int N>
Vec<N> stack(const Eigen::Ref<const VecX>& qa, const Eigen::Ref<const VecX>& qb) {
  assert(qa.size() + qb.size() == N);
  Vec<N> q;
  q << qa, qb;
  return q;
}

Vec3 body_vector(const fn::Q& q, const Vec3& c) {
  return fn::directors(q) * c;
}

Vec3 director(const Eigen::Ref<const VecX>& q) {  // d of a director node
  return q.segment<3>(3);
}

// Sine of the angle between two vectors, the degeneracy measure of a rotation row.
double sine(const Vec3& a, const Vec3& b) {
  return a.cross(b).norm() / (a.norm() * b.norm());
}

// Below this sine two directions count as parallel: the joint's rotation row and freedom vanish.
constexpr double kParallel = 1e-6;

[[noreturn]] void reject(const std::string& what, double value) {
  std::ostringstream s;
  s << what << " (sin = " << value << ")";
  throw std::invalid_argument(s.str());
}

}  // namespace

// --- ShellIntersection -------------------------------------------------------------------------
// q = (φ_A, d_A, φ_B, d_B) ∈ R¹².

ShellIntersection::ShellIntersection(const dn::Q& qa0, const dn::Q& qb0) {
  const double s = sine(qa0.tail<3>(), qb0.tail<3>());
  if (!(s > kParallel)) reject("shell intersection: directors are parallel at t = 0", s);
  eta_ = qa0.tail<3>().dot(qb0.tail<3>());
  rows_.add_vector(slot<12>(6) - slot<12>(0));        // φ_B − φ_A   (64)₁
  rows_.add_product(slot<12>(3), slot<12>(9), eta_);  // d_A·d_B − η (64)₂
}

VecX ShellIntersection::constraints(CRef qa, CRef qb) const {
  return rows_.values(stack<12>(qa, qb));
}

MatX ShellIntersection::jacobian(CRef qa, CRef qb) const {
  return rows_.jacobian(stack<12>(qa, qb));
}

void ShellIntersection::add_constraint_hessian(CRef lambda, MatX& H) const {
  rows_.add_hessian(lambda, H);
}

Mat<6, 6> ShellIntersection::parent_block(CRef, CRef) const {
  // The shared node (65)–(67): φ̇_B = φ̇_A and ω_B = ω_A + τ d_A. ḋ_A = ω_A × d_A and
  // ḋ_B = ω_B × d_B give (d_A·d_B)˙ = ω_A·(d_A × d_B) + ω_B·(d_B × d_A) = −τ d_A·(d_A × d_B) = 0
  // for every q ∈ R¹² (no unit length used), so G(q)·P(q) = 0 identically.
  return Mat<6, 6>::Identity();
}

FreedomBlock ShellIntersection::freedom_block(CRef qa, CRef) const {
  MatX B = MatX::Zero(6, 1);
  B.block<3, 1>(3, 0) = director(qa);
  return B;
}

NodeVec ShellIntersection::update(CRef, CRef qa_n1, const Mat3& step_a, CRef qb_n, CRef tau,
                                  Mat3* step_b, const StepIncrement* parent,
                                  StepIncrement* child) const {
  assert(tau.size() == 1);
  // B turns with A's full step rotation Q_A (drilling about d_A included: it turns d_B) and then
  // by τ about d_A,n+1. With d_A,n+1 = Q_A d_A,n, d_A·d_B keeps its value η:
  // d_A,n+1·exp(τ d̂_A,n+1) Q_A d_B,n = d_A,n+1·Q_A d_B,n = d_A,n·d_B,n. The point row is reset.
  Mat3 A;
  const Mat3 R = rodrigues(Vec3(tau(0) * director(qa_n1)), child ? &A : nullptr) * step_a;
  if (step_b) *step_b = R;
  if (child) {  // (Δφ_A, (R − I) d_B,n)
    child->dQ = compose_increments(A, parent->dQ);
    dn::Q dq;
    dq << parent->dq.head<3>(), child->dQ * director(qb_n);
    child->dq = dq;
  }
  dn::Q qb;
  qb << qa_n1.head<3>(), R * director(qb_n);
  return qb;
}

FreedomBlock ShellIntersection::update_freedom_block(CRef qa_n1, CRef, CRef qb_n1, CRef) const {
  // ∂/∂τ exp(τ â) = â exp(τ â) for the fixed axis a = d_A,n+1 (T(τa) a = a): the continuous block.
  return freedom_block(qa_n1, qb_n1);
}

// --- DirectorOnFrame ---------------------------------------------------------------------------
// q = (φ_A, d₁^A, d₂^A, d₃^A, φ_B, d_B) ∈ R¹⁸.

DirectorOnFrame::DirectorOnFrame(const fn::Q& qa0, const dn::Q& qb0) {
  const Mat3 Ra = fn::directors(qa0);
  X_A_ = Ra.transpose() * (qb0.head<3>() - fn::phi(qa0));
  D_ = Ra.transpose() * qb0.tail<3>();
  const Mat<3, 2> ef = dn::tangent_basis(D_);
  // x_B − x_A: φ_B − (φ_A + R_A X_A), linear in q.
  rows_.add_vector(slot<18>(12) - slot<18>(0) - body_vector_map<18>(X_A_, 0));
  // d_B·(R_A e), d_B·(R_A f): bilinear. With |d_B| = 1 and R_A orthonormal they say d_B = ±R_A D;
  // continuity from t = 0 selects +.
  for (int k = 0; k < 2; ++k) rows_.add_product(slot<18>(15), body_vector_map<18>(ef.col(k), 0));
}

VecX DirectorOnFrame::constraints(CRef qa, CRef qb) const {
  return rows_.values(stack<18>(qa, qb));
}

MatX DirectorOnFrame::jacobian(CRef qa, CRef qb) const {
  return rows_.jacobian(stack<18>(qa, qb));
}

void DirectorOnFrame::add_constraint_hessian(CRef lambda, MatX& H) const {
  rows_.add_hessian(lambda, H);
}

Mat<6, 6> DirectorOnFrame::parent_block(CRef qa, CRef) const {
  // φ̇_B = φ̇_A + ω_A × ρ_A, ω_B = ω_A, with ρ_A = X_A,I d_I^A: ρ̇_A = ω_A × ρ_A and
  // (R_A e)˙ = ω_A × R_A e hold for every q_A ∈ R¹² (P_int of a frame node), so the point rows
  // have zero rate and (d_B·a)˙ = (ω_A × d_B)·a + d_B·(ω_A × a) = 0 for every q.
  Mat<6, 6> A = Mat<6, 6>::Identity();
  A.block<3, 3>(0, 3) = -skew(body_vector(qa, X_A_));
  return A;
}

FreedomBlock DirectorOnFrame::freedom_block(CRef, CRef) const {
  return MatX::Zero(6, 0);
}

NodeVec DirectorOnFrame::update(CRef, CRef qa_n1, const Mat3& step_a, CRef, CRef tau, Mat3* step_b,
                                const StepIncrement* parent, StepIncrement* child) const {
  assert(tau.size() == 0);
  (void)tau;
  // From A's configuration at t_{n+1} directly (not Q_A d_B,n): no round-off drift of the rows.
  // The derivative w.r.t. A's motion δφ, δQ_A = δω̂ Q_A is δφ + δω × ρ_A, δω × d_B: the block A.
  if (step_b) *step_b = step_a;
  if (child) {  // (Δφ_A + ΔR_A X_A, ΔR_A D), ΔR_A the parent's director increments
    const Mat3 dRa = Eigen::Map<const Mat3>(parent->dq.data() + 3);
    dn::Q dq;
    dq << parent->dq.head<3>() + dRa * X_A_, dRa * D_;
    child->dq = dq;
    child->dQ = parent->dQ;
  }
  const fn::Q qa = qa_n1;
  dn::Q qb;
  qb << fn::phi(qa) + body_vector(qa, X_A_), body_vector(qa, D_);
  return qb;
}

FreedomBlock DirectorOnFrame::update_freedom_block(CRef, CRef, CRef, CRef) const {
  return MatX::Zero(6, 0);
}

// --- FrameOnDirector ---------------------------------------------------------------------------
// q = (φ_A, d_A, φ_B, d₁^B, d₂^B, d₃^B) ∈ R¹⁸.

FrameOnDirector::FrameOnDirector(const dn::Q& qa0, const fn::Q& qb0) {
  const Mat3 Rb = fn::directors(qb0);
  X_B_ = Rb.transpose() * (qa0.head<3>() - fn::phi(qb0));
  const Mat<3, 2> ef = dn::tangent_basis(Rb.transpose() * qa0.tail<3>());
  // φ_B + R_B X_B − φ_A: B's material point at the shell node.
  rows_.add_vector(slot<18>(6) + body_vector_map<18>(X_B_, 6) - slot<18>(0));
  // (R_B e)·d_A, (R_B f)·d_A: d_A stays B's body direction D_B; rotation about it is free.
  for (int k = 0; k < 2; ++k) rows_.add_product(body_vector_map<18>(ef.col(k), 6), slot<18>(3));
}

VecX FrameOnDirector::constraints(CRef qa, CRef qb) const {
  return rows_.values(stack<18>(qa, qb));
}

MatX FrameOnDirector::jacobian(CRef qa, CRef qb) const {
  return rows_.jacobian(stack<18>(qa, qb));
}

void FrameOnDirector::add_constraint_hessian(CRef lambda, MatX& H) const {
  rows_.add_hessian(lambda, H);
}

Mat<6, 6> FrameOnDirector::parent_block(CRef, CRef qb) const {
  // ω_B = ω_A + τ d_A and φ̇_B = φ̇_A − ω_B × ρ_B (ρ_B = X_B,I d_I^B): the point row's rate is
  // φ̇_B + ω_B × ρ_B − φ̇_A = 0, and with b = R_B e, (b·d_A)˙ = (ω_B × b)·d_A + b·(ω_A × d_A)
  // = (ω_B − ω_A)·(b × d_A) = τ d_A·(b × d_A) = 0 — for every q ∈ R¹⁸.
  Mat<6, 6> A = Mat<6, 6>::Identity();
  A.block<3, 3>(0, 3) = skew(body_vector(qb, X_B_));
  return A;
}

FreedomBlock FrameOnDirector::freedom_block(CRef qa, CRef qb) const {
  const Vec3 d = director(qa);
  MatX B(6, 1);
  B << body_vector(qb, X_B_).cross(d), d;
  return B;
}

NodeVec FrameOnDirector::update(CRef, CRef qa_n1, const Mat3& step_a, CRef qb_n, CRef tau,
                                Mat3* step_b, const StepIncrement* parent,
                                StepIncrement* child) const {
  assert(tau.size() == 1);
  // As for the intersection: R_B,n+1 = exp(τ d̂_A,n+1) Q_A R_B,n keeps (R_B e)·d_A at its value
  // (Q_A d_A,n = d_A,n+1), and B's material point is put back on the node.
  Mat3 A;
  const Mat3 R = rodrigues(Vec3(tau(0) * director(qa_n1)), child ? &A : nullptr) * step_a;
  if (step_b) *step_b = R;
  if (child) {  // (Δφ_A − ΔR_B X_B, ΔR_B), ΔR_B = (R − I) R_B,n
    child->dQ = compose_increments(A, parent->dQ);
    const Mat3 dRb = child->dQ * fn::directors(qb_n);
    child->dq = fn::make(parent->dq.head<3>() - dRb * X_B_, dRb);
  }
  const Mat3 Rb = R * fn::directors(qb_n);
  return fn::make(qa_n1.head<3>() - Rb * X_B_, Rb);
}

FreedomBlock FrameOnDirector::update_freedom_block(CRef qa_n1, CRef, CRef qb_n1, CRef) const {
  return freedom_block(qa_n1, qb_n1);  // fixed axis d_A,n+1, as ShellIntersection
}

// --- DirectorSupport ---------------------------------------------------------------------------
// q = (ground ∈ R¹², φ_B, d_B) ∈ R¹⁸; the rows do not use the ground's coordinates.

DirectorSupport::DirectorSupport(const dn::Q& qb0, const DirectorSupportSpec& spec)
    : spec_(spec), d0_(qb0.tail<3>()) {
  if (spec_.director == DirectorCondition::about_axis) {
    const double n = spec_.axis.norm();
    if (!(n > 0.0 && std::isfinite(n))) {
      reject("director support: the axis of an about_axis condition is zero or not finite", n);
    }
    spec_.axis /= n;
    const double s = sine(spec_.axis, d0_);
    if (!(s > kParallel)) reject("director support: axis parallel to the director at t = 0", s);
  }
  for (int i = 0; i < 3; ++i) {
    if (spec_.fix_translation[i]) {
      Vec<18> g = Vec<18>::Zero();
      g(12 + i) = 1.0;
      rows_.add_linear(g, qb0(i));  // e_iᵀ(φ_B − φ_B0)
    } else {
      ++free_count_;
    }
  }
  switch (spec_.director) {
    case DirectorCondition::free:
      break;
    case DirectorCondition::fixed: {
      const Mat<3, 2> ef = dn::tangent_basis(d0_);
      for (int k = 0; k < 2; ++k) {
        Vec<18> g = Vec<18>::Zero();
        g.tail<3>() = ef.col(k);  // d_B·e: linear (e is fixed in space)
        rows_.add_linear(g);
      }
      break;
    }
    case DirectorCondition::about_axis: {
      Vec<18> g = Vec<18>::Zero();
      g.tail<3>() = spec_.axis;
      rows_.add_linear(g, spec_.axis.dot(d0_));  // d_B·n − d_B0·n
      break;
    }
  }
}

int DirectorSupport::rotation_count() const {
  switch (spec_.director) {
    case DirectorCondition::free:
      return 2;
    case DirectorCondition::fixed:
      return 0;
    case DirectorCondition::about_axis:
      return 1;
  }
  return 0;
}

VecX DirectorSupport::constraints(CRef qa, CRef qb) const {
  return rows_.values(stack<18>(qa, qb));
}

MatX DirectorSupport::jacobian(CRef qa, CRef qb) const {
  return rows_.jacobian(stack<18>(qa, qb));
}

void DirectorSupport::add_constraint_hessian(CRef lambda, MatX& H) const {
  rows_.add_hessian(lambda, H);  // all rows linear: adds nothing
}

Mat<6, 6> DirectorSupport::parent_block(CRef, CRef) const {
  return Mat<6, 6>::Zero();
}

FreedomBlock DirectorSupport::freedom_block(CRef, CRef qb) const {
  // Translations along the free e_i (rows e_jᵀφ for the fixed j ≠ i see nothing); rotations that
  // keep the director rows: ω = θ̇₁ d₂ − θ̇₂ d₁ (45) with the basis at the given q (free), ω = n
  // ((n × d)·n = 0, about_axis).
  MatX B = MatX::Zero(6, freedom_count());
  int col = 0;
  for (int i = 0; i < 3; ++i) {
    if (!spec_.fix_translation[i]) B(i, col++) = 1.0;
  }
  if (spec_.director == DirectorCondition::free) {
    B.block<3, 2>(3, col) = dn::root_block(qb).bottomRightCorner<3, 2>();
  } else if (spec_.director == DirectorCondition::about_axis) {
    B.block<3, 1>(3, col) = spec_.axis;
  }
  return B;
}

Vec<5> DirectorSupport::root_increment(CRef tau) const {
  Vec<5> u = Vec<5>::Zero();
  int k = 0;
  for (int i = 0; i < 3; ++i) {
    if (!spec_.fix_translation[i]) u(i) = tau(k++);
  }
  if (spec_.director == DirectorCondition::free) u.tail<2>() = tau.segment<2>(k);
  return u;
}

NodeVec DirectorSupport::update(CRef, CRef, const Mat3&, CRef qb_n, CRef tau, Mat3* step_b,
                                const StepIncrement*, StepIncrement* child) const {
  assert(tau.size() == freedom_count());
  // φ_B,n+1 = φ_B,n + Σ τ_i e_i leaves the fixed components untouched (bit for bit). The parent
  // is the ground: the increments are the support's own.
  const Vec<5> u = root_increment(tau);
  const dn::Q qn = qb_n;
  dn::Q dq;
  switch (spec_.director) {
    case DirectorCondition::free: {  // the free node's map (53)–(54) with the basis at t_n
      if (!child) return dn::root_update(qn, u, step_b);
      const dn::Q q = dn::root_update(qn, u, step_b, &dq, &child->dQ);
      child->dq = dq;
      return q;
    }
    case DirectorCondition::fixed: {
      if (step_b) *step_b = Mat3::Identity();
      if (child) {
        dq << u.head<3>(), Vec3::Zero();
        child->dq = dq;
        child->dQ.setZero();
      }
      dn::Q q;
      q << qn.head<3>() + u.head<3>(), d0_;  // exact: no round-off drift
      return q;
    }
    case DirectorCondition::about_axis: {
      // exp(τ n̂) keeps d·n.
      Mat3 A;
      const Mat3 R = rodrigues(Vec3(tau(free_count_) * spec_.axis), child ? &A : nullptr);
      if (step_b) *step_b = R;
      if (child) {
        dq << u.head<3>(), A * qn.tail<3>();
        child->dq = dq;
        child->dQ = A;
      }
      dn::Q q;
      q << qn.head<3>() + u.head<3>(), R * qn.tail<3>();
      return q;
    }
  }
  return VecX(qb_n);
}

FreedomBlock DirectorSupport::update_freedom_block(CRef qa_n1, CRef qb_n, CRef qb_n1,
                                                   CRef tau) const {
  if (spec_.director != DirectorCondition::free) {
    return freedom_block(qa_n1, qb_n1);  // fixed axis n: T(τn) n = n
  }
  // Free director: [d₂ −d₁] at t_n times T(θ), as director_node::root_update_block.
  const Mat<6, 5> R = dn::root_update_block(qb_n, root_increment(tau));
  MatX B = MatX::Zero(6, freedom_count());
  int col = 0;
  for (int i = 0; i < 3; ++i) {
    if (!spec_.fix_translation[i]) B(i, col++) = 1.0;
  }
  B.block<3, 2>(3, col) = R.bottomRightCorner<3, 2>();
  return B;
}

}  // namespace isoflex::joints
