// Loads on a NURBS shell patch (loads/kl_patch_loads.hpp): resultants against independent
// closed forms, the follower tangent against central differences, moments of a point load.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <string>

#include "isoflex/geometry/builders.hpp"
#include "isoflex/geometry/refinement.hpp"
#include "isoflex/loads/kl_patch_loads.hpp"
#include "support/finite_difference.hpp"
#include "support/geometry.hpp"

using namespace isoflex;
using namespace isoflex::loads;
using isoflex::test::central_jacobian;
using isoflex::test::rel_diff;

namespace {

constexpr double kPi = std::numbers::pi;

Vec3 resultant(const VecX& f) {
  Vec3 s = Vec3::Zero();
  for (int a = 0; a < f.size() / 3; ++a) s += f.segment<3>(3 * a);
  return s;
}

Vec3 moment_about(const geometry::NurbsSurface& s, const VecX& f, const Vec3& O) {
  Vec3 M = Vec3::Zero();
  for (int a = 0; a < f.size() / 3; ++a)
    M += (s.points[static_cast<std::size_t>(a)] - O).cross(f.segment<3>(3 * a));
  return M;
}

VecX positions(const geometry::NurbsSurface& s) {
  VecX x(3 * static_cast<int>(s.points.size()));
  for (std::size_t a = 0; a < s.points.size(); ++a)
    x.segment<3>(3 * static_cast<int>(a)) = s.points[a];
  return x;
}

// A biquadratic/cubic flat rectangle [0, 2] × [0, 3] with several elements.
geometry::NurbsSurface flat_rectangle() {
  return geometry::k_refine(geometry::planar_rectangle(2.0, 3.0), 1, 2, 3, 2);
}

// Cylinder sector R = 1.5, L = 2, 120° (two rational quadratic segments, weights cos 30°).
geometry::NurbsSurface cylinder() {
  return geometry::k_refine(geometry::cylinder_sector(1.5, 2.0, 2.0 * kPi / 3.0), 0, 1, 2, 2);
}

}  // namespace

