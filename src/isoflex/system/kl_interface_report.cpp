#include "isoflex/system/kl_interface_report.hpp"

#include <fmt/format.h>

#include <cmath>

namespace isoflex::system {

std::string kl_interface_name(const KLInterfaceInstance& I) {
  const KLInterface& f = I.geometry;
  if (f.kind == KLInterfaceKind::knot_line)
    return fmt::format("{} -- {} at the knot line {} = {:g}", I.a, I.b, f.knot_along_v ? "η" : "ξ",
                       f.knot);
  return fmt::format("{} {} -- {} {}{}", I.a, loads::to_string(f.edge_a), I.b,
                     loads::to_string(f.edge_b), f.reversed ? " (reversed)" : "");
}

namespace {

std::string coupling_text(const System& sys, const KLInterfaceInstance& I) {
  switch (I.coupling) {
    case model::KLCoupling::c0:
      return "c0 (a hinge: no bending moment across)";
    case model::KLCoupling::bending_strip:
      return fmt::format("bending_strip (β = {:g}, E_s = {:g})", I.beta, I.young);
    case model::KLCoupling::perturbed_lagrange:
    case model::KLCoupling::strip_constraints:
    case model::KLCoupling::angle:
      break;
  }
  const int c = I.constraint_index;
  const std::string tied =
      I.tied_triples > 0
          ? fmt::format("{} straight triples' G¹ rows (5.36) eliminated by substitution",
                        I.tied_triples)
          : std::string();
  if (c < 0 && !tied.empty()) return fmt::format("angle ({})", tied);
  if (c < 0) return "none (no triple: every one degenerate)";
  const auto& rows = *sys.nary_constraints()[static_cast<std::size_t>(c)].constraint;
  if (I.coupling == model::KLCoupling::perturbed_lagrange)
    return fmt::format("perturbed_lagrange (α = {:g}, {} rows, all kept)", I.beta,
                       rows.constraint_count());
  return fmt::format("{} ({}{} rows{}, {} independent{})",
                     I.coupling == model::KLCoupling::angle ? "angle" : "strip_constraints",
                     tied.empty() ? "" : tied + "; ", rows.constraint_count(),
                     tied.empty() ? "" : " on the kinked triples", sys.independent_rows_of(c),
                     rows.reselected() ? " at the reference, chosen again in every load step" : "");
}

}  // namespace

std::vector<std::string> kl_interface_report(const System& sys) {
  const auto& faces = sys.kl_interfaces();
  const KLJoiningReport& joining = sys.kl_joining();
  std::vector<std::string> out;
  if (sys.kl_patches().size() < 2 && faces.empty() && joining.open_seams.empty()) return out;
  out.push_back(fmt::format(
      "kl interfaces    {} (edges coincide within {:.3g}; their control points are one node "
      "each; a closed patch's seam and a C⁰ knot line inside a patch are interfaces of the patch "
      "with itself)",
      faces.size(), joining.tolerance));
  for (const KLInterfaceInstance& I : faces) {
    const KLInterface& f = I.geometry;
    const std::string angle = f.triples() == 0 ? std::string("-")
                              : std::abs(f.angle_max - f.angle_min) < 0.05
                                  ? fmt::format("{:.1f}°", f.angle_min)
                                  : fmt::format("{:.1f}° … {:.1f}°", f.angle_min, f.angle_max);
    const std::string degenerate =
        f.degenerate_triples > 0
            ? fmt::format(" (+{} degenerate at a pole, left out)", f.degenerate_triples)
            : std::string();
    out.push_back(fmt::format("  {}: {} triples{}, angle {}, coupling {}", kl_interface_name(I),
                              f.triples(), degenerate, angle, coupling_text(sys, I)));
  }
  for (const std::string& r : joining.refinements) out.push_back("  made conforming: " + r);
  for (const std::string& s : joining.open_seams)
    out.push_back("  seam left open (kl_shells seam: open): " + s);
  return out;
}

}  // namespace isoflex::system
