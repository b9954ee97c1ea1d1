// The dead-axis edge moment on a Kirchhoff–Love patch (loads/kl_edge_moment.hpp): its forces are
// the gradient of m ∫ θ dS (a rigid turn of the edge about the axis by δ does work m L δ), and its
// tangent matches central differences of the forces.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "isoflex/geometry/builders.hpp"
#include "isoflex/geometry/refinement.hpp"
#include "isoflex/loads/kl_edge_moment.hpp"
#include "support/finite_difference.hpp"

using namespace isoflex;
using isoflex::test::central_jacobian;
using isoflex::test::rel_diff;

namespace {
VecX positions(const geometry::NurbsSurface& s) {
  VecX x(3 * static_cast<int>(s.points.size()));
  for (std::size_t a = 0; a < s.points.size(); ++a)
    x.segment<3>(3 * static_cast<int>(a)) = s.points[a];
  return x;
}

// A 3 × 1 plate along x, cubic in both directions, with interior knots.
geometry::NurbsSurface strip() {
  return geometry::k_refine(geometry::planar_rectangle(3.0, 1.0), 2, 2, 3, 1);
}
}  // namespace

TEST(KLEdgeMoment, WorkOfARigidTurnOfTheEdge) {
  const auto s = strip();
  const double m = 2.5;
  const loads::EdgeMoment load(s, loads::PatchEdge::u1, Vec3(0, -2, 0), m);
  // Turning every control point about the y axis through the edge's line by a small δ changes θ
  // by δ on the whole edge (length 1): f · dx = m δ (rotation about −y lifts +x towards +z).
  const VecX x = positions(s);
  VecX dx = VecX::Zero(x.size());
  const double delta = 1e-7;
  for (int a = 0; a < x.size() / 3; ++a) {
    const Vec3 X = x.segment<3>(3 * a);
    dx.segment<3>(3 * a) = delta * Vec3(0, -1, 0).cross(X - Vec3(3, 0, 0));
  }
  EXPECT_NEAR(load.force(x).dot(dx), m * 1.0 * delta, 1e-12 * m * delta * 1e3);
  // A translation does no work.
  VecX shift(x.size());
  for (int a = 0; a < x.size() / 3; ++a) shift.segment<3>(3 * a) = Vec3(0.3, -0.2, 0.7);
  EXPECT_LT(std::abs(load.force(x).dot(shift)), 1e-13 * m);
}

TEST(KLEdgeMoment, TangentMatchesFiniteDifferencesAndIsSymmetric) {
  const auto s = strip();
  const loads::EdgeMoment load(s, loads::PatchEdge::v1, Vec3(1, 0.3, 0.2), 1.7);
  std::mt19937 g(5);
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  VecX x = positions(s);
  for (int i = 0; i < x.size(); ++i) x(i) += u(g);
  Eigen::SparseMatrix<double> K(x.size(), x.size());
  load.add_tangent(x, 1.0, K);
  const MatX Kd(K);
  const MatX fd = central_jacobian([&](const VecX& y) { return load.force(y); }, x);
  EXPECT_LT(rel_diff(Kd, fd), 1e-8);
  EXPECT_LT((Kd - Kd.transpose()).norm(), 1e-12 * Kd.norm());
  EXPECT_GT(Kd.norm(), 0.0);
}

TEST(KLEdgeMoment, RejectsBadInput) {
  const auto s = strip();
  EXPECT_THROW(loads::EdgeMoment(s, loads::PatchEdge::u1, Vec3::Zero(), 1.0),
               std::invalid_argument);
  EXPECT_THROW(loads::EdgeMoment(s, loads::PatchEdge::u1, Vec3::UnitY(), std::nan("")),
               std::invalid_argument);
}
