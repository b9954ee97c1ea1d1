#include "isoflex/math/node_kind.hpp"

#include "isoflex/math/director_node.hpp"
#include "isoflex/math/frame_node.hpp"
#include "isoflex/math/point_node.hpp"
#include "isoflex/math/rotation.hpp"

namespace isoflex {

namespace {

namespace fn = frame_node;
namespace dn = director_node;
namespace pn = point_node;

// (φ, d₁, d₂, d₃), DNSM-III (16)–(37).
class FrameNodeType final : public NodeType {
 public:
  NodeKind kind() const override { return NodeKind::frame; }
  const char* name() const override { return "frame"; }
  int coordinates() const override { return fn::kCoords; }
  int internal_rows() const override { return fn::kConstraints; }
  int free_velocities() const override { return fn::kTwist; }
  NodeVec constraints(CRef q) const override { return fn::constraints(q); }
  NodeMat jacobian(CRef q) const override { return fn::jacobian(q); }
  void add_constraint_hessian(CRef lambda, NodeMat& H) const override {
    Mat<12, 12> h = Mat<12, 12>::Zero();
    fn::add_constraint_hessian(lambda, h);
    H += h;
  }
  NodeMat twist_null_space(CRef q) const override { return fn::null_space(q); }
  NodeMat root_block(CRef) const override { return Mat<6, 6>::Identity(); }
  Vec<6> twist_force(CRef q, CRef r) const override {
    return fn::null_space(q).transpose() * fn::Q(r);
  }
  NodeVec free_force(CRef, const Vec<6>& y) const override { return y; }
  NodeVec root_update(CRef qn, CRef u, Mat3& step, NodeVec& increment, Mat3& A) const override {
    step = rodrigues(u.segment<3>(3), A);
    increment.resize(fn::kCoords);
    increment.head<3>() = u.head<3>();
    for (int I = 0; I < 3; ++I) increment.segment<3>(3 + 3 * I) = A * qn.segment<3>(3 + 3 * I);
    return fn::update(qn, u, step);
  }
  NodeMat root_update_block(CRef, CRef u) const override {
    Mat<6, 6> B = Mat<6, 6>::Identity();
    B.bottomRightCorner<3, 3>() = rodrigues_tangent(u.segment<3>(3));  // (37)
    return B;
  }
  bool extrapolate(CRef, CRef, double, Eigen::Ref<VecX>) const override { return false; }
  Vec3 material_point(CRef q, const Vec3& X) const override {
    const fn::Q qn = q;
    return fn::phi(qn) + fn::directors(qn) * X;
  }
  Vec3 local_coordinates(CRef q, const Vec3& x) const override {
    const fn::Q qn = q;
    return fn::directors(qn).transpose() * (x - fn::phi(qn));
  }
  Mat3 frame(CRef q) const override { return fn::directors(q); }
  Vec3 angular_velocity(CRef q, CRef v) const override {
    const fn::Q qn = q, vn = v;
    Vec3 w = Vec3::Zero();  // ω = ½ Σ d_I × ḋ_I
    for (int I = 0; I < 3; ++I) w += 0.5 * fn::director(qn, I).cross(fn::director(vn, I));
    return w;
  }
};

// (φ, d), DNSM-III (40)–(54), in the twist form (68).
class DirectorNodeType final : public NodeType {
 public:
  NodeKind kind() const override { return NodeKind::director; }
  const char* name() const override { return "director"; }
  int coordinates() const override { return dn::kCoords; }
  int internal_rows() const override { return dn::kConstraints; }
  int free_velocities() const override { return dn::kTwist; }
  NodeVec constraints(CRef q) const override {
    NodeVec g(1);
    g(0) = dn::constraint(q);
    return g;
  }
  NodeMat jacobian(CRef q) const override { return dn::jacobian(q); }
  void add_constraint_hessian(CRef lambda, NodeMat& H) const override {
    H.bottomRightCorner<3, 3>().diagonal().array() += lambda(0);  // ∂²/∂d² ½(d·d − 1) = I (41)
  }
  NodeMat twist_null_space(CRef q) const override { return dn::twist_null_space(q); }
  NodeMat root_block(CRef q) const override { return dn::root_block(q); }
  Vec<6> twist_force(CRef q, CRef r) const override {
    return dn::twist_null_space(q).transpose() * dn::Q(r);
  }
  NodeVec free_force(CRef q, const Vec<6>& y) const override {
    return dn::root_block(q).transpose() * y;
  }
  NodeVec root_update(CRef qn, CRef u, Mat3& step, NodeVec& increment,
                      Mat3& step_increment) const override {
    dn::Q dq;
    const dn::Q q = dn::root_update(qn, u, &step, &dq, &step_increment);
    increment = dq;
    return q;
  }
  NodeMat root_update_block(CRef qn, CRef u) const override { return dn::root_update_block(qn, u); }
  void transport_increments(CRef qn, CRef q1, Eigen::Ref<VecX> u) const override {
    dn::transport_increments(qn, q1, u);
  }
  // The position by Δt φ̇; the rotation keeps the last step's increments (transported to the
  // basis at q, scaled by the step ratio): the mean angular velocity of the last step, not ω
  // at tₙ, which carries the undamped period-2 oscillation of the unresolved director modes
  // (docs/theory/schemes.md §6).
  bool extrapolate(CRef, CRef v, double dt, Eigen::Ref<VecX> u) const override {
    u.head<3>() = dt * v.segment<3>(0);
    return true;
  }
  Vec3 material_point(CRef q, const Vec3& X) const override {
    return q.segment<3>(0) + X.z() * q.segment<3>(3);
  }
  // A global point attached to a shell node is its mid-surface point.
  Vec3 local_coordinates(CRef, const Vec3&) const override { return Vec3::Zero(); }
  Mat3 frame(CRef q) const override {
    const Vec3 d = q.segment<3>(3);
    Mat3 D;
    D << dn::tangent_basis(d), d;
    return D;
  }
  Vec3 angular_velocity(CRef q, CRef v) const override {
    return Vec3(q.segment<3>(3)).cross(Vec3(v.segment<3>(3)));  // no drilling part
  }
};

// φ: an IGA control point or a particle, P_int = [I 0], update φ + u.
class PointNodeType final : public NodeType {
 public:
  NodeKind kind() const override { return NodeKind::point; }
  const char* name() const override { return "point"; }
  int coordinates() const override { return pn::kCoords; }
  int internal_rows() const override { return pn::kConstraints; }
  int free_velocities() const override { return pn::kTwist; }
  NodeVec constraints(CRef) const override { return NodeVec(0); }
  NodeMat jacobian(CRef) const override { return NodeMat(0, pn::kCoords); }
  void add_constraint_hessian(CRef, NodeMat&) const override {}
  NodeMat twist_null_space(CRef) const override {
    NodeMat P = NodeMat::Zero(3, 6);
    P.leftCols<3>().setIdentity();
    return P;
  }
  NodeMat root_block(CRef) const override {
    NodeMat B = NodeMat::Zero(6, 3);
    B.topRows<3>().setIdentity();
    return B;
  }
  Vec<6> twist_force(CRef, CRef r) const override {
    Vec<6> y;
    y << r.head<3>(), Vec3::Zero();
    return y;
  }
  NodeVec free_force(CRef, const Vec<6>& y) const override { return y.head<3>(); }
  NodeVec root_update(CRef qn, CRef u, Mat3& step, NodeVec& increment,
                      Mat3& step_increment) const override {
    step.setIdentity();
    step_increment.setZero();
    increment = u.head<3>();
    return pn::update(qn, u);
  }
  NodeMat root_update_block(CRef q, CRef) const override { return root_block(q); }
  // The last step's increment Δt v_{n−½} (scaled by the step ratio) is a better start than Δt vₙ:
  // the midpoint rule leaves the unresolved membrane modes of a thin KL shell undamped, and vₙ
  // carries their period-2 oscillation while the averaged velocity does not (on
  // examples/kl_free_plate: 25 % fewer Newton iterations).
  bool extrapolate(CRef, CRef, double, Eigen::Ref<VecX>) const override { return false; }
  Vec3 material_point(CRef q, const Vec3&) const override { return q.head<3>(); }
  Vec3 local_coordinates(CRef, const Vec3&) const override { return Vec3::Zero(); }
  Mat3 frame(CRef) const override { return Mat3::Identity(); }
  Vec3 angular_velocity(CRef, CRef) const override { return Vec3::Zero(); }
};

}  // namespace

const NodeType& node_type(NodeKind kind) {
  static const FrameNodeType frame;
  static const DirectorNodeType director;
  static const PointNodeType point;
  switch (kind) {
    case NodeKind::frame:
      return frame;
    case NodeKind::director:
      return director;
    case NodeKind::point:
      return point;
  }
  throw std::logic_error("node_type: a node kind without a description");
}

}  // namespace isoflex
