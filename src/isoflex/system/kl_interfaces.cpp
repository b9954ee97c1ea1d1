#include "isoflex/system/kl_interfaces.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <utility>

#include "isoflex/geometry/projection.hpp"
#include "isoflex/geometry/refinement.hpp"

namespace isoflex::system {

namespace {

using geometry::Direction;
using geometry::KnotVector;
using geometry::NurbsSurface;
using loads::PatchEdge;

constexpr PatchEdge kEdges[4] = {PatchEdge::u0, PatchEdge::u1, PatchEdge::v0, PatchEdge::v1};
// Two normalized knots closer than this are the same knot.
constexpr double kSameKnot = 1e-9;

Direction along(PatchEdge e) {
  return loads::edge_runs_along_v(e) ? Direction::v : Direction::u;
}
const KnotVector& knots_along(const NurbsSurface& s, PatchEdge e) {
  return loads::edge_runs_along_v(e) ? s.v : s.u;
}
const char* parameter_name(PatchEdge e) {
  return loads::edge_runs_along_v(e) ? "η" : "ξ";
}

std::vector<Vec3> row_points(const NurbsSurface& s, PatchEdge e, int row) {
  std::vector<Vec3> out;
  for (int i : loads::edge_control_points(s, e, row)) out.push_back(s.points[i]);
  return out;
}

// Interior breakpoints of a knot vector mapped to [0, 1] (reversed: t → 1 − t), with their
// multiplicities, ascending.
using Breaks = std::vector<std::pair<double, int>>;
Breaks normalized_breaks(const KnotVector& kv, bool reversed) {
  Breaks out;
  const double a = kv.front(), L = kv.back() - kv.front();
  for (double u : kv.breakpoints()) {
    if (u <= a || u >= kv.back()) continue;
    const double t = (u - a) / L;
    out.emplace_back(reversed ? 1.0 - t : t, kv.multiplicity(u));
  }
  std::sort(out.begin(), out.end());
  return out;
}

// The union of two sets of breaks, each knot with the larger multiplicity.
Breaks merged(const Breaks& x, const Breaks& y) {
  Breaks out = x;
  for (const auto& [t, m] : y) {
    auto it = std::find_if(out.begin(), out.end(),
                           [&](const auto& b) { return std::abs(b.first - t) <= kSameKnot; });
    if (it == out.end())
      out.emplace_back(t, m);
    else
      it->second = std::max(it->second, m);
  }
  std::sort(out.begin(), out.end());
  return out;
}

// The knots (in the parameter of kv) to insert so that kv has every break of `target`.
std::vector<double> missing_knots(const KnotVector& kv, bool reversed, const Breaks& target) {
  const Breaks own = normalized_breaks(kv, reversed);
  std::vector<double> out;
  for (const auto& [t, m] : target) {
    const auto it = std::find_if(own.begin(), own.end(),
                                 [&](const auto& b) { return std::abs(b.first - t) <= kSameKnot; });
    const int have = it == own.end() ? 0 : it->second;
    const double s = reversed ? 1.0 - t : t;
    const double u = kv.front() + s * (kv.back() - kv.front());
    for (int k = have; k < m; ++k) out.push_back(u);
  }
  std::sort(out.begin(), out.end());
  return out;
}

bool collapsed(const std::vector<Vec3>& pts, double tol) {
  return std::all_of(pts.begin(), pts.end(),
                     [&](const Vec3& x) { return (x - pts.front()).norm() <= tol; });
}

// The point of the edge at the fraction s ∈ [0, 1] of its parameter range.
Vec3 edge_point(const NurbsSurface& g, PatchEdge e, double s) {
  const KnotVector& kv = knots_along(g, e);
  const double t = kv.front() + s * (kv.back() - kv.front());
  const double fixed = loads::edge_parameter(g, e);
  return loads::edge_runs_along_v(e) ? geometry::evaluate(g, fixed, t).x
                                     : geometry::evaluate(g, t, fixed).x;
}

// Whether the point lies on edge `e` of `g`: its projection is within tol and at the edge's
// parameter.
bool on_edge(const NurbsSurface& g, PatchEdge e, const Vec3& x, double tol) {
  const geometry::ProjectionResult r = geometry::project_point(g, x);
  if (!(r.distance <= tol)) return false;
  const KnotVector& across = loads::edge_runs_along_v(e) ? g.u : g.v;
  const double p = loads::edge_runs_along_v(e) ? r.xi : r.eta;
  return std::abs(p - loads::edge_parameter(g, e)) <= 1e-6 * (across.back() - across.front());
}

struct EdgePair {
  int a, b;
  PatchEdge ea, eb;
  bool reversed;
};

std::string edge_name(const std::vector<std::string>& names, int patch, PatchEdge e) {
  return fmt::format("\"{}\" edge {}", names[static_cast<std::size_t>(patch)], loads::to_string(e));
}

// The box of some points grown by tol.
struct Box {
  Vec3 lo, hi;
  explicit Box(const std::vector<Vec3>& p, double tol) : lo(p.front()), hi(p.front()) {
    for (const Vec3& x : p) {
      lo = lo.cwiseMin(x);
      hi = hi.cwiseMax(x);
    }
    lo.array() -= tol;
    hi.array() += tol;
  }
  bool overlaps(const Box& o) const {
    return (lo.array() <= o.hi.array()).all() && (o.lo.array() <= hi.array()).all();
  }
  bool contains(const Vec3& x) const {
    return (lo.array() <= x.array()).all() && (x.array() <= hi.array()).all();
  }
};

// The edge pairs that coincide as curves. Throws for an edge that lies along part of another.
// Samples inside an edge (not at knots of a uniform refinement), as fractions of its range.
constexpr double kSamples[] = {0.13, 0.29, 0.5, 0.71, 0.87};

// Two edges of one patch that coincide point for point at equal (or, reversed, mirrored)
// fractions of their parameter ranges: a closed patch's seam. Projection cannot decide this (a
// point on the seam projects onto either edge), and a seam of one patch has one parametrization
// on both sides in every closed surface built here or read from CAD.
bool same_curve(const NurbsSurface& g, PatchEdge ea, PatchEdge eb, bool reversed, double tol) {
  return std::all_of(std::begin(kSamples), std::end(kSamples), [&](double f) {
    return (edge_point(g, ea, f) - edge_point(g, eb, reversed ? 1.0 - f : f)).norm() <= tol;
  });
}

// Whether x lies within tol of edge e's curve: the nearest of 65 samples, then golden-section
// search on the bracket around it (edge curves of a seam: projection onto the surface cannot
// tell the two sides apart).
bool near_edge_curve(const NurbsSurface& g, PatchEdge e, const Vec3& x, double tol) {
  constexpr int n = 64;
  int best = 0;
  double d = std::numeric_limits<double>::infinity();
  for (int k = 0; k <= n; ++k)
    if (const double dk = (edge_point(g, e, static_cast<double>(k) / n) - x).norm(); dk < d) {
      d = dk;
      best = k;
    }
  double lo = std::max(0, best - 1) / static_cast<double>(n),
         hi = std::min(n, best + 1) / static_cast<double>(n);
  const double r = 0.5 * (std::sqrt(5.0) - 1.0);
  const auto dist = [&](double f) { return (edge_point(g, e, f) - x).norm(); };
  for (int it = 0; it < 60 && d > tol; ++it) {
    const double f1 = hi - r * (hi - lo), f2 = lo + r * (hi - lo);
    const double d1 = dist(f1), d2 = dist(f2);
    d = std::min({d, d1, d2});
    if (d1 < d2)
      hi = f2;
    else
      lo = f1;
  }
  return d <= tol;
}

std::vector<EdgePair> coincident_edges(const std::vector<NurbsSurface>& s,
                                       const std::vector<std::string>& names, double tol,
                                       const std::vector<bool>& open_seam,
                                       std::vector<std::pair<int, std::string>>& open_seams) {
  std::vector<EdgePair> out;
  const int n = static_cast<int>(s.size());
  for (int a = 0; a < n; ++a)
    for (int b = a; b < n; ++b)
      for (PatchEdge ea : kEdges)
        for (PatchEdge eb : kEdges) {
          // Within one patch each unordered pair of different edges once.
          if (a == b && static_cast<int>(eb) <= static_cast<int>(ea)) continue;
          const std::vector<Vec3> ra = row_points(s[a], ea, 0), rb = row_points(s[b], eb, 0);
          if (collapsed(ra, tol) || collapsed(rb, tol)) continue;
          if (!Box(ra, tol).overlaps(Box(rb, tol))) continue;
          const auto near = [&](const Vec3& x, const Vec3& y) { return (x - y).norm() <= tol; };
          const bool fwd = near(ra.front(), rb.front()) && near(ra.back(), rb.back());
          const bool rev = near(ra.front(), rb.back()) && near(ra.back(), rb.front());
          if (a == b) {
            // Adjacent edges of a patch share a corner; only a whole edge on another is a seam.
            // Of a closed edge (both ends at one point) fwd and rev both hold: try both.
            const bool open = !open_seam.empty() && open_seam[static_cast<std::size_t>(a)];
            bool joined = false;
            for (const bool r : {false, true}) {
              if (!(r ? rev : fwd) || !same_curve(s[a], ea, eb, r, tol)) continue;
              if (open)
                open_seams.emplace_back(
                    a, fmt::format("{} -- {}{}", edge_name(names, a, ea), loads::to_string(eb),
                                   r ? " (reversed)" : ""));
              else
                out.push_back({a, b, ea, eb, r});
              joined = true;
              break;
            }
            // The same curve, but not point for point at equal fractions of the parameters: a
            // seam parametrized differently on its two sides, which the couplings (matching
            // control points) cannot join. Open on request, otherwise a located error.
            if (!joined && (fwd || rev) &&
                std::all_of(std::begin(kSamples), std::end(kSamples), [&](double f) {
                  return near_edge_curve(s[a], eb, edge_point(s[a], ea, f), tol);
                })) {
              if (open) {
                open_seams.emplace_back(
                    a, fmt::format("{} -- {} (parametrized differently)", edge_name(names, a, ea),
                                   loads::to_string(eb)));
                continue;
              }
              throw KLInterfaceError(
                  a, a,
                  fmt::format("{} and {} are the same curve (a seam) but not point for point at "
                              "equal fractions of their parameters: the couplings join matching "
                              "control points only; give the surface one parametrization on both "
                              "sides of its seam, or keep the seam open (seam: open)",
                              edge_name(names, a, ea), loads::to_string(eb)),
                  "seam");
            }
            continue;
          }
          const auto along_other = [&](const NurbsSurface& from, PatchEdge ef,
                                       const NurbsSurface& to, PatchEdge et) {
            return std::all_of(std::begin(kSamples), std::end(kSamples), [&](double f) {
              return on_edge(to, et, edge_point(from, ef, f), tol);
            });
          };
          if (fwd || rev) {
            if (along_other(s[a], ea, s[b], eb)) out.push_back({a, b, ea, eb, rev});
            continue;
          }
          // Not the same ends: an edge that runs along part of the other is a T-junction or a
          // non-matching subdivision, which the couplings cannot join. An edge curve lies in the
          // box of its control points (convex hull, positive weights): edges that only touch,
          // as at the corners of a grid of patches, fail that cheap test before any projection.
          const Box box_a(ra, tol), box_b(rb, tol);
          if (!(box_b.contains(ra.front()) && box_b.contains(ra.back())) &&
              !(box_a.contains(rb.front()) && box_a.contains(rb.back())))
            continue;
          const bool a_in_b = on_edge(s[b], eb, ra.front(), tol) &&
                              on_edge(s[b], eb, ra.back(), tol) && along_other(s[a], ea, s[b], eb);
          const bool b_in_a = on_edge(s[a], ea, rb.front(), tol) &&
                              on_edge(s[a], ea, rb.back(), tol) && along_other(s[b], eb, s[a], ea);
          if (a_in_b || b_in_a)
            throw KLInterfaceError(
                a, b,
                fmt::format("{} lies along part of {}: a non-conforming interface (the patches "
                            "must meet edge to edge; split the longer patch at the shorter one's "
                            "ends)",
                            edge_name(names, a_in_b ? a : b, a_in_b ? ea : eb),
                            edge_name(names, a_in_b ? b : a, a_in_b ? eb : ea)));
        }
  return out;
}

// Raises the degree and inserts knots along the coincident edges until every pair has the same
// degree and the same normalized knots along its edge.
void make_conforming(std::vector<NurbsSurface>& s, const std::vector<EdgePair>& pairs,
                     const std::vector<std::string>& names, std::vector<std::string>& log) {
  const std::size_t most_passes = 4 * s.size() + 4;
  for (std::size_t pass = 0;; ++pass) {
    bool changed = false;
    for (const EdgePair& p : pairs) {
      const int pa = knots_along(s[p.a], p.ea).degree(), pb = knots_along(s[p.b], p.eb).degree();
      const auto elevate = [&](int k, PatchEdge e, int by, int other, PatchEdge eo) {
        s[k] = geometry::elevate_degree(s[k], along(e), by);
        log.push_back(fmt::format("\"{}\": degree along {} raised by {} (to match {})", names[k],
                                  parameter_name(e), by, edge_name(names, other, eo)));
        changed = true;
      };
      if (pa < pb) elevate(p.a, p.ea, pb - pa, p.b, p.eb);
      if (pb < pa) elevate(p.b, p.eb, pa - pb, p.a, p.ea);
      if (p.a == p.b && pa != pb) continue;  // one surface: compare again in the next pass
      const KnotVector &ka = knots_along(s[p.a], p.ea), &kb = knots_along(s[p.b], p.eb);
      const Breaks target = merged(normalized_breaks(ka, false), normalized_breaks(kb, p.reversed));
      const std::vector<double> na = missing_knots(ka, false, target);
      const std::vector<double> nb = missing_knots(kb, p.reversed, target);
      const auto insert = [&](int k, PatchEdge e, const std::vector<double>& knots, int other,
                              PatchEdge eo) {
        if (knots.empty()) return;
        s[k] = geometry::refine_knots(s[k], along(e), knots);
        log.push_back(fmt::format("\"{}\": {} knot{} inserted along {} (to match {})", names[k],
                                  knots.size(), knots.size() == 1 ? "" : "s", parameter_name(e),
                                  edge_name(names, other, eo)));
        changed = true;
      };
      insert(p.a, p.ea, na, p.b, p.eb);
      // A patch's own seam: b's knots are in the surface just refined; the next pass computes
      // what is still missing from that (inserting both would insert a knot twice).
      if (p.a != p.b) insert(p.b, p.eb, nb, p.a, p.ea);
    }
    if (!changed) return;
    if (pass + 1 >= most_passes)
      throw std::logic_error("join_kl_patches: making the interfaces conforming did not settle");
  }
}

// Union–find over all control points (patch offset + index).
struct Groups {
  std::vector<int> parent;
  explicit Groups(int n) : parent(static_cast<std::size_t>(n)) {
    std::iota(parent.begin(), parent.end(), 0);
  }
  int find(int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  }
  void join(int i, int j) { parent[find(i)] = find(j); }
};

}  // namespace

KLPatchJoining join_kl_patches(std::vector<NurbsSurface> surfaces, double relative_tolerance,
                               const std::vector<std::string>& names,
                               const KLJoinOptions& options) {
  if (!(relative_tolerance > 0.0 && relative_tolerance <= 0.01))
    throw std::invalid_argument(
        fmt::format("interface tolerance must lie in (0, 0.01], got {}", relative_tolerance));
  if (names.size() != surfaces.size())
    throw std::invalid_argument("join_kl_patches: one name per surface");
  if (!options.open_seam.empty() && options.open_seam.size() != surfaces.size())
    throw std::invalid_argument("join_kl_patches: one open_seam flag per surface");
  KLPatchJoining J;
  Vec3 lo = Vec3::Constant(INFINITY), hi = Vec3::Constant(-INFINITY);
  for (const NurbsSurface& g : surfaces)
    for (const Vec3& x : g.points) {
      lo = lo.cwiseMin(x);
      hi = hi.cwiseMax(x);
    }
  J.tolerance = surfaces.empty() ? 0.0 : relative_tolerance * (hi - lo).norm();
  std::vector<std::pair<int, std::string>> open_seams;
  const std::vector<EdgePair> pairs =
      coincident_edges(surfaces, names, J.tolerance, options.open_seam, open_seams);
  for (std::size_t k = 0; k < options.open_seam.size(); ++k) {
    const int K = static_cast<int>(k);
    if (options.open_seam[k] && std::none_of(open_seams.begin(), open_seams.end(),
                                             [&](const auto& o) { return o.first == K; }))
      throw KLInterfaceError(
          K, K,
          fmt::format("seam: open, but no two edges of \"{}\" coincide (within {:.3g}): the patch "
                      "has no seam to keep open",
                      names[k], J.tolerance),
          "seam");
  }
  for (const auto& o : open_seams) J.open_seams.push_back(o.second);
  make_conforming(surfaces, pairs, names, J.refinements);

  std::vector<int> offset(surfaces.size() + 1, 0);
  for (std::size_t k = 0; k < surfaces.size(); ++k)
    offset[k + 1] = offset[k] + static_cast<int>(surfaces[k].points.size());
  Groups groups(offset.back());
  for (const EdgePair& p : pairs) {
    KLInterface f;
    f.a = p.a;
    f.b = p.b;
    f.edge_a = p.ea;
    f.edge_b = p.eb;
    f.reversed = p.reversed;
    f.shared_a = loads::edge_control_points(surfaces[p.a], p.ea, 0);
    f.inner_a = loads::edge_control_points(surfaces[p.a], p.ea, 1);
    f.shared_b = loads::edge_control_points(surfaces[p.b], p.eb, 0);
    f.inner_b = loads::edge_control_points(surfaces[p.b], p.eb, 1);
    if (p.reversed) {
      std::reverse(f.shared_b.begin(), f.shared_b.end());
      std::reverse(f.inner_b.begin(), f.inner_b.end());
    }
    const NurbsSurface &ga = surfaces[p.a], &gb = surfaces[p.b];
    if (f.shared_a.size() != f.shared_b.size())
      throw KLInterfaceError(
          p.a, p.b,
          fmt::format("{} and {} coincide but have {} and {} control points after raising the "
                      "degree and inserting knots: not conforming",
                      edge_name(names, p.a, p.ea), edge_name(names, p.b, p.eb), f.shared_a.size(),
                      f.shared_b.size()));
    const double ratio = gb.weights[f.shared_b[0]] / ga.weights[f.shared_a[0]];
    for (int k = 0; k < f.triples(); ++k) {
      const int A = f.shared_a[k], B = f.shared_b[k];
      const double d = (ga.points[A] - gb.points[B]).norm();
      const double dw = std::abs(gb.weights[B] / ga.weights[A] - ratio);
      if (d > J.tolerance || dw > 1e-9 * ratio)
        throw KLInterfaceError(
            p.a, p.b,
            fmt::format("{} and {} coincide as curves but are parametrized differently: with the "
                        "same knots, control point {} of the edge is {} ({:.3g} apart, tolerance "
                        "{:.3g}); give both surfaces the same parametrization along the edge",
                        edge_name(names, p.a, p.ea), edge_name(names, p.b, p.eb), k,
                        d > J.tolerance ? "at a different place" : "weighted differently", d,
                        J.tolerance));
      groups.join(offset[p.a] + A, offset[p.b] + B);
    }
    J.interfaces.push_back(std::move(f));
  }
  // The C⁰ knot lines inside each patch, after the conforming (which may have carried such a
  // line over from a neighbour: a knot inserted with the neighbour's multiplicity p).
  for (std::size_t k = 0; k < surfaces.size(); ++k)
    for (const bool along_v : {false, true}) {
      const NurbsSurface& g = surfaces[k];
      const KnotVector& kv = along_v ? g.v : g.u;
      const int p = kv.degree(), nu = g.n_u();
      const int count = along_v ? g.n_v() : nu, other = along_v ? nu : g.n_v();
      for (double t : kv.breakpoints()) {
        if (!(t > kv.front() && t < kv.back())) continue;
        const int m = kv.multiplicity(t);
        if (m < p) continue;
        const int K = static_cast<int>(k);
        if (m > p)
          throw KLInterfaceError(
              K, K,
              fmt::format("\"{}\": the knot {} = {} has multiplicity {} > degree {}: the basis is "
                          "discontinuous there and the pieces are not joined (split the patch "
                          "there into two patches)",
                          names[k], along_v ? "η" : "ξ", t, m, p));
        // The one basis function that is 1 on the line (multiplicity p: the function before the
        // knot's first copy interpolates it), its column (or row) c of control points.
        const auto& U = kv.knots();
        const int first = static_cast<int>(std::find(U.begin(), U.end(), t) - U.begin());
        const int c = first - 1;
        if (c < 1 || c + 1 >= count) throw std::logic_error("join_kl_patches: knot line at a rim");
        KLInterface f;
        f.a = f.b = K;
        f.kind = KLInterfaceKind::knot_line;
        f.knot_along_v = along_v;
        f.knot = t;
        const auto index = [&](int line, int s) { return along_v ? s + nu * line : line + nu * s; };
        for (int s = 0; s < other; ++s) {
          f.inner_a.push_back(index(c - 1, s));
          f.shared_a.push_back(index(c, s));
          f.shared_b.push_back(index(c, s));
          f.inner_b.push_back(index(c + 1, s));
        }
        J.interfaces.push_back(std::move(f));
      }
    }
  // The coincident control points at their mean position.
  std::vector<Vec3> sum(static_cast<std::size_t>(offset.back()), Vec3::Zero());
  std::vector<int> count(static_cast<std::size_t>(offset.back()), 0);
  for (std::size_t k = 0; k < surfaces.size(); ++k)
    for (std::size_t A = 0; A < surfaces[k].points.size(); ++A) {
      const int r = groups.find(offset[k] + static_cast<int>(A));
      sum[r] += surfaces[k].points[A];
      ++count[r];
    }
  J.point_group.resize(surfaces.size());
  for (std::size_t k = 0; k < surfaces.size(); ++k)
    for (std::size_t A = 0; A < surfaces[k].points.size(); ++A) {
      const int r = groups.find(offset[k] + static_cast<int>(A));
      if (count[r] > 1) surfaces[k].points[A] = sum[r] / count[r];
      J.point_group[k].push_back(r);
    }
  for (KLInterface& f : J.interfaces) {
    // A triple with a leg of length ≤ τ (at a pole all three points coincide) has no angle: it
    // is left out of the triples (its shared point stays joined).
    KLInterface kept = f;
    kept.shared_a.clear();
    kept.shared_b.clear();
    kept.inner_a.clear();
    kept.inner_b.clear();
    kept.angle_min = 180.0;
    kept.angle_max = 0.0;
    for (int k = 0; k < f.triples(); ++k) {
      const Vec3 x = surfaces[f.a].points[f.shared_a[k]];
      const Vec3 da = surfaces[f.a].points[f.inner_a[k]] - x;
      const Vec3 db = surfaces[f.b].points[f.inner_b[k]] - x;
      if (!(da.norm() > J.tolerance && db.norm() > J.tolerance)) {
        ++kept.degenerate_triples;
        continue;
      }
      kept.shared_a.push_back(f.shared_a[k]);
      kept.shared_b.push_back(f.shared_b[k]);
      kept.inner_a.push_back(f.inner_a[k]);
      kept.inner_b.push_back(f.inner_b[k]);
      const double deg = std::atan2(da.cross(db).norm(), da.dot(db)) * 180.0 / std::numbers::pi;
      kept.angle_min = std::min(kept.angle_min, deg);
      kept.angle_max = std::max(kept.angle_max, deg);
    }
    f = std::move(kept);
  }
  J.surfaces = std::move(surfaces);
  return J;
}

}  // namespace isoflex::system
