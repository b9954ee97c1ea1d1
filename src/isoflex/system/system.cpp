#include "isoflex/system/system.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <map>

#include "isoflex/elements/beam_element.hpp"
#include "isoflex/elements/beam_mesh.hpp"
#include "isoflex/elements/rigid_body.hpp"
#include "isoflex/joints/director_joints.hpp"
#include "isoflex/joints/point_joints.hpp"
#include "isoflex/loads/patch_load_set.hpp"
#include "isoflex/math/director_node.hpp"
#include "isoflex/math/rotation.hpp"
#include "isoflex/math/skew.hpp"
#include "isoflex/solve/linear_solver.hpp"
#include "isoflex/system/joint_drivers.hpp"
#include "isoflex/system/kl_model.hpp"

namespace isoflex::system {

namespace fn = frame_node;
namespace dn = director_node;
using joints::NodeKind;

namespace {

[[noreturn]] void fail(const model::Source& s, const std::string& what, const std::string& msg) {
  compile_fail(s, what, msg);
}

// Templated so that fixed-size blocks are not copied into a heap-allocated MatX.
template <class Derived>
void add_block(Triplets& t, int r0, int c0, const Eigen::MatrixBase<Derived>& B) {
  for (int j = 0; j < B.cols(); ++j)
    for (int i = 0; i < B.rows(); ++i)
      if (B(i, j) != 0.0) t.emplace_back(r0 + i, c0 + j, B(i, j));
}

}  // namespace

joints::Joint::CRef System::node_q(const VecX& q, int node) const {
  if (node < 0) return ground_;
  return q.segment(nodes_[node].q_offset, coordinate_count(node));
}

void System::add_node(NodeKind kind, const VecX& q0, const std::string& name, int beam) {
  const NodeType& type = isoflex::node_type(kind);
  assert(q0.size() == type.coordinates());
  nodes_.push_back({&type, static_cast<int>(q0_build_.size()), internal_rows_});
  internal_rows_ += type.internal_rows();
  ++kind_count_[static_cast<int>(kind)];
  q0_build_.insert(q0_build_.end(), q0.data(), q0.data() + q0.size());
  node_names_.push_back(name);
  node_beam_.push_back(beam);
}

Vec3 System::body_coordinates(int node, const std::optional<Vec3>& global,
                              const std::optional<Vec3>& local) const {
  if (global) return node_type(node).local_coordinates(node_q(q0_, node), *global);
  return local ? *local : Vec3::Zero();
}

VecX System::stacked(const VecX& q, const std::vector<int>& nodes) const {
  int size = 0;
  for (int a : nodes) size += coordinate_count(a);
  VecX out(size);
  int o = 0;
  for (int a : nodes) {
    const int c = coordinate_count(a);
    out.segment(o, c) = q.segment(nodes_[a].q_offset, c);
    o += c;
  }
  return out;
}

int System::nary_of_row(int row) const {
  for (int c = 0; c < static_cast<int>(nary_.size()); ++c) {
    const auto& C = nary_[c];
    if (row >= C.row_offset && row < C.row_offset + C.constraint->constraint_count()) return c;
  }
  return -1;
}

int System::independent_rows_of(int c) const {
  for (const ReselectedGroup& g : reselected_groups_)
    if (g.constraint == c) return g.rank;
  const ConstraintInstance& C = nary_[static_cast<std::size_t>(c)];
  return static_cast<int>(std::count_if(cut_rows_.begin(), cut_rows_.end(), [&](int r) {
    return r >= C.row_offset && r < C.row_offset + C.constraint->constraint_count();
  }));
}

int System::joint_of_row(int row) const {
  for (int j = 0; j < static_cast<int>(joints_.size()); ++j) {
    const auto& J = joints_[j];
    if (row >= J.row_offset && row < J.row_offset + J.joint->constraint_count()) return j;
  }
  return -1;
}

void System::set_threads(int threads) {
  configure_kl_patches([threads](elements::KLShellPatch& p) { p.set_threads(threads); });
}

void System::keep_linear_tangent(bool keep) {
  configure_kl_patches([keep](elements::KLShellPatch& p) { p.set_keep_linear_tangent(keep); });
}

void System::partition_kl_patches(int part, int parts) {
  configure_kl_patches([=](elements::KLShellPatch& p) { p.set_partition(part, parts); });
  elements_of_part_0_.assign(elements_.size(), part != 0);
  for (const KLPatchInstance& P : kl_patches_)
    elements_of_part_0_[static_cast<std::size_t>(P.element_index)] = false;
}

int System::kl_parts() const {
  return kl_patches_.empty() ? 1 : kl_patches_.front().element->patch().parts();
}

void System::configure_kl_patches(const std::function<void(elements::KLShellPatch&)>& set) {
  for (KLPatchInstance& P : kl_patches_) {
    auto patch = std::make_shared<elements::KLShellPatch>(P.element->patch());  // shares the data
    set(*patch);
    auto element = std::make_unique<elements::KLPatchElement>(std::move(patch),
                                                              P.element->kinematics(), P.nodes);
    P.element = element.get();
    elements_[static_cast<std::size_t>(P.element_index)] = std::move(element);
  }
}

ProbeInstance System::kl_probe(const model::Probe& P) const {
  const auto patch = std::find_if(kl_patches_.begin(), kl_patches_.end(),
                                  [&](const KLPatchInstance& k) { return k.name == P.kl_shell; });
  if (patch == kl_patches_.end())
    fail(P.source, "probes", "no kl_shell named '" + P.kl_shell + "'");
  const geometry::NurbsSurface& g = patch->element->patch().reference();
  const geometry::SurfaceBasis B = geometry::surface_basis(g, P.xi, P.eta);
  ProbeInstance out{P.name, -1, Vec3::Zero(), {}};
  for (int k = 0; k < B.R.cols(); ++k)
    out.weights.push_back({patch->nodes[B.global_index(g, k)], B.R(0, k)});
  return out;
}

Vec3 System::probe_point(const VecX& q, const ProbeInstance& p) const {
  if (p.weights.empty()) return material_point(q, p.node, p.X);
  Vec3 x = Vec3::Zero();
  for (const auto& [node, w] : p.weights) x += w * q.segment<3>(nodes_[node].q_offset);
  return x;
}

std::vector<std::pair<int, double>> System::probe_gradient(const ProbeInstance& p,
                                                           const Vec3& direction) const {
  std::vector<std::pair<int, double>> c;
  if (!p.weights.empty()) {
    for (const auto& [node, w] : p.weights)
      for (int k = 0; k < 3; ++k)
        if (w * direction(k) != 0.0) c.emplace_back(nodes_[node].q_offset + k, w * direction(k));
    return c;
  }
  // Linear in the node's coordinates: the derivative along e_j is point(e_j) − point(0).
  const NodeType& type = node_type(p.node);
  NodeVec z = NodeVec::Zero(type.coordinates());
  const Vec3 origin = type.material_point(z, p.X);
  for (int j = 0; j < type.coordinates(); ++j) {
    z(j) = 1.0;
    const double v = direction.dot(type.material_point(z, p.X) - origin);
    z(j) = 0.0;
    if (v != 0.0) c.emplace_back(nodes_[p.node].q_offset + j, v);
  }
  return c;
}

std::vector<int> System::coordinates_of(const std::vector<int>& nodes) const {
  std::vector<int> c;
  for (int a : nodes)
    for (int k = 0; k < coordinate_count(a); ++k) c.push_back(nodes_[a].q_offset + k);
  return c;
}

void System::build_stiffness_pattern() {
  for (const auto& e : elements_)
    element_part_.push_back(stiffness_.add(e->pattern(), coordinates_of(e->nodes())));
  // Only a follower load has a tangent.
  for (const auto& L : loads_) {
    const std::vector<int> coords = coordinates_of(L->nodes());
    load_part_.push_back(
        L->follower() ? stiffness_.add(L->tangent_pattern(static_cast<int>(coords.size())), coords)
                      : -1);
  }
  stiffness_.finalize(n());
}

std::shared_ptr<const joints::Joint> System::director_joint(const model::Joint& J, int parent,
                                                            int child,
                                                            const std::string& what) const {
  using T = model::JointType;
  if (J.type != T::rigid && J.type != T::fixed)
    fail(J.source, what + ".type",
         fmt::format("a shell node joins bodies, beam nodes and other shell nodes rigidly only "
                     "(type rigid, or fixed to the ground; found {}): DNSM-III Ex. 5.3",
                     model::to_string(J.type)));
  const bool director_parent = parent >= 0 && node_kind(parent) == NodeKind::director;
  const bool director_child = node_kind(child) == NodeKind::director;
  try {
    if (director_parent && director_child)
      return std::make_shared<joints::ShellIntersection>(dn::Q(node_q(q0_, parent)),
                                                         dn::Q(node_q(q0_, child)));
    if (director_child)
      return std::make_shared<joints::DirectorOnFrame>(fn::Q(node_q(q0_, parent)),
                                                       dn::Q(node_q(q0_, child)));
    return std::make_shared<joints::FrameOnDirector>(dn::Q(node_q(q0_, parent)),
                                                     fn::Q(node_q(q0_, child)));
  } catch (const std::invalid_argument& e) {
    fail(J.source, what, e.what());
  }
}

double System::potential(const VecX& q) const {
  double V = 0.0;
  for (const auto& e : elements_) V += e->potential(stacked(q, e->nodes()));
  return V;
}

VecX System::discrete_force(const VecX& qn, const VecX& qn1, double t_mid, SpMat* K) const {
  return midpoint_forces(
      [&](const elements::Element& e, const std::vector<int>& nodes, double* values) {
        return e.discrete_gradient_in_pattern(stacked(qn, nodes), stacked(qn1, nodes), values);
      },
      qn, qn1, t_mid, K);
}

VecX System::mixed_discrete_force(const VecX& qn, const VecX& qn1, const VecX* q_lin, double t_mid,
                                  SpMat* K, VecX& stress_force) const {
  stress_force.setZero(n());
  VecX local;
  return midpoint_forces(
      [&](const elements::Element& e, const std::vector<int>& nodes, double* values) {
        const VecX ql = q_lin ? stacked(*q_lin, nodes) : VecX();
        VecX dv = e.mixed_discrete_gradient_in_pattern(stacked(qn, nodes), stacked(qn1, nodes),
                                                       q_lin ? &ql : nullptr, values, &local);
        add_stacked(nodes, local, stress_force);
        return dv;
      },
      qn, qn1, t_mid, K);
}

VecX System::midpoint_forces(const ElementKernel& kernel, const VecX& qn, const VecX& qn1,
                             double t_mid, SpMat* K) const {
  VecX f = VecX::Zero(n());
  if (K) stiffness_.reset(*K);
  add_element_forces(kernel, f, K);
  // Loads at the midpoint, f_ext(q_{n+½}, t_{n+½}); their part of ∂f/∂qₙ₊₁ is −½ ∂f_ext/∂q.
  add_load_forces(0.5 * (qn + qn1), t_mid, 0.5, f, K, nullptr);
  return f;
}

VecX System::static_force(const VecX& q, double t, SpMat* K, double* load_norm) const {
  VecX f = VecX::Zero(n());
  if (K) stiffness_.reset(*K);
  add_element_forces(
      [&](const elements::Element& e, const std::vector<int>& nodes, double* values) {
        return e.gradient_in_pattern(stacked(q, nodes), values);
      },
      f, K);
  VecX fext = VecX::Zero(load_norm ? n() : 0);
  add_load_forces(q, t, 1.0, f, K, load_norm ? &fext : nullptr);
  if (load_norm) *load_norm = n() > 0 ? fext.lpNorm<Eigen::Infinity>() : 0.0;
  return f;
}

VecX System::external_force(const VecX& q, double t) const {
  VecX f = VecX::Zero(n()), fext = VecX::Zero(n());
  add_load_forces(q, t, 1.0, f, nullptr, &fext);
  return fext;
}

void System::accept(const VecX& q) const {
  for (const auto& e : elements_) e->accept(stacked(q, e->nodes()));
  for_each_constraint([&](const joints::Constraint& C, int) { C.accept(stacked(q, C.nodes())); });
}

VecX System::viscous_force(const VecX& q, const VecX& qdot, double cq, double cv, SpMat* K) const {
  VecX f = VecX::Zero(n());
  add_element_forces(
      [&](const elements::Element& e, const std::vector<int>& nodes, double* values) {
        return e.viscous_force_in_pattern(stacked(q, nodes), stacked(qdot, nodes), cq, cv, values);
      },
      f, K, Kernels::viscous_adding);
  return f;
}

VecX System::strain_dissipation_force(const VecX& q_prev, const VecX& qn, const VecX& qn1,
                                      double chi, double ratio, SpMat* K) const {
  VecX f = VecX::Zero(n());
  add_element_forces(
      [&](const elements::Element& e, const std::vector<int>& nodes, double* values) {
        return e.strain_dissipation_force_in_pattern(stacked(q_prev, nodes), stacked(qn, nodes),
                                                     stacked(qn1, nodes), chi, ratio, values);
      },
      f, K, Kernels::strain_dissipation_adding);
  return f;
}

VecX System::mixed_strain_dissipation_force(const VecX& q_prev, const VecX& qn, const VecX& qn1,
                                            const VecX* q_lin, double chi, double ratio, SpMat* K,
                                            VecX& stress_force) const {
  VecX f = VecX::Zero(n());
  VecX local;
  add_element_forces(
      [&](const elements::Element& e, const std::vector<int>& nodes, double* values) {
        const VecX ql = q_lin ? stacked(*q_lin, nodes) : VecX();
        VecX fd = e.mixed_strain_dissipation_force_in_pattern(
            stacked(q_prev, nodes), stacked(qn, nodes), stacked(qn1, nodes), q_lin ? &ql : nullptr,
            chi, ratio, values, &local);
        add_stacked(nodes, local, stress_force);
        return fd;
      },
      f, K, Kernels::strain_dissipation_adding);
  return f;
}

void System::add_stacked(const std::vector<int>& nodes, const VecX& local, VecX& global) const {
  int o = 0;
  for (int a : nodes) {
    const int c = coordinate_count(a);
    global.segment(nodes_[a].q_offset, c) += local.segment(o, c);
    o += c;
  }
}

void System::add_element_forces(const ElementKernel& kernel, VecX& f, SpMat* K,
                                Kernels kernels) const {
  const bool adding = kernels != Kernels::all_overwriting;
  std::vector<double> values;
  bool touched = false;  // whether K has received values yet (it starts at zero)
  for (std::size_t i = 0; i < elements_.size(); ++i) {
    const auto& e = elements_[i];
    if (kernels == Kernels::viscous_adding && !e->viscous()) continue;
    if (kernels == Kernels::strain_dissipation_adding && !e->strain_dissipation()) continue;
    if (!elements_of_part_0_.empty() && elements_of_part_0_[i]) continue;
    const auto& nodes = e->nodes();
    const int part = element_part_[i];
    // An element whose pattern is the whole global one (a patch alone) writes in place: always
    // when its kernel adds to the values, else only while K is still zero.
    const bool in_place = K && (adding || !touched) && stiffness_.whole(part);
    if (K && !in_place) {
      if (adding)
        values.assign(stiffness_.local_entries(part), 0.0);
      else
        values.resize(stiffness_.local_entries(part));
    }
    add_stacked(nodes,
                kernel(*e, nodes,
                       !K         ? nullptr
                       : in_place ? K->valuePtr()
                                  : values.data()),
                f);
    if (K && !in_place) stiffness_.scatter(part, values.data(), *K);
    touched = touched || (K && stiffness_.local_entries(part) > 0);
  }
}

// f −= f_ext(q, t) load by load; K += −c ∂f_ext/∂q; fext (if not null) += f_ext.
void System::add_load_forces(const VecX& q, double t, double c, VecX& f, SpMat* K,
                             VecX* fext) const {
  std::vector<double> values;
  for (std::size_t l = 0; l < loads_.size(); ++l) {
    const loads::Load& L = *loads_[l];
    const VecX x = stacked(q, L.nodes());
    const VecX g = L.generalized_force(x, t);
    int o = 0;
    for (int a : L.nodes()) {
      const int n = coordinate_count(a);
      f.segment(nodes_[a].q_offset, n) -= g.segment(o, n);
      if (fext) fext->segment(nodes_[a].q_offset, n) += g.segment(o, n);
      o += n;
    }
    if (!K || load_part_[l] < 0) continue;
    values.assign(static_cast<std::size_t>(stiffness_.local_entries(load_part_[l])), 0.0);
    L.add_tangent(x, t, -c, values.data());
    stiffness_.scatter(load_part_[l], values.data(), *K);
  }
}

// Every row of the model after the nodes' internal rows, through the constraint contract: the
// joints' rows (JointRows), then the n-ary constraints, with their first row.
template <class F>
void System::for_each_constraint(F&& f) const {
  for (const auto& J : joints_) f(*J.rows, J.row_offset);
  for (const auto& C : nary_) f(*C.constraint, C.row_offset);
}

VecX System::constraints(const VecX& q, double t) const {
  VecX c(m_all_);
  for (int i = 0; i < node_count(); ++i) {
    const Node& nd = nodes_[i];
    c.segment(nd.row_offset, nd.type->internal_rows()) = nd.type->constraints(node_q(q, i));
  }
  for_each_constraint([&](const joints::Constraint& C, int row) {
    c.segment(row, C.constraint_count()) = C.constraints(stacked(q, C.nodes()));
    if (C.rheonomic()) c.segment(row, C.constraint_count()) -= C.prescribed(t);
  });
  return c;
}

VecX System::prescribed(double t) const {
  VecX d = VecX::Zero(m_all_);
  for_each_constraint([&](const joints::Constraint& C, int row) {
    if (C.rheonomic()) d.segment(row, C.constraint_count()) = C.prescribed(t);
  });
  return d;
}

namespace {

// The rows `rows` of `all` (m_all × n), in that order.
SpMat pick_rows(const SpMat& all, const std::vector<int>& rows) {
  Triplets s;
  for (std::size_t i = 0; i < rows.size(); ++i) s.emplace_back(static_cast<int>(i), rows[i], 1.0);
  SpMat S(static_cast<int>(rows.size()), all.rows());
  S.setFromTriplets(s.begin(), s.end());
  return S * all;
}

}  // namespace

// Every row's Jacobian block G_c from `block(C)` for the constraints, the nodes' internal rows
// (quadratic) at qm; then the rows picked.
template <class Block>
SpMat System::assemble_rows(const VecX& qm, const std::vector<int>& rows, Block&& block) const {
  Triplets t;
  for (int i = 0; i < node_count(); ++i)
    add_block(t, nodes_[i].row_offset, nodes_[i].q_offset, node_type(i).jacobian(node_q(qm, i)));
  for_each_constraint([&](const joints::Constraint& C, int row) {
    const MatX G = block(C);
    int o = 0;
    for (int a : C.nodes()) {
      add_block(t, row, nodes_[a].q_offset, G.middleCols(o, coordinate_count(a)));
      o += coordinate_count(a);
    }
  });
  SpMat all(m_all_, n());
  all.setFromTriplets(t.begin(), t.end());
  return pick_rows(all, rows);
}

SpMat System::jacobian_rows(const VecX& q, const std::vector<int>& rows) const {
  return assemble_rows(
      q, rows, [&](const joints::Constraint& C) { return C.jacobian(stacked(q, C.nodes())); });
}

SpMat System::jacobian(const VecX& q) const {
  return jacobian_rows(q, selected_rows_);
}

SpMat System::discrete_jacobian_rows(const VecX& qa, const VecX& qb,
                                     const std::vector<int>& rows) const {
  return assemble_rows(0.5 * (qa + qb), rows, [&](const joints::Constraint& C) {
    return C.discrete_jacobian(stacked(qa, C.nodes()), stacked(qb, C.nodes()));
  });
}

SpMat System::discrete_jacobian(const VecX& qa, const VecX& qb) const {
  return discrete_jacobian_rows(qa, qb, selected_rows_);
}

SpMat System::constraint_hessian(const VecX& q, const VecX& lambda_sel) const {
  VecX l = VecX::Zero(m_all_);
  for (std::size_t i = 0; i < selected_rows_.size(); ++i) l(selected_rows_[i]) = lambda_sel(i);
  Triplets t;
  for (int i = 0; i < node_count(); ++i) {
    const Node& nd = nodes_[i];
    const int c = nd.type->coordinates();
    if (nd.type->internal_rows() == 0) continue;
    NodeMat H = NodeMat::Zero(c, c);
    nd.type->add_constraint_hessian(l.segment(nd.row_offset, nd.type->internal_rows()), H);
    add_block(t, nd.q_offset, nd.q_offset, H);
  }
  for_each_constraint([&](const joints::Constraint& C, int row) {
    const std::vector<int> coords = coordinates_of(C.nodes());
    MatX H = MatX::Zero(coords.size(), coords.size());
    C.add_constraint_hessian(stacked(q, C.nodes()), l.segment(row, C.constraint_count()), H);
    for (int j = 0; j < H.cols(); ++j)
      for (int i = 0; i < H.rows(); ++i)
        if (H(i, j) != 0.0) t.emplace_back(coords[i], coords[j], H(i, j));
  });
  SpMat H(n(), n());
  H.setFromTriplets(t.begin(), t.end());
  return H;
}

VecX System::constraint_curvature(const VecX& q, const VecX& v) const {
  // G is affine in q for the rows at most quadratic, so (G(q + v) − G(q)) v = (vᵀ∇²Φᵢ v)ᵢ exactly.
  VecX out = (jacobian(q + v) - jacobian(q)) * v;
  std::vector<int> position(static_cast<std::size_t>(m_all_), -1);
  for (std::size_t p = 0; p < selected_rows_.size(); ++p)
    position[static_cast<std::size_t>(selected_rows_[p])] = static_cast<int>(p);
  // A driven angle (not quadratic): its Hessian.
  for (const auto& C : nary_) {
    if (!dynamic_cast<const JointDriver*>(C.constraint.get())) continue;
    const int p = position[static_cast<std::size_t>(C.row_offset)];
    if (p < 0) continue;
    const VecX qc = stacked(q, C.constraint->nodes()), vc = stacked(v, C.constraint->nodes());
    MatX H = MatX::Zero(qc.size(), qc.size());
    C.constraint->add_constraint_hessian(qc, VecX::Ones(1), H);
    out(p) = vc.dot(H * vc);
  }
  return out;
}

System::InputBlocks System::input_blocks(const VecX& q) const {
  InputBlocks in;
  for (int r : roots_) in.root.push_back(node_type(r).root_block(node_q(q, r)));
  in.joint.resize(joints_.size());
  for (int j : tree_order_) {
    const auto& J = joints_[j];
    in.joint[j] = J.joint->freedom_block(node_q(q, J.parent), node_q(q, J.child));
  }
  return in;
}

System::InputBlocks System::update_input_blocks(const VecX& qn, const VecX& q1,
                                                const VecX& u) const {
  InputBlocks in;
  for (std::size_t r = 0; r < roots_.size(); ++r)
    in.root.push_back(node_type(roots_[r]).root_update_block(
        node_q(qn, roots_[r]), u.segment(root_nu_offset_[r], root_width_[r])));
  in.joint.resize(joints_.size());
  for (int j : tree_order_) {
    const auto& J = joints_[j];
    in.joint[j] = J.joint->update_freedom_block(node_q(q1, J.parent), node_q(qn, J.child),
                                                node_q(q1, J.child),
                                                u.segment(J.nu_offset, J.joint->freedom_count()));
  }
  return in;
}

System::TwistBlocks System::twist_blocks(const VecX& q, const InputBlocks& in) const {
  TwistBlocks rows(node_count());
  for (std::size_t r = 0; r < roots_.size(); ++r)
    rows[roots_[r]].push_back({root_nu_offset_[r], in.root[r]});
  for (int j : tree_order_) {
    const auto& J = joints_[j];
    auto& out = rows[J.child];
    if (J.parent >= 0) {
      const Mat<6, 6> A = J.joint->parent_block(node_q(q, J.parent), node_q(q, J.child));
      for (const auto& [c, B] : rows[J.parent]) out.push_back({c, A * B});
    }
    if (J.joint->freedom_count() > 0) out.push_back({J.nu_offset, in.joint[j]});
  }
  return rows;
}

SpMat System::twist_map(const VecX& q, const InputBlocks& in) const {
  // Each node's twist as a sum of blocks (first column in ν, 6 × w block) over its tree path.
  const TwistBlocks rows = twist_blocks(q, in);
  Triplets t;
  for (int i = 0; i < node_count(); ++i)
    for (const auto& [c, B] : rows[i]) add_block(t, 6 * i, c, B);
  SpMat E(6 * node_count(), k_);
  E.setFromTriplets(t.begin(), t.end());
  return E;
}

SpMat System::twist_map(const VecX& q) const {
  return twist_map(q, input_blocks(q));
}

SpMat System::internal_null_space(const VecX& q) const {
  Triplets t;
  for (int i = 0; i < node_count(); ++i)
    add_block(t, nodes_[i].q_offset, 6 * i, node_type(i).twist_null_space(node_q(q, i)));
  SpMat Pint(n(), 6 * node_count());
  Pint.setFromTriplets(t.begin(), t.end());
  return Pint;
}

SpMat System::tree_null_space(const VecX& q) const {
  // P_int E (57), column by column of E, without P_int as a sparse matrix and without Eigen's
  // sparse product (per step in the residual scale of the reparametrized formulation). The
  // entries, their order and their sums are the product's: an entry wherever a stored (nonzero)
  // entry of P_int meets one of E, the products summed over E's column in the order of
  // its rows.
  const SpMat E = twist_map(q);
  std::vector<NodeMat> Pint(static_cast<std::size_t>(node_count()));
  for (int i = 0; i < node_count(); ++i) Pint[i] = node_type(i).twist_null_space(node_q(q, i));
  SpMat P(n(), k_);
  P.reserve(2 * E.nonZeros() * kMaxCoordinates / 6);
  std::vector<double> values(static_cast<std::size_t>(n()));
  std::vector<char> seen(static_cast<std::size_t>(n()), 0);
  std::vector<int> rows;
  for (int j = 0; j < E.outerSize(); ++j) {
    rows.clear();
    for (SpMat::InnerIterator it(E, j); it; ++it) {
      const int i = static_cast<int>(it.row()) / 6, t = static_cast<int>(it.row()) % 6;
      const NodeMat& Pi = Pint[i];
      for (int r = 0; r < Pi.rows(); ++r) {
        const double x = Pi(r, t);
        if (x == 0.0) continue;  // not stored in P_int
        const int row = nodes_[i].q_offset + r;
        if (!seen[row]) {
          seen[row] = 1;
          values[row] = x * it.value();
          rows.push_back(row);
        } else {
          values[row] += x * it.value();
        }
      }
    }
    std::sort(rows.begin(), rows.end());
    P.startVec(j);
    for (int row : rows) {
      P.insertBack(row, j) = values[row];
      seen[row] = 0;
    }
  }
  P.finalize();
  return P;
}

VecX System::abs_tree_null_space_transpose_bound(const VecX& q, const VecX& t) const {
  // The sweep of reduce with entrywise absolute blocks: |P_int,i A⋯A B| ≤ |P_int,i| |A|⋯|A| |B|,
  // so every entry bounds |P_tree|ᵀ t from above, in O(nodes) where the exact sums read every
  // (node, ancestor) block, O(nodes × depth) (a chain: O(N²)).
  const int N = node_count();
  VecX y(6 * N), out = VecX::Zero(k_);
  for (int i = 0; i < N; ++i)
    y.segment<6>(6 * i) =
        node_type(i).twist_null_space(node_q(q, i)).cwiseAbs().transpose() * node_q(t, i);
  for (auto it = tree_order_.rbegin(); it != tree_order_.rend(); ++it) {
    const auto& J = joints_[*it];
    const auto qa = node_q(q, J.parent), qb = node_q(q, J.child);
    const Vec<6> yc = y.segment<6>(6 * J.child);
    if (J.parent >= 0)
      y.segment<6>(6 * J.parent) += J.joint->parent_block(qa, qb).cwiseAbs().transpose() * yc;
    if (J.joint->freedom_count() > 0)
      out.segment(J.nu_offset, J.joint->freedom_count()) =
          J.joint->freedom_block(qa, qb).cwiseAbs().transpose() * yc;
  }
  for (std::size_t r = 0; r < roots_.size(); ++r) {
    const int i = roots_[r];
    out.segment(root_nu_offset_[r], root_width_[r]) =
        node_type(i).root_block(node_q(q, i)).cwiseAbs().transpose() * y.segment<6>(6 * i);
  }
  return out;
}

VecX System::update(const VecX& qn, const VecX& u) const {
  VecX q;
  std::vector<Mat3> step;
  update(qn, u, q, step);
  return q;
}

void System::update(const VecX& qn, const VecX& u, VecX& q, std::vector<Mat3>& step,
                    VecX* increment, std::vector<Mat3>* step_increment) const {
  q = qn;
  const auto N = static_cast<std::size_t>(node_count());
  // Rotation of every node over the step (joints/joint.hpp): what the joints below it apply.
  step.assign(N, Mat3::Identity());
  std::vector<Mat3> local;
  std::vector<Mat3>& dQ = step_increment ? *step_increment : local;
  if (increment) {
    increment->setZero(qn.size());
    dQ.assign(N, Mat3::Zero());
  }
  NodeVec dq;
  Mat3 dQ_root;
  for (std::size_t r = 0; r < roots_.size(); ++r) {
    const int i = roots_[r];
    const auto ui = u.segment(root_nu_offset_[r], root_width_[r]);
    const int at = nodes_[i].q_offset, size = coordinate_count(i);
    q.segment(at, size) =
        node_type(i).root_update(node_q(qn, i), ui, step[i], dq, increment ? dQ[i] : dQ_root);
    if (increment) increment->segment(at, size) = dq;
  }
  const Mat3 ground_step = Mat3::Identity();
  joints::StepIncrement parent, child;  // fixed-size: no heap allocation
  for (int j : tree_order_) {
    const auto& J = joints_[j];
    const int c = J.child;
    if (increment) {
      // The ground (a frame node) does not move.
      parent.dq =
          J.parent >= 0
              ? NodeVec(increment->segment(nodes_[J.parent].q_offset, coordinate_count(J.parent)))
              : NodeVec(NodeVec::Zero(fn::kCoords));
      parent.dQ = J.parent >= 0 ? dQ[static_cast<std::size_t>(J.parent)] : Mat3::Zero();
    }
    q.segment(nodes_[c].q_offset, coordinate_count(c)) = J.joint->update(
        node_q(qn, J.parent), node_q(q, J.parent), J.parent >= 0 ? step[J.parent] : ground_step,
        node_q(qn, c), u.segment(J.nu_offset, J.joint->freedom_count()), &step[c],
        increment ? &parent : nullptr, increment ? &child : nullptr);
    if (increment) {
      increment->segment(nodes_[c].q_offset, coordinate_count(c)) = child.dq;
      dQ[static_cast<std::size_t>(c)] = child.dQ;
    }
  }
}

void System::extrapolate_increments(const VecX& q, const VecX& v, double dt, VecX& u) const {
  for (std::size_t r = 0; r < roots_.size(); ++r) {
    const int i = roots_[r];
    auto ui = u.segment(root_nu_offset_[r], root_width_[r]);
    node_type(i).extrapolate(node_q(q, i), node_q(v, i), dt, ui);
  }
}

void System::transport_increments(const VecX& qn, const VecX& q1, VecX& u) const {
  for (std::size_t r = 0; r < roots_.size(); ++r) {
    const int i = roots_[r];
    node_type(i).transport_increments(node_q(qn, i), node_q(q1, i),
                                      u.segment(root_nu_offset_[r], root_width_[r]));
  }
}

SpMat System::update_input_map(const VecX& qn, const VecX& q1, const VecX& u) const {
  const InputBlocks in = update_input_blocks(qn, q1, u);
  Triplets t;
  for (std::size_t r = 0; r < roots_.size(); ++r)
    add_block(t, 6 * roots_[r], root_nu_offset_[r], in.root[r]);
  for (int j : tree_order_)
    if (joints_[j].joint->freedom_count() > 0)
      add_block(t, 6 * joints_[j].child, joints_[j].nu_offset, in.joint[j]);
  SpMat B(6 * node_count(), k_);
  B.setFromTriplets(t.begin(), t.end());
  return B;
}

SpMat System::update_derivative(const VecX& qn, const VecX& q1, const VecX& u) const {
  return internal_null_space(q1) * twist_map(q1, update_input_blocks(qn, q1, u));
}

void System::tree_factors(const VecX& q, SpMat& L, SpMat& B, SpMat& Pint) const {
  const int N = node_count();
  const InputBlocks in = input_blocks(q);
  Triplets tl, tb;
  for (int i = 0; i < N; ++i) add_block(tl, 6 * i, 6 * i, Mat<6, 6>::Identity());
  for (std::size_t r = 0; r < roots_.size(); ++r)
    add_block(tb, 6 * roots_[r], root_nu_offset_[r], in.root[r]);
  for (int j : tree_order_) {
    const auto& J = joints_[j];
    const auto qa = node_q(q, J.parent), qb = node_q(q, J.child);
    if (J.parent >= 0) add_block(tl, 6 * J.child, 6 * J.parent, -J.joint->parent_block(qa, qb));
    if (J.joint->freedom_count() > 0) add_block(tb, 6 * J.child, J.nu_offset, in.joint[j]);
  }
  L.resize(6 * N, 6 * N);
  L.setFromTriplets(tl.begin(), tl.end());
  B.resize(6 * N, k_);
  B.setFromTriplets(tb.begin(), tb.end());
  Pint = internal_null_space(q);
}

VecX System::reduce(const VecX& q, const VecX& r) const {
  VecX out, y;
  reduce(q, r, out, y);
  return out;
}

void System::reduce(const VecX& q, const VecX& r, VecX& out, VecX& y) const {
  const int N = node_count();
  y.resize(6 * N);
  for (int i = 0; i < N; ++i)
    y.segment<6>(6 * i) = node_type(i).twist_force(node_q(q, i), node_q(r, i));
  out.setZero(k_);
  for (auto it = tree_order_.rbegin(); it != tree_order_.rend(); ++it) {
    const auto& J = joints_[*it];
    const auto qa = node_q(q, J.parent), qb = node_q(q, J.child);
    const Vec<6> yc = y.segment<6>(6 * J.child);
    if (J.parent >= 0) y.segment<6>(6 * J.parent) += J.joint->parent_block(qa, qb).transpose() * yc;
    if (J.joint->freedom_count() > 0) {
      const joints::FreedomBlock B = J.joint->freedom_block(qa, qb);
      // Viewed as a MatX: the product kernel (and its roundings) of a dynamic matrix, written
      // straight into out (no temporary).
      out.segment(J.nu_offset, B.cols()).noalias() =
          Eigen::Map<const MatX>(B.data(), 6, B.cols()).transpose() * yc;
    }
  }
  for (std::size_t r = 0; r < roots_.size(); ++r) {
    const int i = roots_[r];
    out.segment(root_nu_offset_[r], root_width_[r]) =
        node_type(i).free_force(node_q(q, i), y.segment<6>(6 * i));
  }
}

Vec3 System::linear_momentum(const VecX& v) const {
  const VecX p = M_ * v;
  Vec3 s = Vec3::Zero();
  for (const Node& nd : nodes_) s += p.segment<3>(nd.q_offset);
  return s;
}

Vec3 System::angular_momentum(const VecX& q, const VecX& v) const {
  const VecX p = M_ * v;
  Vec3 L = Vec3::Zero();
  for (int k = 0; k < n() / 3; ++k) L += q.segment<3>(3 * k).cross(p.segment<3>(3 * k));
  return L;
}

VecX System::beam_element_q(const VecX& q, int b, int e) const {
  return stacked(q, beams_[b].elements[e]->nodes());
}

Vec3 System::material_point(const VecX& q, int node, const Vec3& X) const {
  return node_type(node).material_point(node_q(q, node), X);
}

std::string System::describe_forest(const model::Model&) const {
  std::string out;
  // Free roots; consecutive nodes of one beam are listed as a range.
  for (std::size_t k = 0; k < roots_.size();) {
    const int r = roots_[k];
    std::size_t e = k;
    const auto beam_of = [&](int i) { return node_beam_[i]; };
    while (beam_of(r) >= 0 && e + 1 < roots_.size() && roots_[e + 1] == roots_[e] + 1 &&
           beam_of(roots_[e + 1]) == beam_of(r))
      ++e;
    if (e == k)
      out += fmt::format("  root (free node): {}\n", node_names_[r]);
    else
      out += fmt::format("  root (free nodes): {} … {} ({} nodes)\n", node_names_[r],
                         node_names_[roots_[e]], e - k + 1);
    k = e + 1;
  }
  auto name = [&](int i) { return i < 0 ? std::string("ground") : node_names_[i]; };
  for (int j : tree_order_) {
    const auto& J = joints_[j];
    out +=
        fmt::format("  tree  {:<16} {:<13} {} -> {}  (r = {}){}\n", J.name, J.type, name(J.parent),
                    name(J.child), J.joint->freedom_count(), J.reversed ? "  [reversed]" : "");
  }
  for (const auto& J : joints_)
    if (!J.tree)
      out += fmt::format("  cut   {:<16} {:<13} {} -- {}  (m = {}, loop-closing)\n", J.name, J.type,
                         name(J.parent), name(J.child), J.joint->constraint_count());
  return out;
}

}  // namespace isoflex::system
