// System::compile (docs/architecture.md "How data flows"): a model becomes a system in phases,
// each adding one part of the model; `Build` carries what the phases pass on (node names, the
// joint graph, the supports).
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <functional>
#include <limits>
#include <map>
#include <new>
#include <set>

#include "isoflex/elements/beam_mesh.hpp"
#include "isoflex/elements/rigid_body.hpp"
#include "isoflex/joints/director_joints.hpp"
#include "isoflex/joints/joint_rows.hpp"
#include "isoflex/joints/linear_rows.hpp"
#include "isoflex/joints/point_joints.hpp"
#include "isoflex/joints/quadratic_rows.hpp"
#include "isoflex/loads/body_load.hpp"
#include "isoflex/loads/director_node_load.hpp"
#include "isoflex/loads/follower_body_load.hpp"
#include "isoflex/loads/patch_edge.hpp"
#include "isoflex/loads/time_function.hpp"
#include "isoflex/math/director_node.hpp"
#include "isoflex/solve/linear_solver.hpp"
#include "isoflex/solve/normal_equations.hpp"
#include "isoflex/system/joint_drivers.hpp"
#include "isoflex/system/joint_frames.hpp"
#include "isoflex/system/kl_model.hpp"
#include "isoflex/system/row_selection.hpp"
#include "isoflex/system/system.hpp"

namespace isoflex::system {

namespace fn = frame_node;
namespace dn = director_node;

struct System::Build {
  const model::Model& model;
  std::map<std::string, int> index;  // node by name: bodies, "<beam>[i]", "<shell>[i]"
  struct Edge {
    int a, b;  // nodes (−1: the ground) of a model joint's body_a, body_b, or a support's sides
  };
  std::vector<Edge> edges;  // model joints, then supports
  struct Support {
    std::string name;
    std::shared_ptr<const joints::Joint> joint;
    model::Source source;
    std::string type = "shell_support";
  };
  std::vector<Support> supports;
  std::vector<int> tree_parent_side;  // per edge: 0 not in the tree, +1 a → b, −1 b → a
  std::vector<int> order;             // tree joints (edges) in BFS order
  // Per model joint: its driver row's n-ary constraint (revolute, prismatic) or −1.
  std::vector<int> driver_of_joint;

  int find(const std::string& name, const model::Source& src, const std::string& what) const {
    if (name == "ground") return -1;
    const auto it = index.find(name);
    if (it == index.end()) compile_fail(src, what, fmt::format("no body named '{}'", name));
    return it->second;
  }
};

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

}  // namespace

System System::compile(const model::Model& model) {
  System s;
  Build build{model, {}, {}, {}, {}, {}, {}};
  s.ground_ = fn::make(Vec3::Zero(), Mat3::Identity());
  // Nodes: the bodies in model order, the nodes of each beam along its polyline, the shells'
  // director nodes, the control points of the Kirchhoff–Love patches.
  s.add_bodies(build);
  s.add_beams(build);
  s.add_shells(build);
  s.add_kl_patches(model);
  for (const auto& e : s.elements_) s.viscous_ = s.viscous_ || e->viscous();
  for (const auto& e : s.elements_)
    s.strain_dissipation_ = s.strain_dissipation_ || e->strain_dissipation();
  s.finish_nodes(build);
  // A static analysis has no inertia: its mass matrix stays empty (zero), saving the patch mass
  // (as large as the stiffness) and its quadrature.
  if (model.solver.analysis == model::Analysis::statics)
    s.M_.resize(s.n(), s.n());
  else
    s.assemble_mass();
  s.add_body_loads(build);
  s.add_distributed_loads(build);
  s.add_shell_loads(build);
  s.add_probes(build);
  const NodeFinder find = [&](const std::string& name, const model::Source& src,
                              const std::string& what) { return build.find(name, src, what); };
  s.add_springs(model, find);
  s.add_frame_springs(model, find);
  // Joints and supports, the spanning forest, the rows.
  s.add_joint_edges(build);
  s.add_shell_supports(build);
  s.add_kl_supports(build);
  s.add_kl_surface_joints(build);
  s.add_joint_drivers(model, find, build.driver_of_joint);
  s.build_forest(build);
  s.add_joint_instances(build);
  s.mark_rotations();
  s.check_assembled(build);
  s.select_loop_rows();
  // A spherical joint whose ground point moves (a driver) must keep all its rows: a dropped row
  // holds only if the kept ones imply it, which a moving point does not (as for the n-ary rows,
  // select_loop_rows).
  for (int r : s.redundant_rows_) {
    const int j = s.joint_of_row(r);
    if (j < 0 || static_cast<std::size_t>(j) >= model.joints.size() ||
        !s.joints_[static_cast<std::size_t>(j)].rows->rheonomic())
      continue;
    fail(model.joints[static_cast<std::size_t>(j)].source, fmt::format("joints[{}].driver", j),
         fmt::format("row {} of the moving point depends on the other rows of the model (it "
                     "acts on what other joints already hold); a prescribed motion must act on "
                     "free coordinates only",
                     r - s.joints_[static_cast<std::size_t>(j)].row_offset));
  }
  s.set_initial_velocities(model);
  s.build_stiffness_pattern();
  return s;
}

// Bodies: frame nodes in model order (node i is body i) with their RigidBody elements.
void System::add_bodies(Build& build) {
  const model::Model& model = build.model;
  for (int i = 0; i < static_cast<int>(model.bodies.size()); ++i) {
    const auto& b = model.bodies[i];
    build.index[b.name] = i;
    add_node(NodeKind::frame, fn::make(b.position, b.orientation), b.name, -1);
    elements_.push_back(std::make_unique<elements::RigidBody>(i, b.mass, b.inertia, model.gravity));
  }
}

// Beams: frame nodes along each polyline, BeamElements between them.
void System::add_beams(Build& build) {
  const model::Model& model = build.model;
  for (std::size_t bi = 0; bi < model.beams.size(); ++bi) {
    const auto& B = model.beams[bi];
    const int next = node_count();
    const std::string what = fmt::format("beams[{}]", bi);
    BeamInstance inst{B.name, {}, {}};
    std::vector<fn::Q> q;
    // Per node, the triad of the segment that starts there where it differs from the node's: a
    // vertex shared by two segments keeps the triad of the segment before it, and the first
    // element of the next one sees it turned by the constant rotation between the two — a rigid
    // corner (elements::BeamElement's triad_a). Before, that element absorbed the kink in its
    // reference strains: its directors interpolated between the two triads, and the frame was far
    // too flexible (+3.9 % tip deflection at a 45° corner, Newton failing at 90°).
    std::vector<std::optional<Mat3>> corner_triad;
    try {
      if (B.arc)
        q = elements::helix_beam_nodes(B.arc->axis_point, B.arc->axis, B.arc->start, B.arc->angle,
                                       B.arc->pitch, B.d1, B.elements.front());
      corner_triad.resize(q.size());
      for (std::size_t seg = 0; seg + 1 < B.points.size(); ++seg) {
        const auto part =
            elements::straight_beam_nodes(B.points[seg], B.points[seg + 1], B.d1, B.elements[seg]);
        if (seg > 0) {
          const Eigen::Map<const Mat3> before(q.back().data() + 3), after(part.front().data() + 3);
          if ((before - after).cwiseAbs().maxCoeff() > 1e-12) corner_triad.back() = Mat3(after);
        }
        q.insert(q.end(), part.begin() + (seg == 0 ? 0 : 1), part.end());
        corner_triad.resize(q.size());
      }
    } catch (const std::bad_alloc&) {
      throw;  // out of memory is not a model error (app/commands.cpp reports it)
    } catch (const std::exception& e) {
      fail(B.source, what, e.what());
    }
    for (std::size_t k = 0; k < q.size(); ++k) {
      const std::string name = fmt::format("{}[{}]", B.name, k);
      build.index[name] = next + static_cast<int>(k);
      add_node(NodeKind::frame, q[k], name, static_cast<int>(bi));
      inst.nodes.push_back(next + static_cast<int>(k));
    }
    const model::BeamSection& c = B.section;
    const elements::BeamSection section{c.EA, c.GA1,   c.GA2,    c.EI1,    c.EI2,
                                        c.GJ, c.A_rho, c.M_rho1, c.M_rho2, c.eta};
    for (std::size_t k = 0; k + 1 < q.size(); ++k) {
      const int a = next + static_cast<int>(k);
      try {
        elements_.push_back(std::make_unique<elements::BeamElement>(
            a, a + 1, q[k], q[k + 1], section, model.gravity, corner_triad[k]));
      } catch (const std::bad_alloc&) {
        throw;  // out of memory is not a model error (app/commands.cpp reports it)
      } catch (const std::exception& e) {
        fail(B.source, fmt::format("{}.section", what), e.what());
      }
      inst.elements.push_back(static_cast<const elements::BeamElement*>(elements_.back().get()));
    }
    beams_.push_back(std::move(inst));
  }
}

