#include "isoflex/geometry/builders.hpp"

#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>
#include <string>

#include "isoflex/math/exact_text.hpp"

namespace isoflex::geometry {

namespace {

constexpr double kPi = std::numbers::pi;
// 2π less a relative round-off: an angle this large is a full turn (360° → radians is exact, but a
// user's 2π may be computed).
constexpr double kFullTurn = 2.0 * kPi * (1.0 - 1e-15);

void check_positive(double x, const char* what, const char* name) {
  if (!(x > 0.0) || !std::isfinite(x))
    throw std::invalid_argument(std::string(what) + ": " + name + " = " + exact_text(x) +
                                " must be positive and finite");
}

void check_angle(double a, double max, const char* what, const char* name, const char* range) {
  if (!(a > 0.0 && a <= max * (1.0 + 1e-15)))
    throw std::invalid_argument(std::string(what) + ": " + name + " = " + exact_text(a) +
                                " outside " + range);
}

// Control polygon of a circular arc in the plane (cos, sin)·R: the rational quadratic segments
// of at most 90° described in builders.hpp. Returns 2·n_arcs + 1 planar points, their weights
// and the knot vector (0,0,0, 1/n,1/n, …, 1,1,1).
struct Arc2 {
  KnotVector knots;
  std::vector<Eigen::Vector2d> points;
  std::vector<double> weights;
};

Arc2 arc2(double radius, double start, double sweep) {
  // Number of segments: the fewest with Δθ ≤ 90° (a small slack so that 90° itself is one).
  const int n_arcs = std::max(1, static_cast<int>(std::ceil(sweep / (kPi / 2.0) - 1e-12)));
  // A full turn ends where it starts; cos/sin of start + 2π differ from those of start by
  // round-off, so the closing point is the first one copied: the seam of a closed patch (its
  // edges ξ = 0 and ξ = 1) then has the same control points, bit for bit.
  const bool full_turn = sweep >= kFullTurn;
  const double d = sweep / n_arcs;
  const double wm = std::cos(d / 2.0);  // weight of the middle points
  Arc2 a;
  std::vector<double> k(3, 0.0);
  for (int s = 0; s < n_arcs; ++s) {
    const double t0 = start + s * d, tm = t0 + d / 2.0;
    a.points.push_back(radius * Eigen::Vector2d(std::cos(t0), std::sin(t0)));
    a.weights.push_back(1.0);
    // Intersection of the end tangents: on the bisector at R / cos(Δθ/2).
    a.points.push_back(radius / wm * Eigen::Vector2d(std::cos(tm), std::sin(tm)));
    a.weights.push_back(wm);
    if (s > 0) k.insert(k.end(), 2, static_cast<double>(s) / n_arcs);
  }
  const double t1 = start + sweep;
  const Eigen::Vector2d end = radius * Eigen::Vector2d(std::cos(t1), std::sin(t1));
  a.points.push_back(full_turn ? a.points.front() : end);
  a.weights.push_back(1.0);
  k.insert(k.end(), 3, 1.0);
  a.knots = KnotVector(2, k);
  return a;
}

}  // namespace

NurbsCurve circle_arc(double radius, double start, double sweep, const Vec3& center) {
  check_positive(radius, "circle_arc", "radius");
  check_angle(sweep, 2.0 * kPi, "circle_arc", "sweep", "(0, 2π]");
  if (!std::isfinite(start) || !center.allFinite())
    throw std::invalid_argument("circle_arc: start angle and centre must be finite");
  const Arc2 a = arc2(radius, start, sweep);
  NurbsCurve c;
  c.knots = a.knots;
  for (std::size_t i = 0; i < a.points.size(); ++i)
    c.points.push_back(center + Vec3(a.points[i].x(), a.points[i].y(), 0.0));
  c.weights = a.weights;
  return c;
}

NurbsCurve circle(double radius) {
  return circle_arc(radius, 0.0, 2.0 * kPi);
}

NurbsSurface planar_rectangle(const Vec3& corner, const Vec3& edge_u, const Vec3& edge_v) {
  if (!corner.allFinite() || !edge_u.allFinite() || !edge_v.allFinite())
    throw std::invalid_argument("planar_rectangle: corner and edges must be finite");
  const double area = edge_u.cross(edge_v).norm();
  if (!(area > 1e-14 * edge_u.norm() * edge_v.norm()) || !(area > 0.0))
    throw std::invalid_argument(
        "planar_rectangle: edges are zero or parallel (|e_u × e_v| = " + exact_text(area) + ")");
  NurbsSurface s;
  s.u = KnotVector(1, {0, 0, 1, 1});
  s.v = KnotVector(1, {0, 0, 1, 1});
  s.points = {corner, corner + edge_u, corner + edge_v, corner + edge_u + edge_v};  // i + 2j
  s.weights.assign(4, 1.0);
  return s;
}

NurbsSurface planar_rectangle(double lx, double ly) {
  check_positive(lx, "planar_rectangle", "lx");
  check_positive(ly, "planar_rectangle", "ly");
  return planar_rectangle(Vec3::Zero(), Vec3(lx, 0, 0), Vec3(0, ly, 0));
}

NurbsSurface cylinder_sector(double radius, double length, double angle) {
  check_positive(radius, "cylinder_sector", "radius");
  check_positive(length, "cylinder_sector", "length");
  check_angle(angle, 2.0 * kPi, "cylinder_sector", "angle", "(0, 2π]");
  const Arc2 a = arc2(radius, 0.0, angle);
  NurbsSurface s;
  s.u = a.knots;
  s.v = KnotVector(1, {0, 0, 1, 1});
  for (const double z : {0.0, length})
    for (std::size_t i = 0; i < a.points.size(); ++i) {
      s.points.emplace_back(a.points[i].x(), a.points[i].y(), z);
      s.weights.push_back(a.weights[i]);
    }
  return s;
}

NurbsSurface cylinder(double radius, double length) {
  return cylinder_sector(radius, length, 2.0 * kPi);
}

NurbsSurface annulus(double inner_radius, double outer_radius, double angle) {
  check_positive(inner_radius, "annulus", "inner_radius");
  check_positive(outer_radius, "annulus", "outer_radius");
  if (!(inner_radius < outer_radius))
    throw std::invalid_argument("annulus: inner_radius = " + exact_text(inner_radius) +
                                " must be smaller than outer_radius = " + exact_text(outer_radius));
  check_angle(angle, 2.0 * kPi, "annulus", "angle", "(0, 2π]");
  // The unit arc polygon scaled by each radius: a ruled surface between two concentric arcs of
  // the same rational parametrization, x(ξ, η) = ((1 − η) r_outer + η r_inner) c(ξ) with c the
  // exact unit arc (4.10) — linear in η, so degree 1 is exact. η runs inwards so that
  // S_ξ × S_η = r (r_inner − r_outer) c' × c = r (r_outer − r_inner) e_z points along +z
  // (c' × c = −e_z for a counter-clockwise c).
  const Arc2 a = arc2(1.0, 0.0, angle);
  NurbsSurface s;
  s.u = a.knots;
  s.v = KnotVector(1, {0, 0, 1, 1});
  for (const double r : {outer_radius, inner_radius})
    for (std::size_t i = 0; i < a.points.size(); ++i) {
      s.points.emplace_back(r * a.points[i].x(), r * a.points[i].y(), 0.0);
      s.weights.push_back(a.weights[i]);
    }
  return s;
}

NurbsSurface sphere_sector(double radius, double azimuth_sweep, double lat_from, double lat_to) {
  check_positive(radius, "sphere_sector", "radius");
  check_angle(azimuth_sweep, 2.0 * kPi, "sphere_sector", "azimuth_sweep", "(0, 2π]");
  if (!(lat_from >= -kPi / 2 - 1e-15 && lat_to <= kPi / 2 + 1e-15 && lat_from < lat_to))
    throw std::invalid_argument("sphere_sector: latitudes [" + exact_text(lat_from) + ", " +
                                exact_text(lat_to) + "] not an interval inside [−π/2, π/2]");
  // Surface of revolution of the meridian arc (r, z) = R (cos λ, sin λ) about z: the control
  // point (r_j, z_j) with weight w_j, turned by the unit-circle arc polygon (c_i, w_i), gives
  // P_ij = (r_j c_i, z_j), w_ij = w_i w_j — a tensor product of two exact arcs (4.12).
  const Arc2 az = arc2(1.0, 0.0, azimuth_sweep);
  const Arc2 mer = arc2(radius, lat_from, lat_to - lat_from);
  NurbsSurface s;
  s.u = az.knots;
  s.v = mer.knots;
  for (std::size_t j = 0; j < mer.points.size(); ++j)
    for (std::size_t i = 0; i < az.points.size(); ++i) {
      const double r = mer.points[j].x(), z = mer.points[j].y();
      s.points.emplace_back(r * az.points[i].x(), r * az.points[i].y(), z);
      s.weights.push_back(az.weights[i] * mer.weights[j]);
    }
  return s;
}

NurbsSurface sphere_octant(double radius) {
  return sphere_sector(radius, kPi / 2.0, 0.0, kPi / 2.0);
}

NurbsSurface hemisphere(double radius) {
  return sphere_sector(radius, 2.0 * kPi, 0.0, kPi / 2.0);
}

NurbsSurface spherical_cap(double radius, double polar_angle) {
  check_positive(radius, "spherical_cap", "radius");
  if (!(polar_angle > 0.0 && polar_angle < kPi))
    throw std::invalid_argument("spherical_cap: polar_angle = " + exact_text(polar_angle) +
                                " outside (0, π)");
  // Latitude λ = π/2 − polar angle: from the rim up to the north pole.
  return sphere_sector(radius, 2.0 * kPi, kPi / 2.0 - polar_angle, kPi / 2.0);
}

NurbsSurface disc(double radius) {
  check_positive(radius, "disc", "radius");
  const double c = radius / std::sqrt(2.0);  // corners: R (±1, ±1)/√2
  const double m = radius * std::sqrt(2.0);  // edge middles: R/cos 45° on the axes
  const double wm = 1.0 / std::sqrt(2.0);    // cos 45°
  NurbsSurface s;
  s.u = KnotVector(2, {0, 0, 0, 1, 1, 1});
  s.v = KnotVector(2, {0, 0, 0, 1, 1, 1});
  // Row j = 0 (η = 0) is the lower arc, i along +x; so S_ξ × S_η points along +z.
  s.points = {Vec3(-c, -c, 0), Vec3(0, -m, 0), Vec3(c, -c, 0),  //
              Vec3(-m, 0, 0),  Vec3(0, 0, 0),  Vec3(m, 0, 0),   //
              Vec3(-c, c, 0),  Vec3(0, m, 0),  Vec3(c, c, 0)};
  s.weights = {1.0, wm, 1.0, wm, 1.0, wm, 1.0, wm, 1.0};
  return s;
}

}  // namespace isoflex::geometry
