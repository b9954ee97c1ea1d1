// The Kirchhoff–Love patches of a model in the System (docs/model-files.md "kl_shells",
// "kl_interfaces"; docs/theory/multipatch.md): the patches joined along their common edges
// (system/kl_interfaces.hpp), one point node per distinct control point, each patch an element
// with its loads, and the bending strips of the interfaces as elements.
#include <fmt/format.h>

#include <algorithm>

#include "isoflex/elements/bending_strip.hpp"
#include "isoflex/loads/patch_load_set.hpp"
#include "isoflex/system/kl_model.hpp"
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
  KLPatchJoining J;
  try {
    J = join_kl_patches(std::move(surfaces), m.kl_interfaces.tolerance, names);
  } catch (const KLInterfaceError& e) {
    compile_fail(m.kl_shells[static_cast<std::size_t>(e.patch_b)].source,
                 fmt::format("kl_shells[{}]", e.patch_b), e.what());
  }
  kl_joining_ = {J.tolerance, J.refinements};
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
    I.geometry = std::move(f);
    kl_interfaces_.push_back(std::move(I));
  }
  add_kl_strips(m);
}

// The coupling of each interface (kl_interfaces: model-wide, or per pair of shells) and, for
// bending_strip, the strip of IGA-thesis §4.4.2 over its triples: E_s = β E (4.40) with E and the
// thickness of the stiffer patch (the larger E t³), so that β is relative to the patches' own
// bending stiffness.
void System::add_kl_strips(const model::Model& m) {
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
          fmt::format("\"{}\" and \"{}\" have no common edge (within the tolerance {:.3g})", p.a,
                      p.b, kl_joining_.tolerance));
  }
  const auto shell = [&](const std::string& name) -> const model::KLShell& {
    return *std::find_if(m.kl_shells.begin(), m.kl_shells.end(),
                         [&](const model::KLShell& s) { return s.name == name; });
  };
  for (KLInterfaceInstance& I : kl_interfaces_) {
    I.coupling = settings.coupling;
    I.beta = settings.beta;
    for (const model::KLInterfacePair& p : settings.pairs)
      if ((I.a == p.a && I.b == p.b) || (I.a == p.b && I.b == p.a)) {
        I.coupling = p.coupling;
        I.beta = p.beta;
      }
    if (I.coupling != model::KLCoupling::bending_strip) continue;
    const model::KLShell &sa = shell(I.a), &sb = shell(I.b);
    const model::KLShell& stiff = sa.E * sa.thickness * sa.thickness * sa.thickness >=
                                          sb.E * sb.thickness * sb.thickness * sb.thickness
                                      ? sa
                                      : sb;
    I.young = I.beta * stiff.E;
    const KLInterface& f = I.geometry;
    const KLPatchInstance &pa = kl_patch_of(I.a), &pb = kl_patch_of(I.b);
    std::vector<std::array<Vec3, 3>> triples;
    std::vector<int> nodes;
    for (int k = 0; k < f.triples(); ++k)
      for (int node : {pa.nodes[f.inner_a[k]], pa.nodes[f.shared_a[k]], pb.nodes[f.inner_b[k]]})
        nodes.push_back(node);
    const auto position = [&](int node) {  // q₀ is still being built
      return Vec3(Eigen::Map<const Vec3>(q0_build_.data() + nodes_[node].q_offset));
    };
    for (std::size_t k = 0; k < nodes.size(); k += 3)
      triples.push_back({position(nodes[k]), position(nodes[k + 1]), position(nodes[k + 2])});
    std::shared_ptr<elements::KLShellPatch> strip;
    try {
      strip = elements::bending_strip(triples, I.young, stiff.thickness);
    } catch (const std::invalid_argument& e) {
      compile_fail(
          settings.source, "kl_interfaces",
          fmt::format("the bending strip between \"{}\" and \"{}\": {}", I.a, I.b, e.what()));
    }
    I.element_index = static_cast<int>(elements_.size());
    elements_.push_back(
        std::make_unique<elements::KLPatchElement>(strip, kl_kinematics(m), std::move(nodes)));
  }
}

}  // namespace isoflex::system