// Shells: director nodes (40) "<shell>[i]" and bilinear director-shell elements.
void System::add_shells(Build& build) {
  const model::Model& model = build.model;
  for (std::size_t si = 0; si < model.shells.size(); ++si) {
    const auto& S = model.shells[si];
    const int next = node_count();
    const std::string what = fmt::format("shells[{}]", si);
    ShellInstance inst{S.name, {}, {}};
    for (int k = 0; k < S.node_count(); ++k) {
      const std::string name = fmt::format("{}[{}]", S.name, k);
      build.index[name] = next + k;
      dn::Q q;
      q << S.points[k], S.directors[k];
      add_node(NodeKind::director, q, name, static_cast<int>(model.beams.size() + si));
      inst.nodes.push_back(next + k);
    }
    const elements::ShellMaterial mat{S.material.E,
                                      S.material.nu,
                                      S.material.thickness,
                                      S.material.density,
                                      S.material.shear_correction,
                                      S.material.eta};
    for (std::size_t e = 0; e < S.quads.size(); ++e) {
      std::array<int, 4> nodes;
      Vec<24> q0;
      for (int a = 0; a < 4; ++a) {
        nodes[a] = next + S.quads[e][a];
        q0.segment<6>(6 * a) << S.points[S.quads[e][a]], S.directors[S.quads[e][a]];
      }
      try {
        elements_.push_back(
            std::make_unique<elements::DirectorShellElement>(nodes, q0, mat, model.gravity));
      } catch (const std::bad_alloc&) {
        throw;  // out of memory is not a model error (app/commands.cpp reports it)
      } catch (const std::exception& ex) {
        fail(S.source, fmt::format("{} element {}", what, e), ex.what());
      }
      inst.elements.push_back(
          static_cast<const elements::DirectorShellElement*>(elements_.back().get()));
    }
    shells_.push_back(std::move(inst));
  }
}

// After the last node: q₀ as one vector, the control points findable by name.
void System::finish_nodes(Build& build) {
  for (const KLPatchInstance& k : kl_patches_)
    for (int node : k.nodes) build.index[node_names_[node]] = node;
  q0_ = Eigen::Map<const VecX>(q0_build_.data(), static_cast<Eigen::Index>(q0_build_.size()));
  q0_build_ = {};
}

// The constant mass matrix from the elements' sparse masses.
void System::assemble_mass() {
  Triplets t;
  for (const auto& e : elements_) {
    const std::vector<int> c = coordinates_of(e->nodes());
    const SpMat Me = e->sparse_mass();
    for (int j = 0; j < Me.outerSize(); ++j)
      for (SpMat::InnerIterator it(Me, j); it; ++it)
        t.emplace_back(c[it.row()], c[it.col()], it.value());
  }
  M_.resize(n(), n());
  M_.setFromTriplets(t.begin(), t.end());
}

// Loads on bodies and beam nodes: global components (loads/body_load.hpp) or components in the
// node's director frame (frame: body, loads/follower_body_load.hpp).
void System::add_body_loads(Build& build) {
  const model::Model& model = build.model;
  for (std::size_t l = 0; l < model.loads.size(); ++l) {
    const auto& L = model.loads[l];
    const std::string what = fmt::format("loads[{}]", l);
    const int node = build.find(L.body, L.source, what + ".body");
    if (node < 0) fail(L.source, what + ".body", "a load cannot act on the ground");
    if (node_kind(node) != NodeKind::frame)
      fail(L.source, what + ".body",
           fmt::format("'{}' is a shell node: load shells with shell_loads", L.body));
    const Vec3 X = body_coordinates(node, L.point, L.point_local);
    auto compile3 = [&](const std::optional<std::array<std::string, 3>>& e, const char* key) {
      std::optional<std::array<loads::TimeFunction, 3>> f;
      if (!e) return f;
      try {
        f = std::array<loads::TimeFunction, 3>{loads::TimeFunction((*e)[0]),
                                               loads::TimeFunction((*e)[1]),
                                               loads::TimeFunction((*e)[2])};
      } catch (const std::bad_alloc&) {
        throw;  // out of memory is not a model error (app/commands.cpp reports it)
      } catch (const std::exception& ex) {
        fail(L.source, what + "." + key, ex.what());
      }
      return f;
    };
    auto force = compile3(L.force, "force");
    auto moment = compile3(L.moment, "moment");
    if (L.frame == model::LoadFrame::body)
      loads_.push_back(
          std::make_shared<loads::FollowerBodyLoad>(node, X, std::move(force), std::move(moment)));
    else
      loads_.push_back(
          std::make_shared<loads::BodyLoad>(node, X, std::move(force), std::move(moment)));
  }
}

// Distributed dead loads per length: consistent nodal forces of the linear shape functions,
// ∫ N_a f ds = f L/2 per element end (f constant along the element).
void System::add_distributed_loads(Build& build) {
  const model::Model& model = build.model;
  for (std::size_t l = 0; l < model.distributed_loads.size(); ++l) {
    const auto& D = model.distributed_loads[l];
    const std::string what = fmt::format("distributed_loads[{}]", l);
    const auto beam = std::find_if(beams_.begin(), beams_.end(),
                                   [&](const BeamInstance& b) { return b.name == D.beam; });
    if (beam == beams_.end()) fail(D.source, what + ".beam", "no beam named '" + D.beam + "'");
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
      } catch (const std::bad_alloc&) {
        throw;  // out of memory is not a model error (app/commands.cpp reports it)
      } catch (const std::exception& ex) {
        fail(D.source, what + ".force_per_length", ex.what());
      }
      loads_.push_back(
          std::make_shared<loads::BodyLoad>(beam->nodes[k], Vec3::Zero(), f, std::nullopt));
    }
  }
}

