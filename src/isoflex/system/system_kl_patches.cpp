// The Kirchhoff–Love patches of a model in the System (docs/model-files.md "kl_shells",
// "kl_interfaces"; docs/theory/multipatch.md): the patches joined along their common edges, a
// closed patch along its own seam, and every patch across its C⁰ knot lines
// (system/kl_interfaces.hpp), one point node per distinct control point, each patch an element
// with its loads, and the bending strips of the interfaces as elements. Nothing below needs the
// two sides of an interface to be different patches: a coupling works on the system nodes of
// the triples, which are distinct on a seam (the seam's two rows are one node, the triple's
// inner points are the next rows on either side) and on a knot line (columns c − 1, c, c + 1).
#include <fmt/format.h>

#include <algorithm>

#include "isoflex/elements/bending_strip.hpp"
#include "isoflex/joints/linear_rows.hpp"
#include "isoflex/joints/triple_continuity_rows.hpp"
#include "isoflex/loads/patch_load_set.hpp"
#include "isoflex/system/kl_interface_report.hpp"
#include "isoflex/system/kl_model.hpp"
#include "isoflex/system/strip_force_rows.hpp"
#include "isoflex/system/system.hpp"

namespace isoflex::system {

const KLPatchInstance& System::kl_patch_of(const std::string& shell) const {
  const auto it = std::find_if(kl_patches_.begin(), kl_patches_.end(),
                               [&](const KLPatchInstance& P) { return P.name == shell; });
  if (it == kl_patches_.end()) throw std::logic_error("no kl patch \"" + shell + "\"");
  return *it;
}

// A point node "<shell>[A]" per control point A — one node for the coincident control points of
// joined patches, named after the first patch (C⁰, IGA-thesis (4.36c), by shared unknowns rather
// than the equality rows B_C0 of (4.37b): the same solution with fewer unknowns and no scaling
// (4.42) to choose) — the patch as one element over its nodes, its kl_loads.
void System::add_kl_patches(const model::Model& m) {
  if (m.kl_shells.empty()) return;
  std::vector<geometry::NurbsSurface> surfaces;
  std::vector<std::string> names;
  for (std::size_t k = 0; k < m.kl_shells.size(); ++k) {
    const model::KLShell& S = m.kl_shells[k];
    if (m.solver.analysis == model::Analysis::dynamic && !(S.density > 0.0))
      compile_fail(S.source, fmt::format("kl_shells[{}].material.density", k),
                   "a dynamic run needs the shell's mass: give a density > 0, or "
                   "solver.analysis: static for its equilibrium");
    surfaces.push_back(kl_surface(m, S));
    names.push_back(S.name);
  }
  KLJoinOptions options;
  for (const model::KLShell& S : m.kl_shells) options.open_seam.push_back(S.open_seam);
  KLPatchJoining J;
  try {
    J = join_kl_patches(std::move(surfaces), m.kl_interfaces.tolerance, names, options);
  } catch (const KLInterfaceError& e) {
    compile_fail(m.kl_shells[static_cast<std::size_t>(e.patch_b)].source,
                 fmt::format("kl_shells[{}]{}", e.patch_b, e.key.empty() ? "" : "." + e.key),
                 e.what());
  }
  kl_joining_ = {J.tolerance, J.refinements, J.open_seams};
  const int group = static_cast<int>(m.beams.size() + m.shells.size());
  std::vector<int> node_of_point;  // by point group
  for (const auto& g : J.point_group)
    for (int id : g) node_of_point.resize(std::max<std::size_t>(node_of_point.size(), id + 1), -1);
  for (std::size_t k = 0; k < m.kl_shells.size(); ++k) {
    const model::KLShell& S = m.kl_shells[k];
    const geometry::NurbsSurface& g = J.surfaces[k];
    KLPatchInstance inst;
    inst.name = S.name;
    inst.renumbered = g.points.size() != kl_surface(m, S).points.size();
    auto patch = kl_patch(m, static_cast<int>(k), g);
    for (int A = 0; A < patch->control_points(); ++A) {
      int& node = node_of_point[static_cast<std::size_t>(J.point_group[k][A])];
      if (node < 0) {
        node = node_count();
        add_node(NodeKind::point, g.points[A], fmt::format("{}[{}]", S.name, A),
                 group + static_cast<int>(k));
      }
      inst.nodes.push_back(node);
    }
    auto element = std::make_unique<elements::KLPatchElement>(patch, kl_kinematics(m), inst.nodes);
    inst.element = element.get();
    inst.element_index = static_cast<int>(elements_.size());
    elements_.push_back(std::move(element));
    loads::PatchLoads patch_loads = kl_patch_loads(m, S, g);
    if (!patch_loads.empty()) {
      // The element's pattern is kept only for a follower's tangent (it is as large as the patch).
      const bool follower = std::any_of(patch_loads.begin(), patch_loads.end(),
                                        [](const auto& L) { return L->follower(); });
      loads_.push_back(std::make_shared<loads::PatchLoadSet>(
          inst.nodes, std::move(patch_loads),
          follower ? inst.element->pattern() : loads::Load::SpMat()));
    }
    kl_patches_.push_back(std::move(inst));
  }
  for (KLInterface& f : J.interfaces) {
    KLInterfaceInstance I;
    I.a = m.kl_shells[static_cast<std::size_t>(f.a)].name;
    I.b = m.kl_shells[static_cast<std::size_t>(f.b)].name;
    const std::vector<int>&na = kl_patches_[static_cast<std::size_t>(f.a)].nodes,
          &nb = kl_patches_[static_cast<std::size_t>(f.b)].nodes;
    for (int k = 0; k < f.triples(); ++k)
      for (int node : {na[f.inner_a[k]], na[f.shared_a[k]], nb[f.inner_b[k]]})
        I.triple_nodes.push_back(node);
    I.geometry = std::move(f);
    kl_interfaces_.push_back(std::move(I));
  }
  add_kl_couplings(m);
}

// The coupling of each interface (kl_interfaces: model-wide, or per pair of shells):
// - bending_strip: the strip of IGA-thesis §4.4.2 over its triples, E_s = β E (4.40) with E and
//   the thickness of the stiffer patch (the larger E t³), so that β is relative to the patches'
//   own bending stiffness;
// - strip_constraints (AF-BS, §5.1): the forces of that strip with β = 1 as constraint rows
//   (5.5b), f_s = K_s (x − X) in a linear analysis, whose redundant rows (Conjecture 5.1, the
//   clamped boundary) are dropped with the other loop rows by full-pivot LU (Alg. 5.1); in a
//   nonlinear static analysis the strip's nonlinear forces (StripForceRows), chosen again at the
//   start of every load step (integrate/static_equilibrium.cpp);
// - perturbed_lagrange (§5.1.3.2): those rows perturbed, ŝ f_s − (ŝ/α₁) λ = 0 (5.24b) with
//   α₁ = beta; all kept (the compliance makes the Newton matrix regular). Eliminating λ = α₁ f_s
//   leaves the penalty ŝ α₁ K_sᵀ K_s (x − X) in a linear analysis (Theorem 5.1), ŝ α₁ G_sᵀ f_s in a
//   nonlinear static one (StripForceRows with a compliance);
// - angle (AF-D, §5.2): the continuity constraints on each triple (TripleContinuityRows); in a
//   static analysis the straight triples' rows (5.36), linear, are tied rows of the linear
//   conditions instead, eliminated by the static solver (LinearConstraints::tied).
// Constraint rows are scaled as in (4.42)/(5.5) in a static analysis: to the size
// s = max ‖∇f_i‖∞ of the patches' stiffness at the reference, so that the Newton matrix is not
// badly scaled by them.
void System::add_kl_couplings(const model::Model& m) {
  const model::KLInterfaces& settings = m.kl_interfaces;
  for (std::size_t i = 0; i < settings.pairs.size(); ++i) {
    const model::KLInterfacePair& p = settings.pairs[i];
    const bool found = std::any_of(
        kl_interfaces_.begin(), kl_interfaces_.end(), [&](const KLInterfaceInstance& I) {
          return (I.a == p.a && I.b == p.b) || (I.a == p.b && I.b == p.a);
        });
    if (!found)
      compile_fail(
          p.source, fmt::format("kl_interfaces.pairs[{}]", i),
          p.a == p.b
              ? fmt::format("\"{}\" has no interface with itself: no joined seam (two of its edges "
                            "coinciding within the tolerance {:.3g}) and no C⁰ knot line",
                            p.a, kl_joining_.tolerance)
              : fmt::format("\"{}\" and \"{}\" have no common edge (within the tolerance {:.3g})",
                            p.a, p.b, kl_joining_.tolerance));
  }
  const auto shell = [&](const std::string& name) -> const model::KLShell& {
    return *std::find_if(m.kl_shells.begin(), m.kl_shells.end(),
                         [&](const model::KLShell& s) { return s.name == name; });
  };
  const auto position = [&](int node) {  // q₀ is still being built
    return Vec3(Eigen::Map<const Vec3>(q0_build_.data() + nodes_[node].q_offset));
  };
  const bool linear = m.solver.linear && m.solver.analysis == model::Analysis::statics;
  double scale = -1.0;  // s of (4.42), computed when a coupling needs it
  const auto row_scale = [&] {
    if (scale < 0.0) {
      scale = 0.0;
      for (const KLPatchInstance& P : kl_patches_) {
        const elements::KLShellPatch& patch = P.element->patch();
        SpMat K;
        patch.internal_force(patch.reference_positions(), elements::KLKinematics::linear, &K);
        for (int j = 0; j < K.outerSize(); ++j)  // ‖K‖∞ = ‖K‖₁ (symmetric)
          scale = std::max(scale, K.col(j).cwiseAbs().sum());
      }
    }
    return scale;
  };
  for (KLInterfaceInstance& I : kl_interfaces_) {
    I.coupling = settings.coupling;
    I.beta = settings.beta;
    model::Source source = settings.source;
    for (const model::KLInterfacePair& p : settings.pairs)
      if ((I.a == p.a && I.b == p.b) || (I.a == p.b && I.b == p.a)) {
        I.coupling = p.coupling;
        I.beta = p.beta;
        source = p.source;
      }
    if (I.coupling == model::KLCoupling::c0) continue;
    const std::string what =
        fmt::format("kl_interfaces ({})",
                    I.a != I.b ? fmt::format("{} -- {}", I.a, I.b) : kl_interface_name(I));
    if (I.geometry.triples() == 0) continue;  // all triples degenerate (at a pole)
    const model::KLShell &sa = shell(I.a), &sb = shell(I.b);
    const model::KLShell& stiff = sa.E * sa.thickness * sa.thickness * sa.thickness >=
                                          sb.E * sb.thickness * sb.thickness * sb.thickness
                                      ? sa
                                      : sb;
    std::vector<int> nodes = I.triple_nodes;
    std::vector<std::array<Vec3, 3>> triples;
    for (std::size_t k = 0; k < nodes.size(); k += 3)
      triples.push_back({position(nodes[k]), position(nodes[k + 1]), position(nodes[k + 2])});
    const auto strip = [&](double young) {
      try {
        return elements::bending_strip(triples, young, stiff.thickness);
      } catch (const std::invalid_argument& e) {
        compile_fail(source, what, fmt::format("the bending strip: {}", e.what()));
      }
    };
    if (I.coupling == model::KLCoupling::bending_strip) {
      I.young = I.beta * stiff.E;
      I.element_index = static_cast<int>(elements_.size());
      elements_.push_back(std::make_unique<elements::KLPatchElement>(
          strip(I.young), kl_kinematics(m), std::move(nodes)));
      continue;
    }
    VecX Q(3 * static_cast<Eigen::Index>(nodes.size()));
    for (std::size_t k = 0; k < nodes.size(); ++k)
      Q.segment<3>(3 * static_cast<Eigen::Index>(k)) = position(nodes[k]);
    // Rows scaled so that their largest reference entry is s in a static analysis, 1 in a
    // dynamic one, whose integrators scale the rows themselves (the DAE schemes by (2.56)–(2.58),
    // the reduced energy–momentum formulations by (2/Δt) × the mean mass), as they do the rows
    // of the supports and joints, whose entries are of order 1.
    const auto scaled = [&](const MatX& G) {
      const double norm = G.cwiseAbs().maxCoeff();
      if (!(norm > 0.0)) return 1.0;
      return (m.solver.analysis == model::Analysis::statics ? row_scale() : 1.0) / norm;
    };
    std::shared_ptr<const joints::Constraint> rows;
    const bool perturbed = I.coupling == model::KLCoupling::perturbed_lagrange;
    if (I.coupling == model::KLCoupling::strip_constraints || perturbed) {
      const bool statics = m.solver.analysis == model::Analysis::statics;
      if (!statics)
        compile_fail(source, what,
                     fmt::format("coupling {} is built for static analyses so far: its rows, the "
                                 "strip's forces (5.5b), have no discrete derivative for the time "
                                 "integrators",
                                 perturbed ? "perturbed_lagrange" : "strip_constraints"));
      I.young = stiff.E;
      const auto s = strip(I.young);
      SpMat K;
      s->internal_force(s->reference_positions(), elements::KLKinematics::linear, &K);
      MatX C(K);
      const double factor = scaled(C);
      if (linear) {
        auto r = std::make_shared<joints::LinearRows>(nodes, factor * C, Q);
        // (5.24b): ŝ f_s − (ŝ/α₁) λ = 0 with the rows' scale ŝ, so λ = α₁ f_s.
        if (perturbed) r->set_compliance(factor / I.beta);
        rows = std::move(r);
      } else {
        rows =
            std::make_shared<StripForceRows>(s, nodes, factor, perturbed ? factor / I.beta : 0.0);
      }
    } else {
      const joints::TripleContinuityRows unit(nodes, Q);
      const double factor = scaled(unit.jacobian(Q));
      if (m.solver.analysis == model::Analysis::statics) {
        // The straight triples' rows are linear: tied rows, eliminated by the static solver
        // (x_s or a neighbour written in terms of the others), which leaves the Newton matrix
        // symmetric positive definite when no triple is kinked.
        std::vector<int> kinked;
        for (std::size_t k = 0; k < nodes.size(); k += 3) {
          const auto at = [&](std::size_t i) { return position(nodes[k + i]); };
          const auto tied = joints::TripleContinuityRows::straight_rows(at(0), at(1), at(2));
          if (!tied) {
            kinked.insert(kinked.end(), nodes.begin() + static_cast<std::ptrdiff_t>(k),
                          nodes.begin() + static_cast<std::ptrdiff_t>(k) + 3);
            continue;
          }
          for (int d = 0; d < 3; ++d) {
            std::vector<std::pair<int, double>> row;
            for (int p = 0; p < 3; ++p)
              row.emplace_back(q_offset(nodes[k + static_cast<std::size_t>(p)]) + d,
                               (*tied)[static_cast<std::size_t>(p)]);
            linear_.tied.push_back(std::move(row));
          }
          ++I.tied_triples;
        }
        if (kinked.empty()) continue;
        nodes = std::move(kinked);
        Q.resize(3 * static_cast<Eigen::Index>(nodes.size()));
        for (std::size_t k = 0; k < nodes.size(); ++k)
          Q.segment<3>(3 * static_cast<Eigen::Index>(k)) = position(nodes[k]);
      }
      // A linear analysis takes the rows linearized at the reference, as it does every equation.
      if (linear)
        rows = std::make_shared<joints::LinearRows>(
            nodes, factor * joints::TripleContinuityRows(nodes, Q).jacobian(Q), Q);
      else
        rows = std::make_shared<joints::TripleContinuityRows>(nodes, Q, factor);
    }
    I.constraint_index = static_cast<int>(nary_.size());
    nary_.push_back({what,
                     I.coupling == model::KLCoupling::angle ? "angle_constraints"
                     : perturbed                            ? "perturbed_strip_constraints"
                                                            : "strip_constraints",
                     std::move(rows), 0, source});
  }
}

}  // namespace isoflex::system
