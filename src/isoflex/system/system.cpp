#include "isoflex/system/system.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <deque>
#include <map>

#include "isoflex/elements/beam_element.hpp"
#include "isoflex/elements/beam_mesh.hpp"
#include "isoflex/elements/rigid_body.hpp"
#include "isoflex/joints/director_joints.hpp"
#include "isoflex/joints/point_joints.hpp"
#include "isoflex/math/director_node.hpp"
#include "isoflex/math/rotation.hpp"
#include "isoflex/math/skew.hpp"
#include "isoflex/solve/linear_solver.hpp"
#include "isoflex/system/kl_model.hpp"

namespace isoflex::system {

namespace fn = frame_node;
namespace dn = director_node;
using joints::NodeKind;

namespace {

[[noreturn]] void fail(const model::Source& s, const std::string& what, const std::string& msg) {
  compile_fail(s, what, msg);
}

joints::Kind kind_of(model::JointType t) {
  using T = model::JointType;
  using K = joints::Kind;
  switch (t) {
    case T::spherical:
      return K::spherical;
    case T::revolute:
      return K::revolute;
    case T::prismatic:
      return K::prismatic;
    case T::cylindrical:
      return K::cylindrical;
    case T::planar:
      return K::planar;
    case T::universal:
      return K::universal;
    case T::rigid:
    case T::fixed:
      return K::rigid;
    case T::point_on_line:
      return K::point_on_line;
  }
  return K::rigid;
}

// A right-handed frame with third column e₃.
Mat3 frame_about(const Vec3& e3) {
  const Vec3 n = e3.normalized();
  const Vec3 a = std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  const Vec3 e1 = (a - a.dot(n) * n).normalized();
  Mat3 E;
  E << e1, n.cross(e1), n;
  return E;
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

int System::joint_of_row(int row) const {
  for (int j = 0; j < static_cast<int>(joints_.size()); ++j) {
    const auto& J = joints_[j];
    if (row >= J.row_offset && row < J.row_offset + J.joint->constraint_count()) return j;
  }
  return -1;
}

System System::compile(const model::Model& model) {
  System s;
  s.ground_ = fn::make(Vec3::Zero(), Mat3::Identity());
  // Nodes: the bodies in model order, then the nodes of each beam along its polyline.
  const int n_bodies = static_cast<int>(model.bodies.size());
  std::map<std::string, int> index;
  for (int i = 0; i < n_bodies; ++i) {
    const auto& b = model.bodies[i];
    index[b.name] = i;
    s.add_node(NodeKind::frame, fn::make(b.position, b.orientation), b.name, -1);
    s.elements_.push_back(
        std::make_unique<elements::RigidBody>(i, b.mass, b.inertia, model.gravity));
  }
  int next = n_bodies;
  for (std::size_t bi = 0; bi < model.beams.size(); ++bi) {
    const auto& B = model.beams[bi];
    const std::string what = fmt::format("beams[{}]", bi);
    BeamInstance inst{B.name, {}, {}};
    std::vector<fn::Q> q;
    try {
      for (std::size_t seg = 0; seg + 1 < B.points.size(); ++seg) {
        const auto part =
            elements::straight_beam_nodes(B.points[seg], B.points[seg + 1], B.d1, B.elements[seg]);
        // A vertex shared by two segments keeps the triad of the segment before it; the
        // reference strains of the next element absorb the kink.
        q.insert(q.end(), part.begin() + (seg == 0 ? 0 : 1), part.end());
      }
    } catch (const std::exception& e) {
      fail(B.source, what, e.what());
    }
    for (std::size_t k = 0; k < q.size(); ++k) {
      const std::string name = fmt::format("{}[{}]", B.name, k);
      index[name] = next + static_cast<int>(k);
      s.add_node(NodeKind::frame, q[k], name, static_cast<int>(bi));
      inst.nodes.push_back(next + static_cast<int>(k));
    }
    const model::BeamSection& c = B.section;
    const elements::BeamSection section{c.EA, c.GA1,   c.GA2,    c.EI1,   c.EI2,
                                        c.GJ, c.A_rho, c.M_rho1, c.M_rho2};
    for (std::size_t k = 0; k + 1 < q.size(); ++k) {
      const int a = next + static_cast<int>(k);
      try {
        s.elements_.push_back(std::make_unique<elements::BeamElement>(a, a + 1, q[k], q[k + 1],
                                                                      section, model.gravity));
      } catch (const std::exception& e) {
        fail(B.source, fmt::format("{}.section", what), e.what());
      }
      inst.elements.push_back(static_cast<const elements::BeamElement*>(s.elements_.back().get()));
    }
    next += static_cast<int>(q.size());
    s.beams_.push_back(std::move(inst));
  }
  // Shells: director nodes (40) "<shell>[i]" and bilinear director-shell elements.
  for (std::size_t si = 0; si < model.shells.size(); ++si) {
    const auto& S = model.shells[si];
    const std::string what = fmt::format("shells[{}]", si);
    ShellInstance inst{S.name, {}, {}};
    for (int k = 0; k < S.node_count(); ++k) {
      const std::string name = fmt::format("{}[{}]", S.name, k);
      index[name] = next + k;
      dn::Q q;
      q << S.points[k], S.directors[k];
      s.add_node(NodeKind::director, q, name, static_cast<int>(model.beams.size() + si));
      inst.nodes.push_back(next + k);
    }
    const elements::ShellMaterial mat{S.material.E, S.material.nu, S.material.thickness,
                                      S.material.density, S.material.shear_correction};
    for (std::size_t e = 0; e < S.quads.size(); ++e) {
      std::array<int, 4> nodes;
      Vec<24> q0;
      for (int a = 0; a < 4; ++a) {
        nodes[a] = next + S.quads[e][a];
        q0.segment<6>(6 * a) << S.points[S.quads[e][a]], S.directors[S.quads[e][a]];
      }
      try {
        s.elements_.push_back(
            std::make_unique<elements::DirectorShellElement>(nodes, q0, mat, model.gravity));
      } catch (const std::exception& ex) {
        fail(S.source, fmt::format("{} element {}", what, e), ex.what());
      }
      inst.elements.push_back(
          static_cast<const elements::DirectorShellElement*>(s.elements_.back().get()));
    }
    next += S.node_count();
    s.shells_.push_back(std::move(inst));
  }
  s.add_kl_patches(model);
  for (const KLPatchInstance& k : s.kl_patches_)
    for (int node : k.nodes) index[s.node_names_[node]] = node;
  s.q0_ = Eigen::Map<const VecX>(s.q0_build_.data(), static_cast<Eigen::Index>(s.q0_build_.size()));
  s.q0_build_ = {};
  auto find_body = [&](const std::string& name, const model::Source& src, const std::string& what) {
    if (name == "ground") return -1;
    auto it = index.find(name);
    if (it == index.end()) fail(src, what, fmt::format("no body named '{}'", name));
    return it->second;
  };

  const int N = s.node_count();
  // Mass matrix.
  {
    Triplets t;
    for (const auto& e : s.elements_) {
      const std::vector<int> c = s.coordinates_of(e->nodes());
      const SpMat Me = e->sparse_mass();
      for (int j = 0; j < Me.outerSize(); ++j)
        for (SpMat::InnerIterator it(Me, j); it; ++it)
          t.emplace_back(c[it.row()], c[it.col()], it.value());
    }
    s.M_.resize(s.n(), s.n());
    s.M_.setFromTriplets(t.begin(), t.end());
  }

  // Loads.
  for (std::size_t l = 0; l < model.loads.size(); ++l) {
    const auto& L = model.loads[l];
    const std::string what = fmt::format("loads[{}]", l);
    const int node = find_body(L.body, L.source, what + ".body");
    if (node < 0) fail(L.source, what + ".body", "a load cannot act on the ground");
    if (s.node_kind(node) != NodeKind::frame)
      fail(L.source, what + ".body",
           fmt::format("'{}' is a shell node: load shells with shell_loads", L.body));
    const Vec3 X = s.body_coordinates(node, L.point, L.point_local);
    auto compile3 = [&](const std::optional<std::array<std::string, 3>>& e, const char* key) {
      std::optional<std::array<loads::TimeFunction, 3>> f;
      if (!e) return f;
      try {
        f = std::array<loads::TimeFunction, 3>{loads::TimeFunction((*e)[0]),
                                               loads::TimeFunction((*e)[1]),
                                               loads::TimeFunction((*e)[2])};
      } catch (const std::exception& ex) {
        fail(L.source, what + "." + key, ex.what());
      }
      return f;
    };
    s.loads_.emplace_back(node, X, compile3(L.force, "force"), compile3(L.moment, "moment"));
  }

  // Distributed dead loads per length: consistent nodal forces of the linear shape functions,
  // ∫ N_a f ds = f L/2 per element end (f constant along the element).
  for (std::size_t l = 0; l < model.distributed_loads.size(); ++l) {
    const auto& D = model.distributed_loads[l];
    const std::string what = fmt::format("distributed_loads[{}]", l);
    const auto beam = std::find_if(s.beams_.begin(), s.beams_.end(),
                                   [&](const BeamInstance& b) { return b.name == D.beam; });
    if (beam == s.beams_.end()) fail(D.source, what + ".beam", "no beam named '" + D.beam + "'");
    std::vector<double> w(beam->nodes.size(), 0.0);
    for (std::size_t e = 0; e < beam->elements.size(); ++e) {
      w[e] += 0.5 * beam->elements[e]->reference_length();
      w[e + 1] += 0.5 * beam->elements[e]->reference_length();
    }
    for (std::size_t k = 0; k < w.size(); ++k) {
      std::array<loads::TimeFunction, 3> f;
      try {
        for (int c = 0; c < 3; ++c)
          f[c] = loads::TimeFunction(fmt::format("({})*{:.17g}", D.force_per_length[c], w[k]));
      } catch (const std::exception& ex) {
        fail(D.source, what + ".force_per_length", ex.what());
      }
      s.loads_.emplace_back(beam->nodes[k], Vec3::Zero(), f, std::nullopt);
    }
  }

  // Shell loads: nodal forces and moments, edge loads lumped by the linear shape functions
  // (½ of each edge segment to its end nodes), area loads by the consistent nodal weights
  // ∫ N_a dA and ∫ N_a N dA of the elements (all dead loads).
  for (std::size_t l = 0; l < model.shell_loads.size(); ++l) {
    const auto& L = model.shell_loads[l];
    const std::string what = fmt::format("shell_loads[{}]", l);
    const auto shell = std::find_if(s.shells_.begin(), s.shells_.end(),
                                    [&](const ShellInstance& x) { return x.name == L.shell; });
    if (shell == s.shells_.end()) fail(L.source, what + ".shell", "no shell named " + L.shell);
    // Nodal vectors per shell node: weight × expression.
    std::vector<Vec3> area(shell->nodes.size(), Vec3::Zero());
    std::vector<double> weight(shell->nodes.size(), 0.0);
    auto scaled = [&](const std::array<std::string, 3>& e, const Vec3& w) {
      std::array<loads::TimeFunction, 3> f;
      try {
        for (int c = 0; c < 3; ++c)
          f[c] = loads::TimeFunction(fmt::format("({})*{:.17g}", e[c], w(c)));
      } catch (const std::exception& ex) {
        fail(L.source, what, ex.what());
      }
      return f;
    };
    const int first = shell->nodes.front();
    if (L.pressure || L.area_force) {
      for (const auto* e : shell->elements) {
        const Vec<4> a = e->nodal_areas();
        const Mat<3, 4> na = e->nodal_normal_areas();
        for (int k = 0; k < 4; ++k) {
          weight[e->nodes()[k] - first] += a(k);
          area[e->nodes()[k] - first] += na.col(k);
        }
      }
      for (std::size_t k = 0; k < shell->nodes.size(); ++k) {
        if (weight[k] == 0.0) continue;
        std::optional<std::array<loads::TimeFunction, 3>> f;
        if (L.pressure) {
          f = scaled({*L.pressure, *L.pressure, *L.pressure}, area[k]);
        } else {
          f = scaled(*L.area_force, Vec3::Constant(weight[k]));
        }
        s.director_loads_.emplace_back(shell->nodes[k], f, std::nullopt);
      }
      continue;
    }
    std::vector<double> w(L.nodes.size(), 1.0);
    if (L.per_length) {
      std::fill(w.begin(), w.end(), 0.0);
      for (std::size_t k = 0; k + 1 < L.nodes.size(); ++k) {
        const double len = (s.q0_.segment<3>(s.q_offset(first + L.nodes[k + 1])) -
                            s.q0_.segment<3>(s.q_offset(first + L.nodes[k])))
                               .norm();
        w[k] += 0.5 * len;
        w[k + 1] += 0.5 * len;
      }
    }
    for (std::size_t k = 0; k < L.nodes.size(); ++k) {
      std::optional<std::array<loads::TimeFunction, 3>> f, m;
      if (L.force) f = scaled(*L.force, Vec3::Constant(w[k]));
      if (L.moment) m = scaled(*L.moment, Vec3::Constant(w[k]));
      s.director_loads_.emplace_back(first + L.nodes[k], f, m);
    }
  }

  // Probes.
  for (std::size_t p = 0; p < model.probes.size(); ++p) {
    const auto& P = model.probes[p];
    if (!P.kl_shell.empty()) {
      s.probes_.push_back(s.kl_probe(P));
      continue;
    }
    const int node = find_body(P.body, P.source, fmt::format("probes[{}].body", p));
    if (node < 0) fail(P.source, fmt::format("probes[{}].body", p), "a probe needs a body");
    // A shell node's probe follows the node's mid-surface point (NodeType::local_coordinates).
    s.probes_.push_back({P.name, node, s.body_coordinates(node, P.point, P.point_local), {}});
  }

  // Joint graph and spanning forest rooted at the ground (breadth first, so chains hang from the
  // ground by their shortest paths). A joint reached from its body_b side is built with the roles
  // swapped; its constraint set is equivalent (frames coincide at t = 0). A point-on-line joint
  // is not symmetric (the line belongs to body_a), so it is never used reversed in the tree.
  struct Edge {
    int a, b;
  };
  std::vector<Edge> edges;
  for (std::size_t j = 0; j < model.joints.size(); ++j) {
    const auto& J = model.joints[j];
    const std::string what = fmt::format("joints[{}]", j);
    const int a = find_body(J.body_a, J.source, what + ".body_a");
    const int b = find_body(J.body_b, J.source, what + ".body_b");
    if (b < 0) fail(J.source, what + ".body_b", "body_b cannot be the ground");
    if (a == b) fail(J.source, what, "a joint needs two different bodies");
    if (J.type == model::JointType::fixed && a >= 0)
      fail(J.source, what + ".body_a", "a fixed support joins a body to the ground");
    edges.push_back({a, b});
  }
  // Shell supports: one joint from the ground per supported node (joints/director_joints.hpp).
  // Entries naming the same node are merged (a corner on two symmetry planes): fixed components
  // add up; two different symmetry normals leave the director no freedom but drilling.
  struct Support {
    std::string name;
    std::shared_ptr<const joints::Joint> joint;
    model::Source source;
    std::string type = "shell_support";
  };
  std::vector<Support> supports;
  {
    using C = joints::DirectorCondition;
    struct Pending {
      int node;
      joints::DirectorSupportSpec spec;
      std::string what;
      model::Source source;
    };
    std::vector<Pending> pending;
    std::map<int, std::size_t> at;
    for (std::size_t k = 0; k < model.shell_supports.size(); ++k) {
      const auto& S = model.shell_supports[k];
      const auto shell = std::find_if(s.shells_.begin(), s.shells_.end(),
                                      [&](const ShellInstance& x) { return x.name == S.shell; });
      const std::string what = fmt::format("shell_supports[{}]", k);
      if (shell == s.shells_.end()) fail(S.source, what + ".shell", "no shell named " + S.shell);
      joints::DirectorSupportSpec spec;
      spec.fix_translation = S.fixed_translation;
      spec.director = S.director == model::DirectorSupport::free    ? C::free
                      : S.director == model::DirectorSupport::fixed ? C::fixed
                                                                    : C::about_axis;
      spec.axis = S.axis;
      for (int i : S.nodes) {
        const int node = shell->nodes[i];
        const auto [it, fresh] = at.emplace(node, pending.size());
        if (fresh) {
          pending.push_back({node, spec, what, S.source});
          continue;
        }
        joints::DirectorSupportSpec& m = pending[it->second].spec;
        for (int c = 0; c < 3; ++c)
          m.fix_translation[c] = m.fix_translation[c] || spec.fix_translation[c];
        if (spec.director == C::fixed || m.director == C::fixed) {
          m.director = C::fixed;
        } else if (spec.director == C::about_axis) {
          if (m.director == C::free)
            m = {m.fix_translation, C::about_axis, spec.axis};
          else if (std::abs(std::abs(m.axis.normalized().dot(spec.axis.normalized())) - 1) > 1e-12)
            m.director = C::fixed;
        }
      }
    }
    for (const Pending& p : pending) {
      try {
        supports.push_back({fmt::format("{}:{}", p.what, s.node_names_[p.node]),
                            std::make_shared<joints::DirectorSupport>(
                                dn::Q(s.q0_.segment<6>(s.q_offset(p.node))), p.spec),
                            p.source});
      } catch (const std::exception& e) {
        fail(p.source, p.what, fmt::format("node {}: {}", s.node_names_[p.node], e.what()));
      }
      edges.push_back({-1, p.node});
    }
  }
  // Kirchhoff–Love supports: the control points of the supported rows (fixed: the edge or the
  // listed points; clamped: rows 0 and 1, which carry the slope across the edge) rigidly attached
  // to a body or the ground (joints/point_joints.hpp). Attaching row 1 also holds the stretch
  // across a clamped edge, unlike the static clamp (docs/theory/kl-static.md §2).
  for (std::size_t k = 0; k < model.kl_supports.size(); ++k) {
    const auto& S = model.kl_supports[k];
    const std::string what = fmt::format("kl_supports[{}]", k);
    using K = model::KLSupportKind;
    if (!(S.components[0] && S.components[1] && S.components[2]) ||
        (S.kind != K::fixed && S.kind != K::clamped))
      fail(S.source, what,
           "in a dynamic run a Kirchhoff–Love support holds all components, fixed or clamped, to "
           "the ground or a body; symmetry, prescribed displacements and single components act "
           "in static analyses only for now (solver.analysis: static)");
    const KLPatchInstance& P = s.kl_patches_.front();  // the reader checked the shell's name
    const geometry::NurbsSurface& g = P.element->patch().reference();
    std::vector<int> cps = S.control_points;
    if (!S.edge.empty())
      for (int r = 0; r < (S.kind == K::clamped ? 2 : 1); ++r)
        for (int cp : loads::edge_control_points(g, loads::patch_edge_from_string(S.edge), r))
          cps.push_back(cp);
    const int parent = S.body.empty() ? -1 : find_body(S.body, S.source, what + ".body");
    for (int cp : cps) {
      const int node = P.nodes[cp];
      supports.push_back(
          {fmt::format("{}:{}", what, s.node_names_[node]),
           std::make_shared<joints::PointOnFrame>(fn::Q(s.node_q(s.q0_, parent)),
                                                  Vec3(s.q0_.segment<3>(s.q_offset(node)))),
           S.source, "kl_support"});
      edges.push_back({parent, node});
    }
  }
  const std::size_t n_model_joints = model.joints.size();
  std::vector<int> tree_parent_side(edges.size(), 0);  // 0 not in tree, +1 a→b, −1 b→a
  std::vector<bool> reached(N, false);
  std::vector<int> order;  // tree joints in BFS order
  auto grow = [&](std::deque<int> frontier) {
    while (!frontier.empty()) {
      const int u = frontier.front();
      frontier.pop_front();
      for (std::size_t j = 0; j < edges.size(); ++j) {
        if (tree_parent_side[j] != 0) continue;
        const auto [a, b] = edges[j];
        if (a == u && !reached[b]) {
          tree_parent_side[j] = 1;
          reached[b] = true;
          order.push_back(static_cast<int>(j));
          frontier.push_back(b);
        } else if (b == u && a >= 0 && !reached[a] && j < n_model_joints &&
                   model.joints[j].type != model::JointType::point_on_line) {
          tree_parent_side[j] = -1;
          reached[a] = true;
          order.push_back(static_cast<int>(j));
          frontier.push_back(a);
        }
      }
    }
  };
  grow({-1});
  for (int i = 0; i < N; ++i) {
    if (reached[i]) continue;
    reached[i] = true;
    s.roots_.push_back(i);
    grow({i});
  }

  // Joint instances, rows and ν layout.
  int row = s.internal_rows_;
  for (std::size_t j = 0; j < n_model_joints; ++j) {
    const auto& J = model.joints[j];
    const std::string what = fmt::format("joints[{}]", j);
    const bool rev = tree_parent_side[j] == -1;
    const int parent = rev ? edges[j].b : edges[j].a;
    const int child = rev ? edges[j].a : edges[j].b;
    const std::string name = J.name.empty() ? what : J.name;
    const bool tree = tree_parent_side[j] != 0;
    if (parent >= 0 && s.node_kind(parent) == NodeKind::point)
      fail(J.source, what,
           fmt::format("'{}' would carry '{}': a point node (a control point) can only hang from "
                       "a body, a beam node or the ground",
                       s.node_names_[parent], s.node_names_[child]));
    if (s.node_kind(child) == NodeKind::point) {
      using T = model::JointType;
      if (J.type != T::rigid && J.type != T::fixed && J.type != T::spherical)
        fail(J.source, what + ".type",
             fmt::format("'{}' is a control point: it is attached (rigid, fixed or spherical, "
                         "which coincide for a point), not {}",
                         s.node_names_[child], model::to_string(J.type)));
      if (parent >= 0 && s.node_kind(parent) != NodeKind::frame)
        fail(J.source, what, "a control point is attached to a body, a beam node or the ground");
      auto joint = std::make_shared<joints::PointOnFrame>(
          fn::Q(s.node_q(s.q0_, parent)), Vec3(s.q0_.segment<3>(s.q_offset(child))));
      s.joints_.push_back({name, model::to_string(J.type), std::move(joint), nullptr, parent, child,
                           tree, rev, row, -1});
      row += 3;
      continue;
    }
    if ((parent >= 0 && s.node_kind(parent) == NodeKind::director) ||
        s.node_kind(child) == NodeKind::director) {
      auto joint = s.director_joint(J, parent, child, what);
      const int m = joint->constraint_count();
      s.joints_.push_back({name, model::to_string(J.type), std::move(joint), nullptr, parent, child,
                           tree, rev, row, -1});
      row += m;
      continue;
    }
    const fn::Q qa0 = s.node_q(s.q0_, parent), qb0 = s.node_q(s.q0_, child);
    // Body a and b of the model entry (not parent/child) at t = 0; the ground frame for ground.
    const fn::Q qA = s.node_q(s.q0_, edges[j].a), qB = s.node_q(s.q0_, edges[j].b);
    const Mat3 RA = fn::directors(qA), RB = fn::directors(qB);
    Vec3 p = fn::phi(qB);
    if (J.point)
      p = *J.point;
    else if (J.point_a)
      p = fn::phi(qA) + RA * *J.point_a;
    else if (J.point_b)
      p = fn::phi(qB) + RB * *J.point_b;
    const std::optional<Vec3> axis = J.axis_a ? std::optional<Vec3>(RA * *J.axis_a) : J.axis;
    const std::optional<Vec3> axis2 = J.axis2_b ? std::optional<Vec3>(RB * *J.axis2_b) : J.axis2;
    Mat3 E = Mat3::Identity();
    using T = model::JointType;
    switch (J.type) {
      case T::revolute:
      case T::prismatic:
      case T::cylindrical:
      case T::planar:
      case T::point_on_line:
        if (!axis || !(axis->norm() > 0))
          fail(J.source, what + ".axis", "a nonzero axis is required");
        E = frame_about(*axis);
        break;
      case T::universal: {
        if (!axis || !axis2) fail(J.source, what, "a universal joint needs axis and axis2");
        Vec3 e1 = axis->normalized(), e2 = axis2->normalized();
        if (std::abs(e1.dot(e2)) > 1e-9)
          fail(J.source, what + ".axis2",
               fmt::format("axis2 must be perpendicular to axis at t = 0 (cosine {:.3g})",
                           e1.dot(e2)));
        if (rev) std::swap(e1, e2);  // the parent's own axis is the first frame axis
        E << e1, e2, e1.cross(e2);
        break;
      }
      default:
        break;
    }
    auto joint = std::make_shared<const joints::FrameJoint>(
        kind_of(J.type), joints::geometry_from_global(qa0, qb0, p, E));
    const joints::FrameJoint* frame = joint.get();
    s.joints_.push_back({name, model::to_string(J.type), std::move(joint), frame, parent, child,
                         tree, rev, row, -1});
    row += frame->constraint_count();
  }
  // Shell supports after the model joints: joints_ is indexed like edges.
  for (std::size_t j = n_model_joints; j < edges.size(); ++j) {
    const Support& S = supports[j - n_model_joints];
    s.joints_.push_back({S.name, S.type, S.joint, nullptr, edges[j].a, edges[j].b,
                         tree_parent_side[j] != 0, false, row, -1});
    row += S.joint->constraint_count();
  }
  s.m_all_ = row;
  int nu = 0;
  for (int root : s.roots_) {
    s.root_nu_offset_.push_back(nu);
    s.root_width_.push_back(s.node_type(root).free_velocities());
    nu += s.root_width_.back();
  }
  for (int j : order) {
    s.joints_[j].nu_offset = nu;
    nu += s.joints_[j].joint->freedom_count();
  }
  s.tree_order_ = order;
  s.k_ = nu;

  // Check that every joint holds at t = 0 (the frames are built to coincide; the points of
  // sliding joints and the parent side of a joint given by point_b must lie where stated).
  {
    const VecX c = s.constraints(s.q0_);
    for (const auto& J : s.joints_) {
      const double v = c.segment(J.row_offset, J.joint->constraint_count()).cwiseAbs().maxCoeff();
      if (v <= 1e-9) continue;
      const std::size_t j = static_cast<std::size_t>(&J - s.joints_.data());
      const bool support = j >= n_model_joints;
      fail(support ? supports[j - n_model_joints].source : model.joints[j].source,
           support ? supports[j - n_model_joints].name : fmt::format("joints[{}]", j),
           fmt::format("not assembled at t = 0 (|Φ| = {:.3g})", v));
    }
  }

  // Loop-closing rows: independent ones by full-pivot LU of G_cut P_tree (IGA-thesis Alg. 5.1,
  // Rem. 5.5); the rest are redundant and dropped. Cross-checked by pivoted QR.
  std::vector<int> cut_all;
  for (const auto& J : s.joints_)
    if (!J.tree)
      for (int i = 0; i < J.joint->constraint_count(); ++i) cut_all.push_back(J.row_offset + i);
  for (int i = 0; i < s.internal_rows_; ++i) s.selected_rows_.push_back(i);
  for (const auto& J : s.joints_)
    if (J.tree)
      for (int i = 0; i < J.joint->constraint_count(); ++i)
        s.selected_rows_.push_back(J.row_offset + i);
  if (!cut_all.empty()) {
    const MatX Gc = MatX(s.jacobian_rows(s.q0_, cut_all) * s.tree_null_space(s.q0_));
    const auto keep = solve::independent_rows_lu(Gc);
    s.cut_rank_qr_ = static_cast<int>(solve::independent_rows_qr(Gc).size());
    std::vector<bool> kept(cut_all.size(), false);
    for (int i : keep) kept[i] = true;
    for (std::size_t i = 0; i < cut_all.size(); ++i) {
      if (kept[i]) {
        s.cut_rows_.push_back(cut_all[i]);
        s.selected_rows_.push_back(cut_all[i]);
      } else {
        s.redundant_rows_.push_back(cut_all[i]);
      }
    }
  }

  // Initial velocities: the admissible twist closest (least squares in twist components) to the
  // given body velocities, within the null space of the loop-closing rows.
  VecX t_given = VecX::Zero(6 * N);  // beam and shell nodes start at rest
  for (int i = 0; i < n_bodies; ++i) {
    t_given.segment<3>(6 * i) = model.bodies[i].velocity;
    t_given.segment<3>(6 * i + 3) = model.bodies[i].angular_velocity;
  }
  VecX nu0 = VecX::Zero(s.k_);
  if (t_given.norm() > 0) {
    if (s.cut_rows_.empty()) {
      // min ½‖w − t‖² subject to (I − 𝒜) w = ℬ ν, as the sparse KKT system
      // [I (I−𝒜)ᵀ 0; (I−𝒜) 0 −ℬ; 0 −ℬᵀ 0] [w; μ; ν] = [t; 0; 0] (linear in N).
      SpMat L, B, Pint;
      s.tree_factors(s.q0_, L, B, Pint);
      const int N6 = 6 * N;
      Triplets t;
      for (int i = 0; i < N6; ++i) t.emplace_back(i, i, 1.0);
      auto put = [&](const SpMat& A, int r0, int c0, double f) {
        for (int c = 0; c < A.outerSize(); ++c)
          for (SpMat::InnerIterator it(A, c); it; ++it)
            t.emplace_back(r0 + it.row(), c0 + it.col(), f * it.value());
      };
      put(SpMat(L.transpose()), 0, N6, 1.0);
      put(L, N6, 0, 1.0);
      put(B, N6, 2 * N6, -1.0);
      put(SpMat(B.transpose()), 2 * N6, N6, -1.0);
      SpMat K(2 * N6 + s.k_, 2 * N6 + s.k_);
      K.setFromTriplets(t.begin(), t.end());
      VecX rhs = VecX::Zero(K.rows());
      rhs.head(N6) = t_given;
      const VecX z = solve::solve(K, rhs);
      nu0 = z.tail(s.k_);
      s.v0_error_ = (z.head(N6) - t_given).norm() / std::max(1.0, t_given.norm());
    } else {
      const MatX E = MatX(s.twist_map(s.q0_));
      MatX W, U;
      solve::qr_range_and_null_space(
          MatX(s.jacobian_rows(s.q0_, s.cut_rows_) * s.tree_null_space(s.q0_)), W, U);
      nu0 = U * solve::least_squares(E * U, t_given);
      s.v0_error_ = (E * nu0 - t_given).norm() / std::max(1.0, t_given.norm());
    }
  }
  {
    SpMat L, B, Pint;
    s.tree_factors(s.q0_, L, B, Pint);
    s.v0_ = Pint * solve::solve(L, B * nu0);
  }
  s.build_stiffness_pattern();
  return s;
}

// Kirchhoff–Love patches (docs/model-files.md "kl_shells"): a point node "<shell>[A]" per control
// point A, the patch as one element over them, its kl_loads. Supports and multipatch coupling
// are not yet constraints of the system: a dynamic model with kl_supports is refused.
void System::add_kl_patches(const model::Model& m) {
  if (m.kl_shells.empty()) return;
  if (m.kl_shells.size() > 1)
    fail(m.kl_shells[1].source, "kl_shells[1]",
         "one Kirchhoff–Love patch per model for now (multipatch coupling is not built yet)");
  const model::KLShell& S = m.kl_shells.front();
  KLPatchInstance inst;
  inst.name = S.name;
  auto patch = kl_patch(m, 0);
  const int group = static_cast<int>(m.beams.size() + m.shells.size());
  const geometry::NurbsSurface& g = patch->reference();
  for (int A = 0; A < patch->control_points(); ++A) {
    inst.nodes.push_back(node_count());
    add_node(NodeKind::point, g.points[A], fmt::format("{}[{}]", S.name, A), group);
  }
  auto element = std::make_unique<elements::KLPatchElement>(patch, kl_kinematics(m), inst.nodes);
  inst.element = element.get();
  inst.element_index = static_cast<int>(elements_.size());
  elements_.push_back(std::move(element));
  inst.loads = kl_patch_loads(m, S);
  kl_patches_.push_back(std::move(inst));
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

std::vector<int> System::coordinates_of(const std::vector<int>& nodes) const {
  std::vector<int> c;
  for (int a : nodes)
    for (int k = 0; k < coordinate_count(a); ++k) c.push_back(nodes_[a].q_offset + k);
  return c;
}

void System::build_stiffness_pattern() {
  for (const auto& e : elements_)
    element_part_.push_back(stiffness_.add(e->pattern(), coordinates_of(e->nodes())));
  // A load's derivative is non-zero only through a moment (follower part M × d).
  for (const auto& L : loads_)
    load_part_.push_back(L.has_moment() ? stiffness_.add_dense(coordinates_of({L.node()})) : -1);
  for (const auto& L : director_loads_)
    director_load_part_.push_back(L.has_moment() ? stiffness_.add_dense(coordinates_of({L.node()}))
                                                 : -1);
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
  VecX f = VecX::Zero(n());
  if (K) stiffness_.reset(*K);
  std::vector<double> values;
  for (std::size_t i = 0; i < elements_.size(); ++i) {
    const auto& e = elements_[i];
    const auto& nodes = e->nodes();
    if (K) values.resize(stiffness_.local_entries(element_part_[i]));
    const VecX dv = e->discrete_gradient_in_pattern(stacked(qn, nodes), stacked(qn1, nodes),
                                                    K ? values.data() : nullptr);
    int o = 0;
    for (int a : nodes) {
      const int c = coordinate_count(a);
      f.segment(nodes_[a].q_offset, c) += dv.segment(o, c);
      o += c;
    }
    if (K) stiffness_.scatter(element_part_[i], values.data(), *K);
  }
  for (std::size_t l = 0; l < loads_.size(); ++l) {
    const auto& L = loads_[l];
    const int o = nodes_[L.node()].q_offset;
    const fn::Q qm = 0.5 * (qn.segment<12>(o) + qn1.segment<12>(o));
    f.segment<12>(o) -= L.generalized_force(qm, t_mid);
    if (K && load_part_[l] >= 0) {
      const Mat<12, 12> D = -0.5 * L.generalized_force_derivative(t_mid);
      stiffness_.scatter(load_part_[l], D.data(), *K);
    }
  }
  for (std::size_t l = 0; l < director_loads_.size(); ++l) {
    const auto& L = director_loads_[l];
    const int o = nodes_[L.node()].q_offset;
    const dn::Q qm = 0.5 * (qn.segment<6>(o) + qn1.segment<6>(o));
    f.segment<6>(o) -= L.generalized_force(qm, t_mid);
    if (K && director_load_part_[l] >= 0) {
      const Mat<6, 6> D = -0.5 * L.generalized_force_derivative(t_mid);
      stiffness_.scatter(director_load_part_[l], D.data(), *K);
    }
  }
  // Patch loads at the midpoint, λ(t_{n+½}) f(x_{n+½}); a follower load's tangent is −½ λ ∂f/∂x.
  for (std::size_t p = 0; p < kl_patches_.size(); ++p) {
    const KLPatchInstance& P = kl_patches_[p];
    if (P.loads.empty()) continue;
    const VecX xm = 0.5 * (stacked(qn, P.nodes) + stacked(qn1, P.nodes));
    VecX fe = VecX::Zero(xm.size());
    SpMat Kl;
    for (const auto& L : P.loads) {
      const double lambda = L->factor(t_mid);
      if (lambda == 0.0) continue;
      fe += lambda * L->force(xm);
      if (!K || !L->follower()) continue;
      if (Kl.size() == 0) Kl = P.element->pattern();
      L->add_tangent(xm, -0.5 * lambda, Kl);
    }
    for (std::size_t k = 0; k < P.nodes.size(); ++k)
      f.segment<3>(nodes_[P.nodes[k]].q_offset) -= fe.segment<3>(3 * k);
    if (Kl.size() != 0) stiffness_.scatter(element_part_[P.element_index], Kl.valuePtr(), *K);
  }
  return f;
}

VecX System::constraints(const VecX& q) const {
  VecX c(m_all_);
  for (int i = 0; i < node_count(); ++i) {
    const Node& nd = nodes_[i];
    c.segment(nd.row_offset, nd.type->internal_rows()) = nd.type->constraints(node_q(q, i));
  }
  for (const auto& J : joints_)
    c.segment(J.row_offset, J.joint->constraint_count()) =
        J.joint->constraints(node_q(q, J.parent), node_q(q, J.child));
  return c;
}

SpMat System::jacobian_rows(const VecX& q, const std::vector<int>& rows) const {
  // Assemble all rows, then pick.
  Triplets t;
  for (int i = 0; i < node_count(); ++i)
    add_block(t, nodes_[i].row_offset, nodes_[i].q_offset, node_type(i).jacobian(node_q(q, i)));
  for (const auto& J : joints_) {
    const MatX G = J.joint->jacobian(node_q(q, J.parent), node_q(q, J.child));
    const int m = J.joint->constraint_count();
    const int na = joints::coordinate_count(J.joint->parent_kind());
    if (J.parent >= 0) add_block(t, J.row_offset, nodes_[J.parent].q_offset, G.leftCols(na));
    add_block(t, J.row_offset, nodes_[J.child].q_offset,
              G.block(0, na, m, coordinate_count(J.child)));
  }
  SpMat all(m_all_, n());
  all.setFromTriplets(t.begin(), t.end());
  Triplets s;
  for (std::size_t i = 0; i < rows.size(); ++i) s.emplace_back(static_cast<int>(i), rows[i], 1.0);
  SpMat S(static_cast<int>(rows.size()), m_all_);
  S.setFromTriplets(s.begin(), s.end());
  return S * all;
}

SpMat System::jacobian(const VecX& q) const {
  return jacobian_rows(q, selected_rows_);
}

SpMat System::constraint_hessian(const VecX& lambda_sel) const {
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
  for (const auto& J : joints_) {
    const int na = joints::coordinate_count(J.joint->parent_kind());
    const int nb = coordinate_count(J.child);
    MatX H = MatX::Zero(na + nb, na + nb);
    J.joint->add_constraint_hessian(l.segment(J.row_offset, J.joint->constraint_count()), H);
    const int nodes[2] = {J.parent, J.child};
    const int off[2] = {0, na}, size[2] = {na, nb};
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b)
        if (nodes[a] >= 0 && nodes[b] >= 0)
          add_block(t, nodes_[nodes[a]].q_offset, nodes_[nodes[b]].q_offset,
                    H.block(off[a], off[b], size[a], size[b]));
  }
  SpMat H(n(), n());
  H.setFromTriplets(t.begin(), t.end());
  return H;
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

SpMat System::twist_map(const VecX& q, const InputBlocks& in) const {
  // Each node's twist as a sum of blocks (first column in ν, 6 × w block) over its tree path.
  using Blocks = std::vector<std::pair<int, MatX>>;
  std::vector<Blocks> rows(node_count());
  for (std::size_t r = 0; r < roots_.size(); ++r)
    rows[roots_[r]].push_back({root_nu_offset_[r], in.root[r]});
  for (int j : tree_order_) {
    const auto& J = joints_[j];
    Blocks& out = rows[J.child];
    if (J.parent >= 0) {
      const Mat<6, 6> A = J.joint->parent_block(node_q(q, J.parent), node_q(q, J.child));
      for (const auto& [c, B] : rows[J.parent]) out.push_back({c, A * B});
    }
    if (J.joint->freedom_count() > 0) out.push_back({J.nu_offset, in.joint[j]});
  }
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
  return internal_null_space(q) * twist_map(q);
}

VecX System::update(const VecX& qn, const VecX& u) const {
  VecX q = qn;
  // Rotation of every node over the step (joints/joint.hpp): what the joints below it apply.
  std::vector<Mat3> step(node_count(), Mat3::Identity());
  for (std::size_t r = 0; r < roots_.size(); ++r) {
    const int i = roots_[r];
    q.segment(nodes_[i].q_offset, coordinate_count(i)) = node_type(i).root_update(
        node_q(qn, i), u.segment(root_nu_offset_[r], root_width_[r]), step[i]);
  }
  const Mat3 ground_step = Mat3::Identity();
  for (int j : tree_order_) {
    const auto& J = joints_[j];
    const int c = J.child;
    q.segment(nodes_[c].q_offset, coordinate_count(c)) = J.joint->update(
        node_q(qn, J.parent), node_q(q, J.parent), J.parent >= 0 ? step[J.parent] : ground_step,
        node_q(qn, c), u.segment(J.nu_offset, J.joint->freedom_count()), &step[c]);
  }
  return q;
}

void System::extrapolate_increments(const VecX& q, const VecX& v, double dt, VecX& u) const {
  for (std::size_t r = 0; r < roots_.size(); ++r) {
    const int i = roots_[r];
    auto ui = u.segment(root_nu_offset_[r], root_width_[r]);
    node_type(i).extrapolate(node_q(q, i), node_q(v, i), dt, ui);
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
  const int N = node_count();
  VecX y(6 * N);
  for (int i = 0; i < N; ++i)
    y.segment<6>(6 * i) = node_type(i).twist_force(node_q(q, i), node_q(r, i));
  VecX out = VecX::Zero(k_);
  for (auto it = tree_order_.rbegin(); it != tree_order_.rend(); ++it) {
    const auto& J = joints_[*it];
    const auto qa = node_q(q, J.parent), qb = node_q(q, J.child);
    const Vec<6> yc = y.segment<6>(6 * J.child);
    if (J.parent >= 0) y.segment<6>(6 * J.parent) += J.joint->parent_block(qa, qb).transpose() * yc;
    if (J.joint->freedom_count() > 0)
      out.segment(J.nu_offset, J.joint->freedom_count()) =
          J.joint->freedom_block(qa, qb).transpose() * yc;
  }
  for (std::size_t r = 0; r < roots_.size(); ++r) {
    const int i = roots_[r];
    out.segment(root_nu_offset_[r], root_width_[r]) =
        node_type(i).free_force(node_q(q, i), y.segment<6>(6 * i));
  }
  return out;
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

// Material points are linear in q, so their velocity is the same map applied to v.
Vec3 System::material_velocity(const VecX&, const VecX& v, int node, const Vec3& X) const {
  return material_point(v, node, X);
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