// Shell loads: nodal forces and moments, edge loads lumped by the linear shape functions
// (½ of each edge segment to its end nodes), area loads by the consistent nodal weights
// ∫ N_a dA and ∫ N_a N dA of the elements (all dead loads).
void System::add_shell_loads(Build& build) {
  const model::Model& model = build.model;
  for (std::size_t l = 0; l < model.shell_loads.size(); ++l) {
    const auto& L = model.shell_loads[l];
    const std::string what = fmt::format("shell_loads[{}]", l);
    const auto shell = std::find_if(shells_.begin(), shells_.end(),
                                    [&](const ShellInstance& x) { return x.name == L.shell; });
    if (shell == shells_.end()) fail(L.source, what + ".shell", "no shell named " + L.shell);
    // Nodal vectors per shell node: weight × expression.
    std::vector<Vec3> area(shell->nodes.size(), Vec3::Zero());
    std::vector<double> weight(shell->nodes.size(), 0.0);
    auto scaled = [&](const std::array<std::string, 3>& e, const Vec3& w) {
      std::array<loads::TimeFunction, 3> f;
      try {
        for (int c = 0; c < 3; ++c)
          f[c] = loads::TimeFunction(fmt::format("({})*{:.17g}", e[c], w(c)));
      } catch (const std::bad_alloc&) {
        throw;  // out of memory is not a model error (app/commands.cpp reports it)
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
        loads_.push_back(
            std::make_shared<loads::DirectorNodeLoad>(shell->nodes[k], f, std::nullopt));
      }
      continue;
    }
    std::vector<double> w(L.nodes.size(), 1.0);
    if (L.per_length) {
      std::fill(w.begin(), w.end(), 0.0);
      for (std::size_t k = 0; k + 1 < L.nodes.size(); ++k) {
        const double len = (q0_.segment<3>(q_offset(first + L.nodes[k + 1])) -
                            q0_.segment<3>(q_offset(first + L.nodes[k])))
                               .norm();
        w[k] += 0.5 * len;
        w[k + 1] += 0.5 * len;
      }
    }
    for (std::size_t k = 0; k < L.nodes.size(); ++k) {
      std::optional<std::array<loads::TimeFunction, 3>> f, m;
      if (L.force) f = scaled(*L.force, Vec3::Constant(w[k]));
      if (L.moment) m = scaled(*L.moment, Vec3::Constant(w[k]));
      loads_.push_back(std::make_shared<loads::DirectorNodeLoad>(first + L.nodes[k], f, m));
    }
  }
}

// Probes: material points of bodies, beam and shell nodes, or KL patches.
void System::add_probes(Build& build) {
  const model::Model& model = build.model;
  for (std::size_t p = 0; p < model.probes.size(); ++p) {
    const auto& P = model.probes[p];
    if (!P.kl_shell.empty()) {
      probes_.push_back(kl_probe(P));
      continue;
    }
    const int node = build.find(P.body, P.source, fmt::format("probes[{}].body", p));
    if (node < 0) fail(P.source, fmt::format("probes[{}].body", p), "a probe needs a body");
    // A shell node's probe follows the node's mid-surface point (NodeType::local_coordinates).
    probes_.push_back({P.name, node, body_coordinates(node, P.point, P.point_local), {}});
  }
}

// Joint graph and spanning forest rooted at the ground (breadth first, so chains hang from the
// ground by their shortest paths). A joint reached from its body_b side is built with the roles
// swapped; its constraint set is equivalent (frames coincide at t = 0). A point-on-line joint
// is not symmetric (the line belongs to body_a), so it is never used reversed in the tree.
void System::add_joint_edges(Build& build) {
  const model::Model& model = build.model;
  for (std::size_t j = 0; j < model.joints.size(); ++j) {
    const auto& J = model.joints[j];
    const std::string what = fmt::format("joints[{}]", j);
    const int a = build.find(J.body_a, J.source, what + ".body_a");
    const int b = build.find(J.body_b, J.source, what + ".body_b");
    if (b < 0) fail(J.source, what + ".body_b", "body_b cannot be the ground");
    if (a == b) fail(J.source, what, "a joint needs two different bodies");
    if (J.type == model::JointType::fixed && a >= 0)
      fail(J.source, what + ".body_a", "a fixed support joins a body to the ground");
    build.edges.push_back({a, b});
  }
}

// Shell supports: one joint from the ground per supported node (joints/director_joints.hpp).
// Entries naming the same node are merged (a corner on two symmetry planes): fixed components
// add up; two different symmetry normals leave the director no freedom but drilling.
void System::add_shell_supports(Build& build) {
  const model::Model& model = build.model;
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
      const auto shell = std::find_if(shells_.begin(), shells_.end(),
                                      [&](const ShellInstance& x) { return x.name == S.shell; });
      const std::string what = fmt::format("shell_supports[{}]", k);
      if (shell == shells_.end()) fail(S.source, what + ".shell", "no shell named " + S.shell);
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
        build.supports.push_back({fmt::format("{}:{}", p.what, node_names_[p.node]),
                                  std::make_shared<joints::DirectorSupport>(
                                      dn::Q(q0_.segment<6>(q_offset(p.node))), p.spec),
                                  p.source});
      } catch (const std::bad_alloc&) {
        throw;  // out of memory is not a model error (app/commands.cpp reports it)
      } catch (const std::exception& e) {
        fail(p.source, p.what, fmt::format("node {}: {}", node_names_[p.node], e.what()));
      }
      build.edges.push_back({-1, p.node});
    }
  }
}

// Kirchhoff–Love supports. In a static analysis a support to the ground is a linear condition
// on the control points (system/kl_boundary_conditions.hpp, docs/theory/kl-static.md §2):
// eliminated components and multiplier rows, every kind. Otherwise the control points of the
// supported rows (fixed: the edge or the listed points; clamped: rows 0 and 1, which carry the
// slope across the edge) are rigidly attached to a body or the ground (joints/point_joints.hpp);
// attaching row 1 also holds the stretch across a clamped edge, unlike the static clamp.
void System::add_kl_supports(Build& build) {
  const model::Model& model = build.model;
  const bool statics = model.solver.analysis == model::Analysis::statics;
  if (statics)
    for (const KLPatchInstance& P : kl_patches_) {
      const KLBoundaryConditions bcs = kl_boundary_conditions(
          model, P.element->patch().reference(),
          [&](const model::KLSupport& S) { return S.body.empty() && S.shell == P.name; });
      add_linear_constraints(bcs.constraints(), P.nodes);
    }
  for (std::size_t k = 0; k < model.kl_supports.size(); ++k) {
    const auto& S = model.kl_supports[k];
    if (!S.control_points.empty() && kl_patch_of(S.shell).renumbered)
      fail(S.source, fmt::format("kl_supports[{}].control_points", k),
           fmt::format("the control points of \"{}\" were renumbered by the knots inserted to "
                       "join it to its neighbours (isoflex check lists them): give the support "
                       "by edge, or refine the surfaces to match in the model file",
                       S.shell));
    if (statics && S.body.empty()) continue;
    const std::string what = fmt::format("kl_supports[{}]", k);
    using K = model::KLSupportKind;
    const KLPatchInstance& P = kl_patch_of(S.shell);  // the reader checked the name
    const bool attachment = S.components[0] && S.components[1] && S.components[2] &&
                            (S.kind == K::fixed || S.kind == K::clamped);
    if (!attachment && S.body.empty()) {
      add_kl_support_rows(model, S, what, P);
      continue;
    }
    if (!attachment)
      fail(S.source, what,
           "a Kirchhoff–Love support to a body holds all components, fixed or clamped");
    const geometry::NurbsSurface& g = P.element->patch().reference();
    std::vector<int> cps = S.control_points;
    if (!S.edge.empty())
      for (int r = 0; r < (S.kind == K::clamped ? 2 : 1); ++r)
        for (int cp : loads::edge_control_points(g, loads::patch_edge_from_string(S.edge), r))
          cps.push_back(cp);
    const int parent = S.body.empty() ? -1 : build.find(S.body, S.source, what + ".body");
    for (int cp : cps) {
      const int node = P.nodes[cp];
      build.supports.push_back(
          {fmt::format("{}:{}", what, node_names_[node]),
           std::make_shared<joints::PointOnFrame>(fn::Q(node_q(q0_, parent)),
                                                  Vec3(q0_.segment<3>(q_offset(node)))),
           S.source, "kl_support"});
      build.edges.push_back({parent, node});
    }
  }
}