TEST(KLPatchLoads, UniformPressureOnFlatRectangle) {
  const auto s = flat_rectangle();
  const double p = 5.0, area = 6.0;
  const DeadPressure dead(s, p);
  const FollowerPressure follower(s, p);
  const VecX X = positions(s);
  const Vec3 expected(0.0, 0.0, p * area);  // builders orient planar patches along +z
  EXPECT_LT((resultant(dead.force(X)) - expected).norm(), 1e-12 * p * area);
  EXPECT_LT((resultant(follower.force(X)) - expected).norm(), 1e-12 * p * area);
  // A rigid rotation of x turns the follower resultant with it; the dead one stays.
  const Mat3 Q = Eigen::AngleAxisd(0.4, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  VecX xr = X;
  for (int a = 0; a < X.size() / 3; ++a) xr.segment<3>(3 * a) = Q * X.segment<3>(3 * a);
  EXPECT_LT((resultant(follower.force(xr)) - Q * expected).norm(), 1e-12 * p * area);
  EXPECT_LT((resultant(dead.force(xr)) - expected).norm(), 1e-12 * p * area);
  // Area force and self-weight.
  const Vec3 q(1.0, -2.0, 0.5);
  EXPECT_LT((resultant(AreaForce(s, q).force(X)) - area * q).norm(), 1e-12 * area * q.norm());
  const Vec3 g(0, 0, -9.81);
  const AreaForce w = self_weight(s, 7800.0, 0.01, g);
  EXPECT_NEAR(resultant(w.force(X)).z(), -7800.0 * 0.01 * 9.81 * area, 1e-9);
  EXPECT_THROW(self_weight(s, -1.0, 0.01, g), std::invalid_argument);
}

// Dead pressure on curved rational patches: ∫ p A₃ dA = p × (vector area), computed in closed form.
TEST(KLPatchLoads, DeadPressureResultantOnCurvedNurbs) {
  const double p = 2.5;
  {
    // Cylinder sector: ∫ n dA = R L (sin θ, 1 − cos θ, 0).
    const double R = 1.5, L = 2.0, th = 2.0 * kPi / 3.0;
    const auto s = cylinder();
    ASSERT_TRUE(s.is_rational());
    const Vec3 expected = p * R * L * Vec3(std::sin(th), 1.0 - std::cos(th), 0.0);
    const Vec3 got = resultant(DeadPressure(s, p, TimeFunction(1.0), {6, 6}).force(positions(s)));
    RecordProperty("cylinder_error", isoflex::test::sci((got - expected).norm() / expected.norm()));
    EXPECT_LT((got - expected).norm(), 1e-9 * expected.norm());
  }
  {
    // Sphere octant R: each coordinate plane sees a quarter disc, ∫ n dA = πR²/4 (1, 1, 1).
    const double R = 2.0;
    const auto s = geometry::refine_uniform(geometry::sphere_octant(R), 3, 3);
    ASSERT_TRUE(s.is_rational());
    const Vec3 expected = p * kPi * R * R / 4.0 * Vec3(1, 1, 1);
    const Vec3 got = resultant(DeadPressure(s, p, TimeFunction(1.0), {8, 8}).force(positions(s)));
    RecordProperty("octant_error", isoflex::test::sci((got - expected).norm() / expected.norm()));
    EXPECT_LT((got - expected).norm(), 1e-8 * expected.norm());
    // Moment about the centre: p A₃ is radial, so it vanishes.
    const VecX f = DeadPressure(s, p, TimeFunction(1.0), {8, 8}).force(positions(s));
    EXPECT_LT(moment_about(s, f, Vec3::Zero()).norm(), 1e-8 * R * expected.norm());
  }
}

TEST(KLPatchLoads, FollowerPressureTangentMatchesFiniteDifferences) {
  std::mt19937 g(7);
  const auto s = cylinder();
  const FollowerPressure load(s, 3.0);
  const VecX x =
      positions(s) + isoflex::test::random_vector(g, 3 * static_cast<int>(s.points.size()), 0.05);
  SpMat K(x.size(), x.size());
  load.add_tangent(x, 1.0, K);
  K.makeCompressed();
  const MatX Kd(K);
  const MatX J = central_jacobian([&](const VecX& y) -> VecX { return load.force(y); }, x);
  const double err = rel_diff(Kd, J);
  RecordProperty("tangent_rel_error", isoflex::test::sci(err));
  EXPECT_LT(err, 1e-8);
  // Not symmetric on an open patch.
  const double skew_part = (Kd - Kd.transpose()).norm() / Kd.norm();
  RecordProperty("skew_part", isoflex::test::sci(skew_part));
  EXPECT_GT(skew_part, 1e-2);
  // A scale is applied: K += −2 ∂f/∂x.
  SpMat K2(x.size(), x.size());
  load.add_tangent(x, -2.0, K2);
  EXPECT_LT(rel_diff(MatX(K2), -2.0 * J), 1e-8);
}

TEST(KLPatchLoads, LineLoadTotalAndSupport) {
  const double R = 1.5, th = 2.0 * kPi / 3.0, L = 2.0;
  const auto s = cylinder();
  const Vec3 q(0.3, -1.0, 2.0);
  // v0 is the arc at z = 0 (length R θ); u1 is the straight generator at angle θ (length L).
  const LineLoad arc(s, PatchEdge::v0, q, TimeFunction(1.0), 6);
  EXPECT_NEAR(arc.edge_length(), R * th, 1e-10);
  const VecX f = arc.force(positions(s));
  EXPECT_LT((resultant(f) - R * th * q).norm(), 1e-10 * q.norm());
  // Only the edge row carries force.
  const auto row0 = edge_control_points(s, PatchEdge::v0, 0);
  for (int a = 0; a < static_cast<int>(s.points.size()); ++a) {
    const bool on_edge = std::find(row0.begin(), row0.end(), a) != row0.end();
    if (!on_edge) {
      EXPECT_EQ(f.segment<3>(3 * a).norm(), 0.0) << "control point " << a;
    }
  }
  const LineLoad gen(s, PatchEdge::u1, q);
  EXPECT_NEAR(gen.edge_length(), L, 1e-12);
  EXPECT_LT((resultant(gen.force(positions(s))) - L * q).norm(), 1e-12);
  // Moment of the generator load about the origin: ∫₀ᴸ (R cos θ, R sin θ, z) × q dz.
  const Vec3 c(R * std::cos(th), R * std::sin(th), L / 2.0);
  EXPECT_LT((moment_about(s, gen.force(positions(s)), Vec3::Zero()) - L * c.cross(q)).norm(),
            1e-11);
}

TEST(KLPatchLoads, PointLoadForceAndMoment) {
  const auto s = cylinder();
  const Vec3 P = geometry::evaluate(s, 0.37, 0.61).x;
  const Vec3 F(1.0, -2.0, 0.7);
  const PointLoad load(s, P, F);
  EXPECT_NEAR(load.xi(), 0.37, 1e-9);
  EXPECT_NEAR(load.eta(), 0.61, 1e-9);
  const VecX f = load.force(positions(s));
  EXPECT_LT((resultant(f) - F).norm(), 1e-13);
  const Vec3 O(0.3, 0.2, -0.4);
  EXPECT_LT((moment_about(s, f, O) - (P - O).cross(F)).norm(), 1e-12);
  // At given parameters: the same forces.
  EXPECT_LT((PointLoad(s, load.xi(), load.eta(), F).force(positions(s)) - f).norm(), 1e-15);
  // Off the surface: 1 mm outside a radius of 1.5.
  const Vec3 off = P * (1.0 + 1e-3 / 1.5);
  const Vec3 off_pt(off.x(), off.y(), P.z());
  try {
    PointLoad bad(s, off_pt, F);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("distance 1.000e-03"), std::string::npos) << msg;
    EXPECT_NE(msg.find("tolerance"), std::string::npos) << msg;
  }
  // With a tolerance above the distance it is accepted.
  EXPECT_NO_THROW(PointLoad(s, off_pt, F, TimeFunction(1.0), 2e-3));
}

TEST(KLPatchLoads, LoadFactor) {
  const auto s = flat_rectangle();
  const DeadPressure a(s, 1.0);  // default λ(t) = t
  EXPECT_DOUBLE_EQ(a.factor(0.25), 0.25);
  const DeadPressure b(s, 1.0, TimeFunction(std::string("2*t^2")));
  EXPECT_DOUBLE_EQ(b.factor(0.5), 0.5);
}
