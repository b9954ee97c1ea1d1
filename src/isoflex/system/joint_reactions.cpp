#include "isoflex/system/joint_reactions.hpp"

#include <cassert>

#include "isoflex/joints/frame_joint.hpp"
#include "isoflex/math/frame_node.hpp"

namespace isoflex::system {

namespace {

// The multipliers of rows offset … offset + m − 1 (all-rows layout) from the selected ones'
// (position: all-row → selected index, −1 for a row not selected, whose λ is 0).
VecX rows_multipliers(const VecX& lambda, const std::vector<int>& position, int offset, int m) {
  VecX lam = VecX::Zero(m);
  for (int i = 0; i < m; ++i)
    if (const int p = position[static_cast<std::size_t>(offset + i)]; p >= 0) lam(i) = lambda(p);
  return lam;
}

// A joint with a director or point node (director-shell nodes, KL control points): the net force
// and moment of its rows' forces on body_b's node, about that node's position φ (the joint point:
// such joints join at nodes), global components in both columns (a node without a frame).
JointReaction node_reaction(const System& sys, const JointInstance& J, const VecX& q,
                            const VecX& lambda, const std::vector<int>& position) {
  const auto& nodes = J.rows->nodes();
  const int m = J.rows->constraint_count();
  const VecX lam = rows_multipliers(lambda, position, J.row_offset, m);
  const VecX f = -(J.rows->jacobian(sys.stacked(q, nodes)).transpose() * lam);
  // body_b's node (the child unless reversed); the ground as body_b: the other node, negated.
  const int b = J.reversed ? J.parent : J.child;
  const int node = b >= 0 ? b : (J.reversed ? J.child : J.parent);
  const double sign = b >= 0 ? 1.0 : -1.0;
  int o = 0;
  for (int a : nodes) {
    if (a == node) break;
    o += sys.coordinate_count(a);
  }
  const auto qn = sys.node_q(q, node);
  const Vec3 F = sign * Vec3(f.segment<3>(o));
  Vec3 M = Vec3::Zero();
  for (int k = 1; k < sys.coordinate_count(node) / 3; ++k)  // directors: d × f_d
    M += sign * Vec3(qn.segment<3>(3 * k)).cross(Vec3(f.segment<3>(o + 3 * k)));
  return {J.name, qn.head<3>(), F, M, F, M, std::nullopt};
}

}  // namespace

std::vector<JointReaction> joint_reactions(const System& sys, const VecX& q, const VecX& lambda) {
  assert(lambda.size() == sys.m_selected());
  std::vector<int> position(static_cast<std::size_t>(sys.m_all()), -1);
  for (int p = 0; p < sys.m_selected(); ++p)
    position[static_cast<std::size_t>(sys.selected_rows()[static_cast<std::size_t>(p)])] = p;
  std::vector<JointReaction> out;
  for (const JointInstance& J : sys.joints()) {
    if (!J.frame) {
      if (J.rows) out.push_back(node_reaction(sys, J, q, lambda, position));
      continue;
    }
    const auto qa = sys.node_q(q, J.parent), qb = sys.node_q(q, J.child);
    const int m = J.frame->constraint_count();
    const VecX lam = rows_multipliers(lambda, position, J.row_offset, m);
    const VecX f = -(J.frame->jacobian(qa, qb).transpose() * lam);  // parent 12, child 12
    // body_b is the child unless the tree edge was reversed; the ground as body_b: the reaction
    // on the other node, negated (at the same joint point).
    const bool on_parent = J.reversed;
    const int node = on_parent ? J.parent : J.child;
    const bool ground = node < 0;
    const bool use_parent = ground ? !on_parent : on_parent;
    const auto& g = J.frame->geometry();
    const frame_node::Q qn = use_parent ? qa : qb;
    const Vec3 X = use_parent ? g.X_A : g.X_B;
    const Mat3 C = use_parent ? g.C_A : g.C_B;
    Vec<12> fn = f.segment<12>(use_parent ? 0 : 12);
    // A driver row (an n-ary constraint over the non-ground nodes of body_a, body_b): its force
    // on the same node.
    std::optional<double> driving;
    if (J.driver >= 0) {
      const ConstraintInstance& D = sys.nary_constraints()[static_cast<std::size_t>(J.driver)];
      const int row = D.row_offset;
      const VecX lam_d = rows_multipliers(lambda, position, row, 1);
      const VecX fd =
          -(D.constraint->jacobian(sys.stacked(q, D.constraint->nodes())).transpose() * lam_d);
      const int node_of_fn = use_parent ? J.parent : J.child;
      int o = 0;
      for (int a : D.constraint->nodes()) {
        if (a == node_of_fn) fn += fd.segment<12>(o);
        o += sys.coordinate_count(a);
      }
      driving = -lam_d(0);
    }
    const Mat3 D = frame_node::directors(qn);
    const Vec3 phi = qn.head<3>();
    const Vec3 rho = D * X;
    Vec3 F = fn.head<3>();
    Vec3 M = Vec3::Zero();
    for (int i = 0; i < 3; ++i) M += D.col(i).cross(Vec3(fn.segment<3>(3 + 3 * i)));
    M -= rho.cross(F);
    if (ground) {
      F = -F;
      M = -M;
    }
    const Mat3 B = D * C;
    out.push_back({J.name, phi + rho, F, M, B.transpose() * F, B.transpose() * M, driving});
  }
  // Joints at shell points: the reaction on the shell (body_b), the net force and moment of the
  // rows' forces on the control points about the shell's material point; local components in
  // the body's directors (global with the ground).
  for (const ShellPointJointInstance& s : sys.shell_point_joints()) {
    const ConstraintInstance& c = sys.nary_constraints()[static_cast<std::size_t>(s.constraint)];
    const auto& nodes = c.constraint->nodes();
    const int m = c.constraint->constraint_count();
    const VecX lam = rows_multipliers(lambda, position, c.row_offset, m);
    const VecX f = -(c.constraint->jacobian(sys.stacked(q, nodes)).transpose() * lam);
    Vec3 p = Vec3::Zero();
    for (const auto& [node, w] : s.point) p += w * Vec3(sys.node_q(q, node).head<3>());
    Vec3 F = Vec3::Zero(), M = Vec3::Zero();
    int o = 0;
    for (int node : nodes) {
      if (sys.node_kind(node) == NodeKind::point) {
        const Vec3 fa = f.segment<3>(o);
        F += fa;
        M += (Vec3(sys.node_q(q, node).head<3>()) - p).cross(fa);
      }
      o += sys.coordinate_count(node);
    }
    const Mat3 D =
        s.body >= 0 ? Mat3(frame_node::directors(sys.node_q(q, s.body))) : Mat3::Identity();
    out.push_back({c.name, p, F, M, D.transpose() * F, D.transpose() * M, std::nullopt});
  }
  return out;
}

}  // namespace isoflex::system