// A support to the ground that is not a rigid attachment, in a dynamic run: its conditions
// (system/kl_boundary_conditions.hpp, as in statics) as linear rows over the control points they
// touch, an n-ary constraint (joints/linear_rows.hpp); an eliminated component is the row
// e_k·(x_A − X_A) = ū(t). A prescribed displacement makes the rows rheonomic, C (x − X) = d(t)
// (IGA-thesis (3.37)–(3.40)); the run starts from the reference configuration, so d(0) = 0.
void System::add_kl_support_rows(const model::Model& model, const model::KLSupport& S,
                                 const std::string& what, const KLPatchInstance& P) {
  using K = model::KLSupportKind;
  const geometry::NurbsSurface& g = P.element->patch().reference();
  LinearConstraints lc = kl_boundary_conditions(model, g, [&](const model::KLSupport& o) {
                           return &o == &S;
                         }).constraints();
  // Rows over patch dofs: the eliminated ones, then C's from row `skip` on.
  int skip = 0;
  if (S.kind == K::displacement) {
    // As in statics (kl_boundary_conditions.hpp, (4.26)): the functions of the edge whose
    // component another support to the ground fixes, or an earlier prescribed edge owns, are
    // dropped, so that a corner is not imposed twice. The other supports' own conditions (their
    // eliminations, the slope rows of a clamp, the earlier edges' rows: the first `skip` rows)
    // are theirs to impose.
    auto fixing = [&](const model::KLSupport& o) {
      return o.body.empty() && o.shell == S.shell &&
             (o.kind == K::fixed || o.kind == K::clamped || (o.kind == K::displacement && &o < &S));
    };
    skip = kl_boundary_conditions(model, g, fixing).constraints().multipliers();
    lc = kl_boundary_conditions(model, g, [&](const model::KLSupport& o) {
           return &o == &S || fixing(o);
         }).constraints();
    lc.eliminated.clear();
    lc.eliminated_value.clear();
  }
  std::vector<std::vector<std::pair<int, double>>> rows;
  for (int i : lc.eliminated) rows.push_back({{i, 1.0}});
  const int first = static_cast<int>(rows.size());
  rows.resize(rows.size() + static_cast<std::size_t>(lc.multipliers() - skip));
  for (int j = 0; j < lc.C.outerSize(); ++j)
    for (Eigen::SparseMatrix<double>::InnerIterator it(lc.C, j); it; ++it)
      if (it.row() >= skip)
        rows[static_cast<std::size_t>(first + it.row() - skip)].push_back({j, it.value()});
  // The control points touched, in patch order, and C over their stacked coordinates.
  std::map<int, int> local;  // control point → position
  for (const auto& r : rows)
    for (const auto& [dof, c] : r) local.emplace(dof / 3, 0);
  std::vector<int> nodes;
  for (auto& [cp, pos] : local) {
    pos = static_cast<int>(nodes.size());
    nodes.push_back(P.nodes[static_cast<std::size_t>(cp)]);
  }
  MatX C = MatX::Zero(static_cast<Eigen::Index>(rows.size()),
                      3 * static_cast<Eigen::Index>(nodes.size()));
  for (std::size_t r = 0; r < rows.size(); ++r)
    for (const auto& [dof, c] : rows[r])
      C(static_cast<Eigen::Index>(r), 3 * local[dof / 3] + dof % 3) += c;
  if (rows.empty()) fail(S.source, what, "the support holds nothing");
  std::function<VecX(double)> d;
  const bool moving = lc.rhs || std::any_of(lc.eliminated_value.begin(), lc.eliminated_value.end(),
                                            [](const auto& f) { return static_cast<bool>(f); });
  if (moving)
    d = [lc, m = static_cast<int>(rows.size())](double t) {
      VecX out = VecX::Zero(m);
      const int e = static_cast<int>(lc.eliminated.size());
      for (int i = 0; i < e; ++i)
        if (lc.eliminated_value[static_cast<std::size_t>(i)])
          out(i) = lc.eliminated_value[static_cast<std::size_t>(i)](t);
      if (lc.rhs) out.tail(m - e) = lc.rhs(t).tail(m - e);
      return out;
    };
  auto constraint =
      std::make_shared<joints::LinearRows>(nodes, std::move(C), stacked(q0_, nodes), std::move(d));
  if (moving) {
    for (int k = 0; k < 3; ++k) {
      const double u0 = loads::TimeFunction(S.displacement[static_cast<std::size_t>(k)])(0.0);
      if (u0 != 0.0)
        fail(S.source, what + fmt::format(".displacement[{}]", k),
             fmt::format("'{}' is {:.6g} at t = 0: a dynamic run starts from the reference "
                         "configuration, so a prescribed displacement starts at 0",
                         S.displacement[static_cast<std::size_t>(k)], u0));
    }
    rheonomic_ = true;
  }
  nary_.push_back({what, "kl_support_rows", std::move(constraint), 0, S.source});
}

