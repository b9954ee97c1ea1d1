#include "isoflex/app/cad_info.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <vector>

#include "isoflex/io/cad/cad_checks.hpp"
#include "isoflex/io/cad/cad_reader.hpp"

namespace isoflex::app {

namespace {

// Distinct knots with their multiplicities: 0 0 0 0.5 1 1 1 → "0^3 0.5 1^3".
std::string compact_knots(const std::vector<double>& knots) {
  std::string s;
  for (std::size_t a = 0; a < knots.size();) {
    std::size_t b = a;
    while (b < knots.size() && knots[b] == knots[a]) ++b;
    s += fmt::format("{}{:.10g}", s.empty() ? "" : " ", knots[a]);
    if (b - a > 1) s += fmt::format("^{}", b - a);
    a = b;
  }
  return s;
}

void print_patch(const io::CadPatch& p, const std::vector<io::Finding>& findings,
                 std::ostream& out) {
  const geometry::NurbsSurface& s = p.surface;
  out << fmt::format("\npatch {}  \"{}\"{}\n", p.index, p.name,
                     p.entity.empty() ? "" : "  (" + p.entity + ")");
  out << fmt::format("  surface         {}{}, {}, {}\n", p.surface_type,
                     p.converted ? " (converted to B-spline)" : "",
                     p.trimmed ? "trimmed (trimming ignored)" : "untrimmed",
                     p.reversed_orientation ? "face reversed" : "face forward");
  out << fmt::format("  degrees         {} x {}\n", s.u.degree(), s.v.degree());
  out << fmt::format("  control points  {} x {} = {}\n", s.n_u(), s.n_v(), s.n_u() * s.n_v());
  out << fmt::format("  knots u         {}\n", compact_knots(s.u.knots()));
  out << fmt::format("  knots v         {}\n", compact_knots(s.v.knots()));
  if (!s.weights.empty()) {
    const auto [lo, hi] = std::minmax_element(s.weights.begin(), s.weights.end());
    out << fmt::format("  rational        {}, weights {:.10g} .. {:.10g}\n",
                       s.is_rational() ? "yes" : "no", *lo, *hi);
  }
  if (!s.points.empty()) {
    Vec3 lo = s.points.front(), hi = lo;
    for (const Vec3& x : s.points) {
      lo = lo.cwiseMin(x);
      hi = hi.cwiseMax(x);
    }
    out << fmt::format(
        "  bounding box    [{:.10g}, {:.10g}] x [{:.10g}, {:.10g}] x [{:.10g}, {:.10g}]"
        "  (of the control points)\n",
        lo.x(), hi.x(), lo.y(), hi.y(), lo.z(), hi.z());
  }
  if (findings.empty()) {
    out << "  findings        none: fit for a Kirchhoff–Love shell as it is\n";
    return;
  }
  out << fmt::format("  findings        {}\n", findings.size());
  for (const auto& f : findings) {
    out << fmt::format("    {:<8} {}\n", io::to_string(f.severity), f.issue);
    out << fmt::format("    {:<8} fix: {}\n", "", f.fix);
  }
}

}  // namespace

int cad_info_command(const std::string& file, std::ostream& out, std::ostream& err) {
  io::CadModel model;
  try {
    model = io::read_cad(file);
  } catch (const io::CadError& e) {
    err << "error: " << e.what() << "\n";
    return 2;
  }
  out << fmt::format("file            {}\n", file);
  out << fmt::format("format          {}, length unit {} (coordinates as written in the file)\n",
                     io::to_string(model.format),
                     model.length_unit.empty() ? "not stated" : model.length_unit);
  out << fmt::format("patches         {}\n", model.patches.size());
  int n_error = 0, n_warning = 0, n_info = 0;
  for (const auto& p : model.patches) {
    const auto findings = io::check_patch(p);
    for (const auto& f : findings)
      ++(f.severity == io::Severity::error     ? n_error
         : f.severity == io::Severity::warning ? n_warning
                                               : n_info);
    print_patch(p, findings, out);
  }
  out << fmt::format("\nsummary         {} patch{}: {} error{}, {} warning{}, {} note{}\n",
                     model.patches.size(), model.patches.size() == 1 ? "" : "es", n_error,
                     n_error == 1 ? "" : "s", n_warning, n_warning == 1 ? "" : "s", n_info,
                     n_info == 1 ? "" : "s");
  return 0;
}

}  // namespace isoflex::app
