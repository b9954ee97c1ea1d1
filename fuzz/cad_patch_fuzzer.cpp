// libFuzzer harness: our side of CAD import (issue #15) — a parsed NURBS patch as the CAD reading
// process hands it over (io::CadPatch, through the pipe's byte format, cad_wire.hpp), the
// suitability checks (io::check_patch) and the conversions a model file applies (clamping of knot
// vectors that are not open, then `refine`: degree elevation, knot insertion;
// io/surface_reader.cpp), on arbitrary degrees, knots, weights and control nets
// (cad_patch_codec.hpp). OpenCASCADE is not in this process: it runs
// in the isolated reading process.
//
// Allowed: std::invalid_argument from the places documented to throw it (KnotVector,
// NurbsSurface::validate, clamped, elevate_degree, refine_knots) — the model reader turns those
// into located errors. A finding is anything else escaping, a crash, a sanitizer report, or one of
// the checks below (__builtin_trap):
//   - the pipe's bytes give the patch back bit for bit;
//   - every finding says what and how to fix it;
//   - clamping and refinement of a patch the reader accepts give a valid surface with the same
//     geometry (at sample parameters, where the numbers are not extreme).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>

#include "cad_patch_codec.hpp"
#include "isoflex/geometry/clamping.hpp"
#include "isoflex/geometry/refinement.hpp"
#include "isoflex/io/cad/cad_checks.hpp"
#include "isoflex/io/cad/cad_wire.hpp"

using namespace isoflex;

namespace {

bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
}

bool same_patch(const io::CadPatch& a, const io::CadPatch& b) {
  if (a.surface.points.size() != b.surface.points.size()) return false;
  for (std::size_t k = 0; k < a.surface.points.size(); ++k)
    if (std::memcmp(a.surface.points[k].data(), b.surface.points[k].data(), 3 * sizeof(double)))
      return false;
  return a.surface.degree_u() == b.surface.degree_u() &&
         a.surface.degree_v() == b.surface.degree_v() &&
         same_bits(a.surface.u.knots(), b.surface.u.knots()) &&
         same_bits(a.surface.v.knots(), b.surface.v.knots()) &&
         same_bits(a.surface.weights, b.surface.weights) && a.trimmed == b.trimmed &&
         a.reversed_orientation == b.reversed_orientation && a.converted == b.converted &&
         a.name == b.name && a.index == b.index;
}

