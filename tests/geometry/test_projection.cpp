// Point projection (IGA-thesis §4.1.5, (4.14)–(4.15)). References: the parameters a surface point
// was generated from, the radial projection onto a cylinder, the offset along the normal of a
// smooth surface, and the boundary line/circle of a half cylinder for points beyond the edge.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "isoflex/geometry/builders.hpp"
#include "isoflex/geometry/nurbs_surface.hpp"
#include "isoflex/geometry/projection.hpp"
#include "support/geometry.hpp"

namespace isoflex::geometry {
namespace {

using namespace isoflex::test;

// Quarter cylinder with a single rational span in ξ (the textbook 90° arc), linear in η.
NurbsSurface quarter_cylinder(double R, double H) {
  NurbsSurface s;
  s.u = KnotVector(2, {0.0, 0.0, 0.0, 1.0, 1.0, 1.0});
  s.v = KnotVector(1, {0.0, 0.0, 1.0, 1.0});
  const double c = std::sqrt(0.5);
  for (const double z : {0.0, H}) {
    s.points.insert(s.points.end(), {Vec3(R, 0, z), Vec3(R, R, z), Vec3(0, R, z)});
    s.weights.insert(s.weights.end(), {1.0, c, 1.0});
  }
  return s;
}

// A doubly curved bicubic B-spline graph z = f(x, y) over [0, 5] × [0, 3.2].
NurbsSurface dome() {
  NurbsSurface s;
  s.u = KnotVector(3, {0, 0, 0, 0, 0.3, 0.6, 1, 1, 1, 1});
  s.v = KnotVector(3, {0, 0, 0, 0, 0.5, 1, 1, 1, 1});
  for (int j = 0; j < s.n_v(); ++j)
    for (int i = 0; i < s.n_u(); ++i) {
      const double x = i, y = 0.8 * j;
      s.points.push_back(Vec3(x, y, 0.6 * std::sin(0.7 * x) * std::cos(0.6 * y) + 0.05 * x * y));
      s.weights.push_back(1.0);
    }
  return s;
}

TEST(Projection, RecoversParametersOfSurfacePoints) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> U01(0.0, 1.0);
  double worst = 0.0;
  int max_it = 0;
  for (const NurbsSurface& s : {half_cylinder(1.5, 2.0), quarter_cylinder(0.8, 1.1), dome()}) {
    for (int trial = 0; trial < 200; ++trial) {
      const double xi = U01(rng), eta = U01(rng);
      const Vec3 q = evaluate(s, xi, eta).x;
      const ProjectionResult r = project_point(s, q);
      ASSERT_TRUE(r.converged());
      EXPECT_TRUE(r.on_surface);
      const double err = std::max(std::abs(r.xi - xi), std::abs(r.eta - eta));
      worst = std::max(worst, err);
      max_it = std::max(max_it, r.iterations);
      EXPECT_LT(err, 1e-12) << "xi " << xi << " eta " << eta;
      EXPECT_LE(r.distance, r.eps1);  // stopped by point coincidence, ε₁ = 1e-13 × net size
      EXPECT_LT(r.eps1, 1e-12);
      EXPECT_LT((r.point - q).norm(), 1e-12);
    }
  }
  RecordProperty("worst_parameter_error", sci(worst));
  RecordProperty("max_iterations", std::to_string(max_it));
}

// Off the surface: the closest point of a cylinder is the radial projection
// (R cos φ, R sin φ, z) of Q = (ρ cos φ, ρ sin φ, z), at distance |ρ − R|.
TEST(Projection, OffSurfacePointsProjectRadiallyOntoCylinder) {
  const double R = 1.5, H = 2.0;
  const NurbsSurface s = half_cylinder(R, H);
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> phi_d(0.02, kPi - 0.02), z_d(0.02 * H, 0.98 * H),
      rho_d(0.3 * R, 3.0 * R);
  double worst = 0.0;
  for (int trial = 0; trial < 300; ++trial) {
    const double phi = phi_d(rng), z = z_d(rng), rho = rho_d(rng);
    const Vec3 q(rho * std::cos(phi), rho * std::sin(phi), z);
    const Vec3 foot(R * std::cos(phi), R * std::sin(phi), z);
    const ProjectionResult r = project_point(s, q);
    ASSERT_TRUE(r.converged());
    const double err = (r.point - foot).norm();
    worst = std::max(worst, err);
    EXPECT_LT(err, 1e-11) << "phi " << phi << " z " << z << " rho " << rho;
    EXPECT_NEAR(r.distance, std::abs(rho - R), 1e-12);
    EXPECT_EQ(r.on_surface, std::abs(rho - R) <= r.eps1);
  }
  RecordProperty("worst_foot_error", sci(worst));
}

// Points beyond the boundary: clamped to the edge. Below the bottom (z < 0) the foot is on the
// circle z = 0 (η = 0); at angles beyond 0 (y < 0, outside the half cylinder) the closest point is
// on the straight edge x = R, y = 0 (ξ = 0); beyond both, the corner.
TEST(Projection, PointsBeyondTheBoundaryClampToTheEdge) {
  const double R = 1.5, H = 2.0;
  const NurbsSurface s = half_cylinder(R, H);
  std::mt19937 rng(29);
  std::uniform_real_distribution<double> phi_d(0.05, kPi - 0.05), z_d(0.05, H - 0.05),
      rho_d(0.5 * R, 2.0 * R), out_d(0.1, 1.0);
  for (int trial = 0; trial < 100; ++trial) {
    const double phi = phi_d(rng), rho = rho_d(rng), dz = out_d(rng), z = z_d(rng);
    {  // below the bottom edge
      const Vec3 q(rho * std::cos(phi), rho * std::sin(phi), -dz);
      const ProjectionResult r = project_point(s, q);
      ASSERT_TRUE(r.converged());
      EXPECT_EQ(r.eta, 0.0);
      const Vec3 foot(R * std::cos(phi), R * std::sin(phi), 0.0);
      EXPECT_LT((r.point - foot).norm(), 1e-11);
      EXPECT_NEAR(r.distance, std::hypot(rho - R, dz), 1e-12);
    }
    {  // above the top edge
      const Vec3 q(rho * std::cos(phi), rho * std::sin(phi), H + dz);
      const ProjectionResult r = project_point(s, q);
      EXPECT_EQ(r.eta, 1.0);
      EXPECT_LT((r.point - Vec3(R * std::cos(phi), R * std::sin(phi), H)).norm(), 1e-11);
    }
    {  // beyond the straight edge ξ = 0 (x = R, y = 0): Q = (x, −y, z) with y > 0, x > 0
      const double x = R * (0.5 + out_d(rng)), y = out_d(rng);
      const Vec3 q(x, -y, z);
      const ProjectionResult r = project_point(s, q);
      ASSERT_TRUE(r.converged());
      EXPECT_EQ(r.xi, 0.0);
      EXPECT_LT((r.point - Vec3(R, 0.0, z)).norm(), 1e-11);
      EXPECT_NEAR(r.distance, std::hypot(x - R, y), 1e-12);
    }
    {  // beyond the corner (ξ, η) = (1, 0): x < 0, y < 0, z < 0
      const Vec3 q(-R * (0.5 + out_d(rng)), -out_d(rng), -dz);
      const ProjectionResult r = project_point(s, q);
      EXPECT_EQ(r.xi, 1.0);
      EXPECT_EQ(r.eta, 0.0);
      EXPECT_LT((r.point - Vec3(-R, 0.0, 0.0)).norm(), 1e-14);
    }
  }
}

// A doubly curved surface: Q = S(ξ, η) + h n with the unit normal n and |h| below the radii of
// curvature projects back onto (ξ, η), at distance |h|.
TEST(Projection, NormalOffsetOnDoublyCurvedSurface) {
  const NurbsSurface s = dome();
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> I(0.03, 0.97), h_d(-0.2, 0.2);
  double worst = 0.0;
  for (int trial = 0; trial < 200; ++trial) {
    const double xi = I(rng), eta = I(rng), h = h_d(rng);
    const SurfacePoint p = evaluate(s, xi, eta);
    const Vec3 n = p.xu.cross(p.xv).normalized();
    const ProjectionResult r = project_point(s, p.x + h * n);
    ASSERT_TRUE(r.converged());
    const double err = std::max(std::abs(r.xi - xi), std::abs(r.eta - eta));
    worst = std::max(worst, err);
    EXPECT_LT(err, 1e-11) << "xi " << xi << " eta " << eta << " h " << h;
    EXPECT_NEAR(r.distance, std::abs(h), 1e-12);
  }
  RecordProperty("worst_parameter_error", sci(worst));
}

TEST(Projection, StartFromGivenParametersAndStopCriteria) {
  const NurbsSurface s = quarter_cylinder(1.0, 1.0);
  const Vec3 on = evaluate(s, 0.3, 0.6).x;
  const ProjectionResult a = project_point(s, on, 0.35, 0.5);
  EXPECT_EQ(a.stop, ProjectionStop::point_coincidence);
  EXPECT_NEAR(a.xi, 0.3, 1e-12);
  EXPECT_GE(a.iterations, 1);
  // Far outside along the normal: zero cosine or a vanishing update ends the iteration.
  const ProjectionResult b = project_point(s, Vec3(3.0 * on.x(), 3.0 * on.y(), on.z()));
  EXPECT_TRUE(b.stop == ProjectionStop::zero_cosine || b.stop == ProjectionStop::parameter_change);
  EXPECT_FALSE(b.on_surface);
  EXPECT_NEAR(b.xi, 0.3, 1e-12);
  EXPECT_NEAR(b.distance, 2.0, 1e-12);
  // Starting parameters outside the domain are clamped.
  const ProjectionResult c = project_point(s, on, -5.0, 7.0);
  EXPECT_NEAR(c.xi, 0.3, 1e-12);
  EXPECT_NEAR(c.eta, 0.6, 1e-12);
  // A budget of zero iterations reports that it did not converge.
  ProjectionOptions o;
  o.max_iterations = 0;
  const ProjectionResult d = project_point(s, on, 0.9, 0.1, o);
  EXPECT_EQ(d.stop, ProjectionStop::max_iterations);
  EXPECT_FALSE(d.converged());
}

// A doubly curved rational surface: the closest point of a sphere is the radial projection
// R·Q/|Q|. The sector (azimuth 0 … π, latitude −60° … 60°, from geometry/builders) has no pole;
// the hemisphere's η = 1 edge collapses to the north pole, where S_ξ = 0.
TEST(Projection, SphereRadialProjection) {
  const double R = 0.9;
  const NurbsSurface sector = sphere_sector(R, kPi, -kPi / 3, kPi / 3);
  std::mt19937 rng(37);
  std::uniform_real_distribution<double> az(0.02, kPi - 0.02), lat(-kPi / 3 + 0.02, kPi / 3 - 0.02),
      rho_d(0.2 * R, 3.0 * R);
  double worst = 0.0;
  for (int trial = 0; trial < 300; ++trial) {
    const double a = az(rng), b = lat(rng), rho = rho_d(rng);
    const Vec3 dir(std::cos(b) * std::cos(a), std::cos(b) * std::sin(a), std::sin(b));
    const ProjectionResult r = project_point(sector, rho * dir);
    ASSERT_TRUE(r.converged());
    const double err = (r.point - R * dir).norm();
    worst = std::max(worst, err);
    EXPECT_LT(err, 1e-11) << "azimuth " << a << " latitude " << b << " rho " << rho;
    EXPECT_NEAR(r.distance, std::abs(rho - R), 1e-12);
  }
  RecordProperty("worst_foot_error", sci(worst));

  // Near and at the degenerate pole of the hemisphere.
  const NurbsSurface hemi = hemisphere(R);
  for (const double b : {kPi / 2 - 0.3, kPi / 2 - 0.01, kPi / 2 - 1e-4}) {
    for (const double a : {0.3, 2.0, 4.0}) {
      const Vec3 dir(std::cos(b) * std::cos(a), std::cos(b) * std::sin(a), std::sin(b));
      const ProjectionResult r = project_point(hemi, 1.7 * dir);
      ASSERT_TRUE(r.converged()) << a << " " << b;
      EXPECT_LT((r.point - R * dir).norm(), 1e-10) << a << " " << b;
    }
  }
  // Across the seam ξ = 0 ≡ ξ = 1 of the closed hemisphere: a point just before azimuth 2π must
  // not be clamped to the seam at ξ = 0.
  for (const double a : {2 * kPi - 0.05, 2 * kPi - 1e-3, 1e-3, 0.05}) {
    const Vec3 dir(std::cos(0.5) * std::cos(a), std::cos(0.5) * std::sin(a), std::sin(0.5));
    const ProjectionResult r = project_point(hemi, 1.3 * dir);
    ASSERT_TRUE(r.converged()) << a;
    EXPECT_LT((r.point - R * dir).norm(), 1e-11) << a;
  }
  const ProjectionResult pole = project_point(hemi, Vec3(0.0, 0.0, 2.0));
  EXPECT_TRUE(pole.converged());
  EXPECT_EQ(pole.eta, 1.0);
  EXPECT_LT((pole.point - Vec3(0.0, 0.0, R)).norm(), 1e-14);
  EXPECT_NEAR(pole.distance, 2.0 - R, 1e-14);
}

}  // namespace
}  // namespace isoflex::geometry