// Joints at points of a Kirchhoff–Love patch: the patch's material point Σ R_A(ξ, η) φ_A
// (IGA-thesis (4.20), (ξ, η) from the point projection (4.14)–(4.15) of the reader) and the
// other side's material point φ + X_I d_I (a frame node) or a fixed point coincide: three rows,
// linear in all coordinates. A revolute joint adds two rows that keep the axis, a vector Y_I d_I
// fixed in the body, in its place relative to the patch (docs/theory/coupling.md §10):
//   axis normal to the surface at t = 0:   a_α · (Y_I d_I) = 0,  α = 1, 2 (a_α = Σ R_A,α φ_A);
//   axis tangent to it, axis = c^α a_α:    (c^α a_α) · (Z^k_I d_I) = 0,  k = 1, 2, Z^k ⊥ Y;
// bilinear in the coordinates, so a QuadraticRows constraint (joints/quadratic_rows.hpp) over the
// frame node and the control points whose functions do not vanish there. Translating or rotating
// both sides together keeps every row, so momentum is conserved with them.
void System::add_kl_surface_joints(Build& build) {
  const model::Model& model = build.model;
  for (std::size_t k = 0; k < model.kl_surface_joints.size(); ++k) {
    const model::Joint& J = model.kl_surface_joints[k];
    const std::string what = J.name;
    const auto patch = std::find_if(kl_patches_.begin(), kl_patches_.end(),
                                    [&](const KLPatchInstance& P) { return P.name == J.kl_shell; });
    if (patch == kl_patches_.end()) fail(J.source, what, "no kl_shell named '" + J.kl_shell + "'");
    const int body = build.find(J.body_a, J.source, what + ".body_a");
    if (body >= 0 && node_kind(body) != NodeKind::frame)
      fail(J.source, what + ".body_a",
           fmt::format("'{}' is not a body or beam node: a joint at a shell point joins a frame "
                       "node or the ground",
                       J.body_a));
    const geometry::NurbsSurface& g = patch->element->patch().reference();
    const geometry::SurfaceBasis B = geometry::surface_basis(g, J.xi, J.eta);
    const bool revolute = J.type == model::JointType::revolute;
    std::vector<int> nodes;
    std::vector<int> functions;  // local functions that (or whose derivatives) do not vanish there
    if (body >= 0) nodes.push_back(body);
    for (int a = 0; a < B.R.cols(); ++a)
      if (B.R(0, a) != 0.0 || (revolute && (B.R(1, a) != 0.0 || B.R(2, a) != 0.0))) {
        nodes.push_back(patch->nodes[B.global_index(g, a)]);
        functions.push_back(a);
      }
    const int off = body >= 0 ? 12 : 0;
    const int n = off + 3 * static_cast<int>(functions.size());
    // x ↦ 3 × n maps: the patch's point (derivative d = 0) or tangent a_d (d = 1, 2).
    const auto patch_map = [&](int d) {
      MatX M = MatX::Zero(3, n);
      for (std::size_t i = 0; i < functions.size(); ++i)
        M.middleCols<3>(off + 3 * static_cast<int>(i)) = B.R(d, functions[i]) * Mat3::Identity();
      return M;
    };
    // The body's vector Y_I d_I (3 × n; zero columns for the ground).
    const auto body_map = [&](const Vec3& Y) {
      MatX M = MatX::Zero(3, n);
      for (int i = 0; i < 3 && body >= 0; ++i) M.middleCols<3>(3 + 3 * i) = Y(i) * Mat3::Identity();
      return M;
    };
    const int rows = revolute ? 5 : 3;
    std::vector<MatX> H(static_cast<std::size_t>(rows));
    MatX C = MatX::Zero(rows, n);
    VecX c = VecX::Zero(rows);
    C.topRows<3>() = patch_map(0);
    if (body >= 0) {
      const Vec3 X = body_coordinates(body, J.point, std::nullopt);
      C.block<3, 3>(0, 0) = -Mat3::Identity();
      C.topRows<3>() -= body_map(X);
    }
    const VecX q0 = stacked(q0_, nodes);
    if (revolute) {
      const Vec3 a1 = patch_map(1) * q0, a2 = patch_map(2) * q0;
      const Vec3 normal = a1.cross(a2).normalized();
      const Mat3 D0 = body >= 0 ? Mat3(frame_node::directors(node_q(q0_, body))) : Mat3::Identity();
      const Vec3 axis = J.axis ? *J.axis : Vec3(D0 * *J.axis_a);  // global at t = 0
      const double cos_n = std::abs(axis.dot(normal));
      // The body vectors the patch's vectors stay perpendicular to, and those patch vectors.
      std::array<Vec3, 2> body_vectors;
      std::array<MatX, 2> patch_vectors;
      if (cos_n > 1.0 - 1e-9) {
        body_vectors = {axis, axis};
        patch_vectors = {patch_map(1), patch_map(2)};
      } else if (cos_n < 1e-9) {
        Eigen::Matrix<double, 3, 2> A;
        A << a1, a2;
        const Eigen::Vector2d cc = A.colPivHouseholderQr().solve(axis);
        const Vec3 z1 =
            axis.cross(std::abs(axis.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).normalized();
        body_vectors = {z1, axis.cross(z1)};
        const MatX t = cc(0) * patch_map(1) + cc(1) * patch_map(2);
        patch_vectors = {t, t};
      } else {
        fail(J.source, what + (J.axis ? ".axis" : ".axis_a"),
             fmt::format("the axis makes {:.6g}° with the normal of '{}' at the joint point: a "
                         "revolute joint at a shell point takes an axis normal or tangent to the "
                         "surface there (within 1e-9)",
                         std::acos(std::min(1.0, cos_n)) * 180.0 / M_PI, J.kl_shell));
      }
      for (int r = 0; r < 2; ++r) {
        const Vec3& v = body_vectors[static_cast<std::size_t>(r)];
        const MatX& T = patch_vectors[static_cast<std::size_t>(r)];
        if (body >= 0) {
          const MatX M = body_map(D0.transpose() * v);  // v = Y_I d_I at t = 0
          const MatX TM = T.transpose() * M;
          H[static_cast<std::size_t>(3 + r)] = TM + TM.transpose();
        } else {
          C.row(3 + r) = v.transpose() * T;
        }
      }
    }
    // Φ(q₀) = 0 exactly: the point projection leaves the two points up to its tolerance apart,
    // and the normal/tangent test accepts an axis within 1e-9.
    for (int r = 0; r < rows; ++r) {
      const MatX& h = H[static_cast<std::size_t>(r)];
      c(r) = -(C.row(r).dot(q0) + (h.size() != 0 ? 0.5 * q0.dot(h * q0) : 0.0));
    }
    ShellPointJointInstance spj{static_cast<int>(nary_.size()), {}, body};
    for (std::size_t i = 0; i < functions.size(); ++i)
      if (B.R(0, functions[i]) != 0.0)
        spj.point.emplace_back(nodes[static_cast<std::size_t>(body >= 0) + i],
                               B.R(0, functions[i]));
    shell_point_joints_.push_back(std::move(spj));
    try {
      nary_.push_back(
          {what, revolute ? "revolute_at_shell_point" : "spherical_at_shell_point",
           std::make_shared<joints::QuadraticRows>(nodes, std::move(H), std::move(C), std::move(c)),
           0, J.source});
    } catch (const std::invalid_argument& e) {
      fail(J.source, what, e.what());
    }
  }
}

// The spanning forest: breadth first from the ground, then from each node not yet reached (a
// root, free). Sets tree_parent_side and the tree joints in BFS order.
void System::build_forest(Build& build) {
  const model::Model& model = build.model;
  const std::size_t n_model_joints = model.joints.size();
  build.tree_parent_side.assign(build.edges.size(), 0);
  std::vector<bool> reached(node_count(), false);
  auto grow = [&](std::deque<int> frontier) {
    while (!frontier.empty()) {
      const int u = frontier.front();
      frontier.pop_front();
      for (std::size_t j = 0; j < build.edges.size(); ++j) {
        if (build.tree_parent_side[j] != 0) continue;
        // A spherical joint whose ground point moves (a driver) is a cut joint: the tree's
        // update map and null space are those of fixed joints.
        if (j < n_model_joints && model.joints[j].type == model::JointType::spherical &&
            !model.joints[j].driver.empty())
          continue;
        const auto [a, b] = build.edges[j];
        if (a == u && !reached[b]) {
          build.tree_parent_side[j] = 1;
          reached[b] = true;
          build.order.push_back(static_cast<int>(j));
          frontier.push_back(b);
        } else if (b == u && a >= 0 && !reached[a] && j < n_model_joints &&
                   model.joints[j].type != model::JointType::point_on_line) {
          build.tree_parent_side[j] = -1;
          reached[a] = true;
          build.order.push_back(static_cast<int>(j));
          frontier.push_back(a);
        }
      }
    }
  };
  grow({-1});
  for (int i = 0; i < node_count(); ++i) {
    if (reached[i]) continue;
    reached[i] = true;
    roots_.push_back(i);
    grow({i});
  }
}

// A joint between two frame nodes (or a frame node and the ground) from its model entry: the
// joint point and axes at t = 0 from the entry (global or in body a/b coordinates), the frame E
// built about the axis.
std::shared_ptr<const joints::Joint> System::frame_joint(const Build& build, std::size_t j,
                                                         int parent, int child, bool rev) const {
  const model::Joint& J = build.model.joints[j];
  const std::string what = fmt::format("joints[{}]", j);
  const fn::Q qa0 = node_q(q0_, parent), qb0 = node_q(q0_, child);
  // Body a and b of the model entry (not parent/child) at t = 0; the ground frame for ground.
  const fn::Q qA = node_q(q0_, build.edges[j].a), qB = node_q(q0_, build.edges[j].b);
  const auto [p, axis, axis2] = joint_frame_at_start(J, qA, qB);
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
  return std::make_shared<const joints::FrameJoint>(kind_of(J.type),
                                                    joints::geometry_from_global(qa0, qb0, p, E));
}

// The joint of model entry j between parent and child (the roles the spanning forest gave them):
// a control point attached to a frame node, a joint with a director node, or a frame joint.
std::shared_ptr<const joints::Joint> System::model_joint(const Build& build, std::size_t j,
                                                         int parent, int child, bool rev) const {
  const model::Joint& J = build.model.joints[j];
  const std::string what = fmt::format("joints[{}]", j);
  if (parent >= 0 && node_kind(parent) == NodeKind::point)
    fail(J.source, what,
         fmt::format("'{}' would carry '{}': a point node (a control point) can only hang from "
                     "a body, a beam node or the ground",
                     node_names_[parent], node_names_[child]));
  if (node_kind(child) == NodeKind::point) {
    using T = model::JointType;
    if (J.type != T::rigid && J.type != T::fixed && J.type != T::spherical)
      fail(J.source, what + ".type",
           fmt::format("'{}' is a control point: it is attached (rigid, fixed or spherical, "
                       "which coincide for a point), not {}",
                       node_names_[child], model::to_string(J.type)));
    if (parent >= 0 && node_kind(parent) != NodeKind::frame)
      fail(J.source, what, "a control point is attached to a body, a beam node or the ground");
    return std::make_shared<joints::PointOnFrame>(fn::Q(node_q(q0_, parent)),
                                                  Vec3(q0_.segment<3>(q_offset(child))));
  }
  if ((parent >= 0 && node_kind(parent) == NodeKind::director) ||
      node_kind(child) == NodeKind::director) {
    return director_joint(J, parent, child, what);
  }
  return frame_joint(build, j, parent, child, rev);
}

// Joint instances in model order, then the supports (joints_ is indexed like build.edges), their
// rows, and the layout of ν: the roots' free velocities, then τ of the tree joints in BFS order.
void System::add_joint_instances(Build& build) {
  const model::Model& model = build.model;
  const std::size_t n_model_joints = model.joints.size();
  int row = internal_rows_;
  for (std::size_t j = 0; j < n_model_joints; ++j) {
    const auto& J = model.joints[j];
    const std::string what = fmt::format("joints[{}]", j);
    const bool rev = build.tree_parent_side[j] == -1;
    const int parent = rev ? build.edges[j].b : build.edges[j].a;
    const int child = rev ? build.edges[j].a : build.edges[j].b;
    auto joint = model_joint(build, j, parent, child, rev);
    const auto* frame = dynamic_cast<const joints::FrameJoint*>(joint.get());
    const int m = joint->constraint_count();
    joints_.push_back({J.name.empty() ? what : J.name, model::to_string(J.type), std::move(joint),
                       frame, parent, child, build.tree_parent_side[j] != 0, rev, row, -1, nullptr,
                       build.driver_of_joint[j]});
    row += m;
  }
  // Shell supports after the model joints: joints_ is indexed like build.edges.
  for (std::size_t j = n_model_joints; j < build.edges.size(); ++j) {
    const Build::Support& S = build.supports[j - n_model_joints];
    joints_.push_back({S.name, S.type, S.joint, nullptr, build.edges[j].a, build.edges[j].b,
                       build.tree_parent_side[j] != 0, false, row, -1, nullptr, -1});
    row += S.joint->constraint_count();
  }
  for (ConstraintInstance& C : nary_) {
    C.row_offset = row;
    row += C.constraint->constraint_count();
  }
  m_all_ = row;
  for (JointInstance& J : joints_)
    J.rows = std::make_shared<joints::JointRows>(J.joint, J.parent, J.child, ground_);
  // Spherical joints whose ground point moves (joints `driver`): x_b − p₀ = p(t) − p₀, p₀ the
  // joint point at t = 0 (on the ground: the parent, the joint is not in the tree).
  for (std::size_t j = 0; j < n_model_joints; ++j) {
    const model::Joint& M = model.joints[j];
    JointInstance& J = joints_[j];
    if (M.type != model::JointType::spherical || M.driver.empty()) continue;
    const std::string what = fmt::format("joints[{}].driver", j);
    if (!J.frame || J.parent >= 0 || J.tree)
      fail(M.source, what, "a point driver moves the ground point of a spherical joint");
    const Vec3 p0 = J.frame->geometry().X_A;
    auto p = std::make_shared<std::array<loads::TimeFunction, 3>>();
    for (int k = 0; k < 3; ++k) {
      try {
        (*p)[static_cast<std::size_t>(k)] =
            loads::TimeFunction(M.driver[static_cast<std::size_t>(k)]);
      } catch (const std::invalid_argument& e) {
        fail(M.source, fmt::format("{}[{}]", what, k), e.what());
      }
    }
    const auto d = [p, p0](double t) -> VecX {
      return Vec3((*p)[0](t), (*p)[1](t), (*p)[2](t)) - p0;
    };
    const double off = d(0.0).norm();
    if (!(off <= kDriverTolerance * std::max(1.0, p0.norm())))
      fail(M.source, what,
           fmt::format("the driven point is ({:.6g}, {:.6g}, {:.6g}) at t = 0, but the joint point "
                       "is ({:.6g}, {:.6g}, {:.6g}): inconsistent by {:.3g}",
                       p0.x() + d(0.0)(0), p0.y() + d(0.0)(1), p0.z() + d(0.0)(2), p0.x(), p0.y(),
                       p0.z(), off));
    J.rows = std::make_shared<joints::JointRows>(J.joint, J.parent, J.child, ground_, d);
    rheonomic_ = true;
  }
  int nu = 0;
  for (int root : roots_) {
    root_nu_offset_.push_back(nu);
    root_width_.push_back(node_type(root).free_velocities());
    nu += root_width_.back();
  }
  for (int j : build.order) {
    joints_[j].nu_offset = nu;
    nu += joints_[j].joint->freedom_count();
  }
  tree_order_ = build.order;
  k_ = nu;
}

void System::mark_rotations() {
  for (std::size_t r = 0; r < roots_.size(); ++r)
    for (int c = 3; c < root_width_[r]; ++c) rotation_nu_.push_back(root_nu_offset_[r] + c);
  for (int j : tree_order_) {
    const JointInstance& J = joints_[static_cast<std::size_t>(j)];
    const joints::FreedomBlock B =
        J.joint->freedom_block(node_q(q0_, J.parent), node_q(q0_, J.child));
    for (int c = 0; c < J.joint->freedom_count(); ++c)
      if (B.col(c).tail<3>().squaredNorm() > 0.0) rotation_nu_.push_back(J.nu_offset + c);
  }
}

// Every joint holds at t = 0 (the frames are built to coincide; the points of sliding joints and
// the parent side of a joint given by point_b must lie where stated).
void System::check_assembled(const Build& build) const {
  const model::Model& model = build.model;
  const std::size_t n_model_joints = model.joints.size();
  const VecX c = constraints(q0_, 0.0);
  for (const auto& J : joints_) {
    const int rows = J.joint->constraint_count();
    if (rows == 0) continue;  // nothing to hold (and maxCoeff of nothing asserts)
    const double v = c.segment(J.row_offset, rows).cwiseAbs().maxCoeff();
    if (v <= 1e-9) continue;
    const std::size_t j = static_cast<std::size_t>(&J - joints_.data());
    const bool support = j >= n_model_joints;
    fail(support ? build.supports[j - n_model_joints].source : model.joints[j].source,
         support ? build.supports[j - n_model_joints].name : fmt::format("joints[{}]", j),
         fmt::format("not assembled at t = 0 (|Φ| = {:.3g})", v));
  }
}

// Loop-closing rows: independent ones by full-pivot LU of G_cut P_tree (IGA-thesis Alg. 5.1,
// Rem. 5.5); the rest are redundant and dropped. Cross-checked by pivoted QR. With the linear
// conditions of a static analysis (the KL supports: eliminated coordinates, multiplier rows C),
// independence is modulo those: G_cut with the eliminated columns removed and projected off
// the row space of C, so that a row a support already holds (a coupling row on a clamped edge,
// IGA-thesis §6.4.2.2) is dropped instead of making the static Newton matrix singular.
std::vector<SpMat> System::reselected_group_jacobians(const VecX& q) const {
  std::vector<SpMat> out;
  for (const ReselectedGroup& g : reselected_groups_) {
    std::vector<int> rows;
    for (int p : g.positions) rows.push_back(selected_rows_[static_cast<std::size_t>(p)]);
    out.push_back(modulo_linear_conditions(jacobian_rows(q, rows)));
  }
  return out;
}

void System::select_loop_rows() {
  std::vector<int> cut_all;
  for (const auto& J : joints_)
    if (!J.tree)
      for (int i = 0; i < J.joint->constraint_count(); ++i) cut_all.push_back(J.row_offset + i);
  for (const auto& C : nary_)
    if (C.constraint->compliance() == 0.0 && !C.constraint->reselected())
      for (int i = 0; i < C.constraint->constraint_count(); ++i)
        cut_all.push_back(C.row_offset + i);
  for (int i = 0; i < internal_rows_; ++i) selected_rows_.push_back(i);
  for (const auto& J : joints_)
    if (J.tree)
      for (int i = 0; i < J.joint->constraint_count(); ++i)
        selected_rows_.push_back(J.row_offset + i);
  if (!cut_all.empty()) {
    SpMat Gq = jacobian_rows(q0_, cut_all);
    if (!linear_.eliminated.empty() || linear_.multipliers() > 0) Gq = modulo_linear_conditions(Gq);
    const IndependentRows independent = independent_rows(SpMat(Gq * tree_null_space(q0_)));
    const std::vector<int>& keep = independent.rows;
    cut_rank_qr_ = independent.rank_qr;
    std::vector<bool> kept(cut_all.size(), false);
    for (int i : keep) kept[i] = true;
    for (std::size_t i = 0; i < cut_all.size(); ++i) {
      if (kept[i]) {
        cut_rows_.push_back(cut_all[i]);
        selected_rows_.push_back(cut_all[i]);
      } else {
        redundant_rows_.push_back(cut_all[i]);
      }
    }
  }
  // Perturbed Lagrange rows are all kept: their compliance makes the Newton matrix regular. Rows
  // reselected at every iterate are all kept here; the static solver picks among them.
  selected_compliance_ = VecX::Zero(static_cast<Eigen::Index>(selected_rows_.size()));
  for (const auto& C : nary_) {
    const double c = C.constraint->compliance();
    if (c == 0.0 && !C.constraint->reselected()) continue;
    ReselectedGroup group;
    group.constraint = static_cast<int>(&C - nary_.data());
    std::vector<int> rows;
    for (int i = 0; i < C.constraint->constraint_count(); ++i) {
      group.positions.push_back(static_cast<int>(selected_rows_.size()));
      rows.push_back(C.row_offset + i);
      selected_rows_.push_back(C.row_offset + i);
    }
    selected_compliance_.conservativeResize(static_cast<Eigen::Index>(selected_rows_.size()));
    selected_compliance_.tail(C.constraint->constraint_count()).setConstant(c);
    if (C.constraint->reselected()) reselected_groups_.push_back(std::move(group));
  }
  // The groups' counts at the reference, chosen together: interfaces meeting at a corner share
  // control points, where a row of one may follow from the kept rows of another.
  if (!reselected_groups_.empty()) {
    std::vector<int> counts(reselected_groups_.size(), -1);
    const auto chosen = select_group_rows(reselected_group_jacobians(q0_), counts);
    for (std::size_t g = 0; g < counts.size(); ++g) {
      reselected_groups_[g].rank = counts[g];
      reselected_groups_[g].reference_rows = chosen[g];
    }
  }
  // A dropped row holds only if the kept ones imply it; for a prescribed d(t) that is a property
  // of d the rank test cannot see, so a moving row must be independent.
  for (int r : redundant_rows_) {
    const int c = nary_of_row(r);
    if (c < 0 || !nary_[static_cast<std::size_t>(c)].constraint->rheonomic()) continue;
    const ConstraintInstance& C = nary_[static_cast<std::size_t>(c)];
    fail(C.source, C.name,
         fmt::format("row {} of the prescribed motion depends on the other rows of the model (it "
                     "acts on what other supports or joints already hold); a prescribed motion "
                     "must act on free coordinates only",
                     r - C.row_offset));
  }
}

SpMat System::modulo_linear_conditions(const SpMat& G) const {
  std::vector<bool> fixed(static_cast<std::size_t>(n()), false);
  for (int i : linear_.eliminated) fixed[static_cast<std::size_t>(i)] = true;
  const auto free_columns = [&](const SpMat& A) {
    SpMat out = A;
    out.prune(
        [&](Eigen::Index, Eigen::Index j, double) { return !fixed[static_cast<std::size_t>(j)]; });
    return out;
  };
  if (linear_.multipliers() == 0) return free_columns(G);
  // Each row g − Cᵀ (C Cᵀ)⁻¹ C g: its part outside the row space of C (on the free coordinates,
  // where C has full row rank: the static solver needs it).
  MatX Gf = MatX(free_columns(G));
  const SpMat C = free_columns(linear_.C);
  solve::NormalEquations normal;
  for (Eigen::Index i = 0; i < Gf.rows(); ++i) {
    const VecX g = Gf.row(i).transpose();
    Gf.row(i) -= (C.transpose() * normal.solve(C, C * g)).transpose();
  }
  return Gf.sparseView();
}

// Initial velocities: the admissible twist closest (least squares in twist components) to the
// given body velocities, within the null space of the loop-closing rows — or, with rheonomic
// rows, within the affine space G_cut P_tree ν = ḋ(0), the rate of their right-hand sides.
void System::set_initial_velocities(const model::Model& model) {
  VecX t_given = VecX::Zero(6 * node_count());
  for (int i = 0; i < static_cast<int>(model.bodies.size()); ++i) {
    t_given.segment<3>(6 * i) = model.bodies[i].velocity;
    t_given.segment<3>(6 * i + 3) = model.bodies[i].angular_velocity;
  }
  // Beams and shells: the rigid field v + ω × (x − p) at every node, then the per-node values. A
  // director node takes only the part of ω that turns its director (the spin about d moves
  // nothing), a point node (a control point) none, so that a rigid field is admissible as given.
  const auto set_twist = [&](int i, const Vec3& v, const Vec3& w) {
    t_given.segment<3>(6 * i) = v;
    const VecX qi = q0_.segment(q_offset(i), node_type(i).coordinates());
    switch (node_kind(i)) {
      case NodeKind::frame:
        t_given.segment<3>(6 * i + 3) = w;
        break;
      case NodeKind::director: {
        const Vec3 d = qi.segment<3>(3);
        t_given.segment<3>(6 * i + 3) = w - w.dot(d) * d;
        break;
      }
      case NodeKind::point:
        break;
    }
  };
  const auto set_field = [&](const model::NodeVelocities& f, const std::vector<int>& nodes,
                             const Vec3& first) {
    const Vec3 p = f.velocity_point.value_or(first);
    for (int i : nodes)
      set_twist(i, f.velocity + f.angular_velocity.cross(q0_.segment<3>(q_offset(i)) - p),
                f.angular_velocity);
    for (const auto& nv : f.nodes)
      set_twist(nodes[static_cast<std::size_t>(nv.node)], nv.velocity, nv.angular_velocity);
  };
  for (std::size_t b = 0; b < model.beams.size(); ++b)
    set_field(model.beams[b].initial, beams_[b].nodes, model.beams[b].start_point());
  for (std::size_t s = 0; s < model.shells.size(); ++s)
    set_field(model.shells[s].initial, shells_[s].nodes, model.shells[s].points.front());
  for (const model::KLShell& S : model.kl_shells) {
    const KLPatchInstance& P = kl_patch_of(S.name);
    if (P.renumbered && !S.initial.nodes.empty())
      fail(S.source, "kl_shells",
           fmt::format("node_velocities of \"{}\" name control points of its surface, but the "
                       "patch was refined to join a neighbour and numbers them differently: give "
                       "the rigid field (velocity, angular_velocity) only",
                       S.name));
    set_field(S.initial, P.nodes, q0_.segment<3>(q_offset(P.nodes.front())));
  }
  VecX rate;  // ḋ(0) of the cut rows, by a one-sided second-order difference (t ≥ 0 only)
  if (rheonomic_ && model.solver.analysis == model::Analysis::dynamic) {
    const double h = 1e-3 * model.solver.dt;
    const VecX dc =
        -(-3.0 * constraints(q0_, 0.0) + 4.0 * constraints(q0_, h) - constraints(q0_, 2.0 * h)) /
        (2.0 * h);
    rate.resize(cut_rank());
    for (int i = 0; i < cut_rank(); ++i) rate(i) = dc(cut_rows_[static_cast<std::size_t>(i)]);
    if (rate.lpNorm<Eigen::Infinity>() == 0.0) rate.resize(0);
  }
  VecX nu0 = VecX::Zero(k_);
  if (t_given.norm() > 0 || rate.size() > 0) {
    if (cut_rows_.empty()) {
      // min ½‖w − t‖² subject to (I − 𝒜) w = ℬ ν, as the sparse KKT system
      // [I (I−𝒜)ᵀ 0; (I−𝒜) 0 −ℬ; 0 −ℬᵀ 0] [w; μ; ν] = [t; 0; 0] (linear in node_count()).
      SpMat L, B, Pint;
      tree_factors(q0_, L, B, Pint);
      const int N6 = 6 * node_count();
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
      SpMat K(2 * N6 + k_, 2 * N6 + k_);
      K.setFromTriplets(t.begin(), t.end());
      VecX rhs = VecX::Zero(K.rows());
      rhs.head(N6) = t_given;
      const VecX z = solve::solve(K, rhs);
      nu0 = z.tail(k_);
      v0_error_ = (z.head(N6) - t_given).norm() / std::max(1.0, t_given.norm());
    } else {
      const MatX E = MatX(twist_map(q0_));
      const MatX Gc = MatX(jacobian_rows(q0_, cut_rows_) * tree_null_space(q0_));
      MatX W, U;
      solve::qr_range_and_null_space(Gc, W, U);
      VecX nu_p = VecX::Zero(k_);  // the particular solution in the range W
      if (rate.size() > 0) nu_p = W * (Gc * W).partialPivLu().solve(rate);
      nu0 = nu_p;
      if (U.cols() > 0) nu0 += U * solve::least_squares(E * U, t_given - E * nu_p);
      v0_error_ = (E * nu0 - t_given).norm() / std::max(1.0, t_given.norm());
    }
  }
  {
    SpMat L, B, Pint;
    tree_factors(q0_, L, B, Pint);
    v0_ = Pint * solve::solve(L, B * nu0);
  }
}

// Conditions on the stacked coordinates of `nodes` (point nodes, 3 each) as conditions on q.
// A multiplier row equal to one already there is dropped: patches joined at shared control
// points state the same condition twice where their supports meet (a symmetry edge across an
// interface), and the static solver needs rows of full rank.
void System::add_linear_constraints(const LinearConstraints& local, const std::vector<int>& nodes) {
  auto global = [&](int i) { return q_offset(nodes[static_cast<std::size_t>(i / 3)]) + i % 3; };
  for (std::size_t k = 0; k < local.eliminated.size(); ++k)
    linear_.eliminate(global(local.eliminated[k]),
                      k < local.eliminated_value.size() ? local.eliminated_value[k] : nullptr);
  if (local.multipliers() == 0) return;
  using Row = std::vector<std::pair<int, double>>;  // (column of q, value), by column
  const auto rows_of = [](const SpMat& C, const std::function<int(int)>& column) {
    std::vector<Row> out(static_cast<std::size_t>(C.rows()));
    for (int j = 0; j < C.outerSize(); ++j)
      for (SpMat::InnerIterator it(C, j); it; ++it)
        out[static_cast<std::size_t>(it.row())].emplace_back(column(j), it.value());
    for (Row& r : out) std::sort(r.begin(), r.end());
    return out;
  };
  const int m0 = linear_.multipliers();
  std::vector<Row> rows = rows_of(linear_.C, [](int j) { return j; });
  std::set<Row> seen(rows.begin(), rows.end());
  std::vector<int> kept;  // the local rows added
  std::vector<Row> local_rows = rows_of(local.C, global);
  for (std::size_t r = 0; r < local_rows.size(); ++r)
    if (seen.insert(local_rows[r]).second) {
      kept.push_back(static_cast<int>(r));
      rows.push_back(std::move(local_rows[r]));
    }
  Triplets t;
  for (std::size_t r = 0; r < rows.size(); ++r)
    for (const auto& [c, v] : rows[r]) t.emplace_back(static_cast<int>(r), c, v);
  linear_.C.resize(static_cast<int>(rows.size()), n());
  linear_.C.setFromTriplets(t.begin(), t.end());
  linear_.C.makeCompressed();
  const auto before = linear_.rhs;
  const auto added = local.rhs;
  linear_.rhs = [before, added, m0, kept](double time) {
    VecX d = VecX::Zero(m0 + static_cast<int>(kept.size()));
    if (before) d.head(m0) = before(time);
    if (added) {
      const VecX a = added(time);
      for (std::size_t k = 0; k < kept.size(); ++k) d(m0 + static_cast<int>(k)) = a(kept[k]);
    }
    return d;
  };
  linear_.row_labels.resize(static_cast<std::size_t>(m0));
  for (int r : kept)
    linear_.row_labels.push_back(static_cast<std::size_t>(r) < local.row_labels.size()
                                     ? local.row_labels[static_cast<std::size_t>(r)]
                                     : std::string());
  linear_.homogeneous.resize(static_cast<std::size_t>(m0), false);
  for (int r : kept) linear_.homogeneous.push_back(local.is_homogeneous(r));
}

}  // namespace isoflex::system
