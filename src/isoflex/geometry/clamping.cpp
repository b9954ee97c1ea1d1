#include "isoflex/geometry/clamping.hpp"

#include <algorithm>
#include <utility>
#include <vector>

#include "isoflex/geometry/homogeneous_lines.hpp"

namespace isoflex::geometry {

namespace {

using detail::HomCurve;

// One line: the ends a = U_p and b = U_n of the domain raised to multiplicity p + 1 by Boehm's
// insertion (homogeneous_lines.hpp), then cut to the pieces between them.
HomCurve clamp_line(HomCurve h) {
  const int p = h.kv.degree();
  const double a = h.kv.front(), b = h.kv.back();
  for (int m = h.kv.multiplicity(a); m < p + 1; ++m) h = detail::insert_once(h, a);
  for (int m = h.kv.multiplicity(b); m < p + 1; ++m) h = detail::insert_once(h, b);
  // With a at least p+1-fold, ending at index e, the functions N_i with i < e − p have their
  // support [U_i, U_{i+p+1}] ⊆ (−∞, a] and vanish on the domain, and N_{e−p}, … depend on knots
  // from U_{e−p} = a on; likewise at b, first at index s: N_i with i ≥ s vanish on it, N_{s−1}
  // ends at U_{s+p} = b. Kept: control points e − p … s − 1, knots U_{e−p} … U_{s+p}, which begin
  // and end with exactly p + 1 copies of a and b.
  const std::vector<double>& U = h.kv.knots();
  const auto e = static_cast<int>(std::upper_bound(U.begin(), U.end(), a) - U.begin()) - 1;
  const auto s = static_cast<int>(std::lower_bound(U.begin(), U.end(), b) - U.begin());
  HomCurve out;
  out.kv = KnotVector(p, std::vector<double>(U.begin() + (e - p), U.begin() + (s + p + 1)));
  out.pw.assign(h.pw.begin() + (e - p), h.pw.begin() + s);
  return out;
}

}  // namespace

NurbsCurve clamped(const NurbsCurve& c) {
  c.validate();
  if (c.knots.is_open()) return c;
  return detail::from_hom(clamp_line(detail::to_hom(c)));
}

NurbsSurface clamped(const NurbsSurface& s, Direction d) {
  s.validate();
  if ((d == Direction::u ? s.u : s.v).is_open()) return s;
  return detail::apply_lines(s, d, [](const HomCurve& h) { return clamp_line(h); });
}

NurbsSurface clamped(const NurbsSurface& s) {
  return clamped(clamped(s, Direction::u), Direction::v);
}

}  // namespace isoflex::geometry