// Whether the numbers of `s` are moderate enough for a geometric comparison in doubles: finite
// coordinates below 1e100, weights in [1e-100, 1e100] within a factor 1e4 of each other, a
// domain that is not tiny relative to its knots.
bool moderate(const geometry::NurbsSurface& s, double& scale) {
  scale = 0;
  for (const Vec3& x : s.points) {
    if (!(x.cwiseAbs().maxCoeff() < 1e100)) return false;
    scale = std::max(scale, x.cwiseAbs().maxCoeff());
  }
  const auto [wmin, wmax] = std::minmax_element(s.weights.begin(), s.weights.end());
  // Weights far from 1 (e.g. subnormal: 1e-317, which validate() accepts) lose their digits in
  // the homogeneous coordinates w·x of refinement, so the geometry is only compared for weights
  // in [1e-100, 1e100].
  if (s.weights.empty() || !(*wmax <= 1e4 * *wmin) || !(*wmin >= 1e-100) || !(*wmax <= 1e100))
    return false;
  for (const geometry::KnotVector* kv : {&s.u, &s.v}) {
    const double size = std::max(std::abs(kv->knots().front()), std::abs(kv->knots().back()));
    // (and not subnormal: a domain [1e-318, 5e-315] evaluates to NaN; see the report of #15)
    if (!(size < 1e100) || !(kv->back() - kv->front() > 1e-8 * size) ||
        !(kv->back() - kv->front() > 1e-100))
      return false;
    // Knot spans much shorter than the domain make the basis ill-conditioned.
    for (std::size_t k = 1; k < kv->knots().size(); ++k) {
      const double h = kv->knots()[k] - kv->knots()[k - 1];
      if (h > 0 && h < 1e-6 * (kv->back() - kv->front())) return false;
    }
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::RawPatch raw;
  if (!fuzz::decode(data, size, raw)) return 0;

  io::CadPatch patch;
  patch.name = "fuzz";
  patch.trimmed = raw.trimmed;
  patch.reversed_orientation = raw.reversed;
  patch.converted = raw.converted;
  try {
    patch.surface.u = geometry::KnotVector(raw.degree_u, raw.knots_u);
    patch.surface.v = geometry::KnotVector(raw.degree_v, raw.knots_v);
    patch.surface.points = raw.points;
    patch.surface.weights = raw.weights;
    patch.surface.validate();  // what the reading process does before handing a patch over
  } catch (const std::invalid_argument&) {
    return 0;
  }

  // The pipe: bytes and back, bit for bit.
  io::CadModel model;
  model.patches.push_back(patch);
  const io::CadModel back = io::detail::model_from_bytes(io::detail::to_bytes(model));
  if (back.patches.size() != 1 || !same_patch(back.patches[0], patch)) __builtin_trap();

  // The checks, as the model reader runs them on the patch of the file.
  for (const io::Finding& f : io::check_patch(patch)) {
    if (f.issue.empty() || f.fix.empty()) __builtin_trap();
    if (f.severity == io::Severity::error) return 0;  // a located error of the model file
  }

  // The model file's clamping (knot vectors that are not open), then its `refine`, with the
  // reader's guards (degree, open knots, size).
  geometry::NurbsSurface clamped;
  try {
    clamped = geometry::clamped(patch.surface);
  } catch (const std::invalid_argument&) {
    return 0;  // the reader's located "cannot clamp the knot vector"
  }
  if (!clamped.u.is_open() || !clamped.v.is_open()) __builtin_trap();
  const int elevate[2] = {raw.elevate_u, raw.elevate_v};
  const int per_span[2] = {raw.knots_per_span_u, raw.knots_per_span_v};
  const geometry::KnotVector* kv[2] = {&clamped.u, &clamped.v};
  double points = 1;
  for (int d = 0; d < 2; ++d) {
    if (elevate[d] > 0 &&
        (kv[d]->degree() + elevate[d] > geometry::kMaxDegree || !kv[d]->is_open()))
      return 0;  // the reader's located errors
    points *= kv[d]->n_basis() +
              elevate[d] * (static_cast<double>(kv[d]->breakpoints().size()) - 1) +
              per_span[d] * static_cast<double>(kv[d]->element_spans().size());
  }
  if (points > 20000) return 0;  // the reader's limit is 1e6; smaller keeps the fuzzer fast
  geometry::NurbsSurface out = clamped;
  try {
    for (int d = 0; d < 2; ++d)
      if (elevate[d] > 0)
        out = geometry::elevate_degree(
            out, d == 0 ? geometry::Direction::u : geometry::Direction::v, elevate[d]);
    for (int d = 0; d < 2; ++d)
      if (per_span[d] > 0) {
        const auto dir = d == 0 ? geometry::Direction::u : geometry::Direction::v;
        out = geometry::refine_knots(
            out, dir, geometry::uniform_new_knots(d == 0 ? out.u : out.v, per_span[d]));
      }
  } catch (const std::invalid_argument&) {
    return 0;  // the reader's located "cannot elevate the degree" / "cannot insert the knots"
  }

  // The refined surface: what the reader checks again and hands on.
  double scale = 0;
  const bool compare = moderate(patch.surface, scale);
  if (compare) {
    out.validate();  // throws (escapes: a finding) if refinement broke a valid surface
    if (out.degree_u() != patch.surface.degree_u() + elevate[0] ||
        out.degree_v() != patch.surface.degree_v() + elevate[1])
      __builtin_trap();
  }
  io::CadPatch refined = patch;
  refined.surface = out;
  for (const io::Finding& f : io::check_patch(refined))
    if (f.issue.empty() || f.fix.empty()) __builtin_trap();

  // The same geometry: clamping and refinement are exact.
  if (compare) {
    const double tol = 1e-7 * std::max(scale, 1e-300);
    for (double a : {0.0, 0.31, 0.77, 1.0})
      for (double b : {0.0, 0.43, 1.0}) {
        const double xi =
            patch.surface.u.front() + a * (patch.surface.u.back() - patch.surface.u.front());
        const double eta =
            patch.surface.v.front() + b * (patch.surface.v.back() - patch.surface.v.front());
        const Vec3 x0 = geometry::evaluate(patch.surface, xi, eta).x;
        const Vec3 x1 = geometry::evaluate(out, xi, eta).x;
        if (!((x0 - x1).cwiseAbs().maxCoeff() <= tol)) __builtin_trap();
      }
  }
  return 0;
}
