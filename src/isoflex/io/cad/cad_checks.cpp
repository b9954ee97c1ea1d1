#include "isoflex/io/cad/cad_checks.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace isoflex::io {

const char* to_string(Severity s) {
  switch (s) {
    case Severity::info:
      return "info";
    case Severity::warning:
      return "warning";
    case Severity::error:
      return "error";
  }
  return "?";
}

namespace {

std::string join(const std::vector<double>& xs) {
  std::string s;
  for (double x : xs) s += fmt::format("{}{:g}", s.empty() ? "" : ", ", x);
  return s;
}

void check_direction(const geometry::KnotVector& kv, const char* dir, std::vector<Finding>& out) {
  const int p = kv.degree();
  if (p < 2)
    out.push_back({Severity::warning,
                   fmt::format("degree {} in {}: the basis is only C⁰ between elements, not "
                               "enough for Kirchhoff–Love shells (they need C¹, degree ≥ 2)",
                               p, dir),
                   fmt::format("elevate the degree in {} to 2 or more (degree elevation in the "
                               "model file; exact, the geometry does not change)",
                               dir)});
  // Only a note: the model reader clamps such a patch exactly (geometry/clamping.hpp) before
  // anything else uses it, so that the boundary passes through the boundary control points.
  if (!kv.is_open())
    out.push_back({Severity::info,
                   fmt::format("the knot vector in {} is not open (end knots not repeated {} "
                               "times: an unclamped or periodic B-spline, whose boundary does not "
                               "pass through the boundary control points)",
                               dir, p + 1),
                   fmt::format("nothing to do: a model file's surface clamps it exactly (knot "
                               "insertion at the ends of the domain [{:g}, {:g}] in {}; the same "
                               "surface and parametrization)",
                               kv.front(), kv.back(), dir)});

  std::vector<double> c0, broken;
  for (double b : kv.breakpoints()) {
    if (!(b > kv.front() && b < kv.back())) continue;
    const int m = kv.multiplicity(b);
    if (m > p)
      broken.push_back(b);
    else if (m >= p && p >= 2)  // degree 1 is reported above; every interior knot is C⁰ there
      c0.push_back(b);
  }
  if (!c0.empty())
    out.push_back(
        {Severity::warning,
         fmt::format("C⁰ line{} inside the patch at {} = {} (knot multiplicity ≥ degree {}): "
                     "the surface may have a kink there and the basis is only C⁰ across it",
                     c0.size() > 1 ? "s" : "", dir, join(c0), p),
         "a Kirchhoff–Love shell on the patch couples the two sides of the line like an "
         "interface between patches (kl_interfaces: its coupling, a bending strip by default); "
         "if the surface is smooth there, removing the repeated knots (knot removal in the CAD "
         "tool) gives C¹ instead"});
  if (!broken.empty())
    out.push_back(
        {Severity::error,
         fmt::format("the patch is split at {} = {} (knot multiplicity > degree {}): "
                     "the basis is discontinuous there and the pieces are not joined",
                     dir, join(broken), p),
         fmt::format("split the patch at {} = {} into separate patches", dir, join(broken))});
}

// An edge whose boundary control points all coincide (a degenerate, e.g. triangular, patch).
void check_collapsed_edges(const geometry::NurbsSurface& s, std::vector<Finding>& out) {
  if (s.points.empty() || !s.u.is_open() || !s.v.is_open()) return;
  Vec3 lo = s.points.front(), hi = lo;
  for (const Vec3& x : s.points) {
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  const double tol = 1e-12 * std::max(1.0, (hi - lo).norm());
  const int nu = s.n_u(), nv = s.n_v();
  auto collapsed = [&](int i0, int j0, int di, int dj, int n) {
    const Vec3& a = s.points[static_cast<std::size_t>(s.index(i0, j0))];
    for (int k = 1; k < n; ++k)
      if ((s.points[static_cast<std::size_t>(s.index(i0 + k * di, j0 + k * dj))] - a).norm() > tol)
        return false;
    return true;
  };
  std::vector<std::string> edges;
  if (collapsed(0, 0, 1, 0, nu)) edges.push_back("v = " + fmt::format("{:g}", s.v.front()));
  if (collapsed(0, nv - 1, 1, 0, nu)) edges.push_back("v = " + fmt::format("{:g}", s.v.back()));
  if (collapsed(0, 0, 0, 1, nv)) edges.push_back("u = " + fmt::format("{:g}", s.u.front()));
  if (collapsed(nu - 1, 0, 0, 1, nv)) edges.push_back("u = " + fmt::format("{:g}", s.u.back()));
  if (edges.empty()) return;
  std::string list;
  for (const auto& e : edges) list += (list.empty() ? "" : ", ") + e;
  out.push_back({Severity::warning,
                 fmt::format("collapsed edge{} at {}: all its control points coincide, so x_u × "
                             "x_v vanishes there (singular parametrization)",
                             edges.size() > 1 ? "s" : "", list),
                 "remodel the region with four-sided patches that have no degenerate edge"});
}

// Numbers a double cannot carry through the basis and its second derivatives: a parameter domain
// that is tiny (absolutely, or relative to the size of its knots: the knot differences of the
// Cox–de Boor quotients keep few digits, a subnormal domain gives NaN), knot spans tiny against
// the domain (the basis derivatives scale like 1/h, 1/h²), and weights whose products w·x in the
// homogeneous coordinates of refinement overflow or lose their digits.
void check_numbers(const geometry::NurbsSurface& s, std::vector<Finding>& out) {
  for (const auto& [kv, dir] : {std::pair{&s.u, "u"}, std::pair{&s.v, "v"}}) {
    const double a = kv->front(), b = kv->back(), w = b - a;
    const double size = std::max(std::abs(a), std::abs(b));
    if (!(w > 1e-100) || !(w > 1e-8 * size) || !(size < 1e100)) {
      out.push_back({Severity::error,
                     fmt::format("the parameter domain in {} is [{:g}, {:g}]: too small (or too "
                                 "far from 0) for the basis to be evaluated in double precision",
                                 dir, a, b),
                     fmt::format("re-export the surface with the parameter range of {} "
                                 "normalized, e.g. to [0, 1]",
                                 dir)});
      continue;
    }
    double h_min = w;
    for (std::size_t k = 1; k < kv->knots().size(); ++k)
      if (const double h = kv->knots()[k] - kv->knots()[k - 1]; h > 0) h_min = std::min(h_min, h);
    if (h_min < 1e-8 * w)
      out.push_back({Severity::warning,
                     fmt::format("a knot span in {} is {:g} of the parameter domain: the basis "
                                 "and its derivatives are ill-conditioned there",
                                 dir, h_min / w),
                     "remove the nearly repeated knot (knot removal in the CAD tool) or make it "
                     "an exact repeated knot"});
  }
  const auto [lo, hi] = std::minmax_element(s.weights.begin(), s.weights.end());
  if (lo == s.weights.end() || !(*lo > 0) || !std::isfinite(*hi)) return;  // reported below
  if (*lo < 1e-100 || *hi > 1e100)
    out.push_back({Severity::error,
                   fmt::format("weights from {:g} to {:g}: the homogeneous coordinates w·x "
                               "overflow or lose their digits",
                               *lo, *hi),
                   "re-export the surface with weights scaled to about 1 (a NURBS surface is "
                   "unchanged when all its weights are multiplied by one factor)"});
  else if (*hi > 1e8 * *lo)
    out.push_back({Severity::warning,
                   fmt::format("weights from {:g} to {:g} (ratio {:.1e}): the rational basis is "
                               "ill-conditioned",
                               *lo, *hi, *hi / *lo),
                   "re-export the surface with a better-conditioned parametrization"});
}

}  // namespace

std::vector<Finding> check_patch(const CadPatch& patch) {
  const geometry::NurbsSurface& s = patch.surface;
  std::vector<Finding> out;
  if (patch.trimmed)
    out.push_back({Severity::warning,
                   "trimmed face: the trimming curves are ignored and the whole untrimmed "
                   "surface is used",
                   "split the face in the CAD tool into untrimmed four-sided patches (or rebuild "
                   "the surface on the face's boundary) before exporting"});
  check_direction(s.u, "u", out);
  check_direction(s.v, "v", out);
  check_collapsed_edges(s, out);
  check_numbers(s, out);
  if (patch.reversed_orientation)
    out.push_back({Severity::warning,
                   "the face is reversed: its normal is −(x_u × x_v), the parameter domain is "
                   "left-handed with respect to the face orientation; the shell normal "
                   "x_u × x_v points to the other side",
                   "reverse one parameter direction or swap u and v (in the CAD tool or the "
                   "model file) if the side of the normal matters (pressure, contact, coupling "
                   "with consistently oriented patches)"});

  int bad = 0;
  double w_min = std::numeric_limits<double>::infinity();
  for (double w : s.weights) {
    if (!(w > 0) || !std::isfinite(w)) ++bad;
    w_min = std::min(w_min, w);
  }
  if (bad > 0)
    out.push_back({Severity::error,
                   fmt::format("{} of {} weights are not positive and finite (smallest {:g}): "
                               "the rational basis is not defined",
                               bad, s.weights.size(), w_min),
                   "re-export the surface with positive weights"});
  if (patch.converted)
    out.push_back({Severity::info,
                   fmt::format("the file has a {} surface; converted exactly to a {}B-spline on "
                               "the face's parameter range",
                               patch.surface_type, s.is_rational() ? "rational " : ""),
                   "nothing to do"});
  return out;
}

}  // namespace isoflex::io
