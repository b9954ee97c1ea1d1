#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "isoflex/elements/beam_element.hpp"
#include "isoflex/elements/beam_mesh.hpp"
#include "isoflex/math/frame_node.hpp"
#include "isoflex/math/rotation.hpp"
#include "support/finite_difference.hpp"

using namespace isoflex;
using namespace isoflex::test;
using elements::BeamElement;
using elements::BeamSection;

namespace {

// Stiffnesses of the order of DNSM-III §5.2 (EA = GA = 10⁵, EI = GJ = 10⁴), all different so that
// a mix-up of which stiffness goes with which strain shows.
BeamSection test_section() {
  BeamSection s;
  s.EA = 1.0e5;
  s.GA1 = 0.7e5;
  s.GA2 = 0.8e5;
  s.EI1 = 1.0e4;
  s.EI2 = 1.3e4;
  s.GJ = 0.9e4;
  s.A_rho = 20.0;
  s.M_rho1 = 10.0;
  s.M_rho2 = 7.0;
  return s;
}

VecX stack(const frame_node::Q& a, const frame_node::Q& b) {
  VecX q(24);
  q << a, b;
  return q;
}

// Node of a circular arc of curvature κ through the origin, tangent e₃ there, bending about e₁:
// triad exp(θ ê₁) at arc angle θ = κ s, centreline φ(s) = (0, cos θ − 1, sin θ)/κ, so φ′ = d₃.
frame_node::Q arc_node(double kappa, double s) {
  const double th = kappa * s;
  return frame_node::make(Vec3(0.0, std::cos(th) - 1.0, std::sin(th)) / kappa,
                          rodrigues(Vec3(th, 0.0, 0.0)));
}

// Every 3-vector block rotated by R, positions also translated by c: a rigid motion.
VecX rigid_motion(const VecX& q, const Mat3& R, const Vec3& c) {
  VecX out(q.size());
  for (int b = 0; b < q.size() / 3; ++b) {
    out.segment<3>(3 * b) = R * q.segment<3>(3 * b);
    if (b % 4 == 0) out.segment<3>(3 * b) += c;
  }
  return out;
}

// A strongly deformed element: random positions and random (orthonormal) triads at both nodes.
VecX random_on_manifold(std::mt19937& g) {
  return stack(frame_node::make(random_vector(g, 3), random_rotation(g)),
               frame_node::make(random_vector(g, 3), random_rotation(g)));
}

struct Fixture {
  std::mt19937 g{2002};
  frame_node::Q qa = frame_node::make(Vec3(0.1, -0.2, 0.3), random_rotation(g));
  frame_node::Q qb = frame_node::make(qa.head<3>() + Vec3(0.2, 0.5, -0.4), random_rotation(g));
  // A sheared, twisted, curved reference (triads unrelated to the chord) with gravity.
  BeamElement beam{3, 7, qa, qb, test_section(), Vec3(0.0, -9.81, 1.0)};
  VecX q0 = stack(qa, qb);
};

}  // namespace

TEST(BeamElement, ContractBasics) {
  Fixture f;
  EXPECT_EQ(f.beam.nodes(), (std::vector<int>{3, 7}));
  EXPECT_NEAR(f.beam.reference_length(), std::sqrt(0.04 + 0.25 + 0.16), 1e-15);
  EXPECT_THROW(f.beam.potential(VecX::Zero(12)), std::invalid_argument);
}

TEST(BeamElement, GradientAndHessianMatchFiniteDifferences) {
  Fixture f;
  for (int trial = 0; trial < 6; ++trial) {
    // Off the manifold (perturbed reference, strongly) and on it (random triads).
    const VecX q = trial < 3 ? VecX(f.q0 + random_vector(f.g, 24, 0.5)) : random_on_manifold(f.g);
    auto V = [&](const VecX& x) -> VecX { return VecX::Constant(1, f.beam.potential(x)); };
    auto grad = [&](const VecX& x) -> VecX { return f.beam.gradient(x); };
    const VecX gr = f.beam.gradient(q);
    EXPECT_LT(rel_diff(gr.transpose(), central_jacobian(V, q)), 1e-8) << trial;
    const MatX H = f.beam.hessian(q);
    EXPECT_LT(rel_diff(H, central_jacobian(grad, q)), 1e-8) << trial;
    EXPECT_LT((H - H.transpose()).norm(), 1e-12 * H.norm());
  }
}

TEST(BeamElement, DiscreteGradientDerivativeMatchesFiniteDifferences) {
  Fixture f;
  for (int trial = 0; trial < 6; ++trial) {
    const VecX qn = trial < 3 ? VecX(f.q0 + random_vector(f.g, 24, 0.5)) : random_on_manifold(f.g);
    const VecX qn1 = trial < 3 ? VecX(f.q0 + random_vector(f.g, 24, 0.5)) : random_on_manifold(f.g);
    MatX K;
    f.beam.discrete_gradient(qn, qn1, &K);
    auto DV = [&](const VecX& x) -> VecX { return f.beam.discrete_gradient(qn, x, nullptr); };
    EXPECT_LT(rel_diff(K, central_jacobian(DV, qn1)), 1e-8) << trial;
  }
}

// DV·(qₙ₊₁ − qₙ) = V(qₙ₊₁) − V(qₙ), relative to the size of the energies involved.
TEST(BeamElement, DiscreteGradientPropertyToRoundOff) {
  Fixture f;
  double worst = 0.0;
  for (int trial = 0; trial < 200; ++trial) {
    VecX qn, qn1;
    if (trial % 3 == 0) {
      qn = f.q0 + random_vector(f.g, 24, 1.0);
      qn1 = f.q0 + random_vector(f.g, 24, 1.0);
    } else if (trial % 3 == 1) {
      qn = random_on_manifold(f.g);
      qn1 = random_on_manifold(f.g);
    } else {  // a small step on the manifold, as in a time step
      qn = random_on_manifold(f.g);
      frame_node::Q a = qn.head<12>(), b = qn.tail<12>();
      qn1 = stack(frame_node::update(a, random_vector(f.g, 6, 0.05)),
                  frame_node::update(b, random_vector(f.g, 6, 0.05)));
    }
    const double Vn = f.beam.potential(qn), Vn1 = f.beam.potential(qn1);
    const VecX dv = f.beam.discrete_gradient(qn, qn1, nullptr);
    const double err =
        std::abs(dv.dot(qn1 - qn) - (Vn1 - Vn)) / std::max(std::abs(Vn), std::abs(Vn1));
    worst = std::max(worst, err);
  }
  EXPECT_LT(worst, 1e-13);
  RecordProperty("worst_relative_error", std::to_string(worst));
}

TEST(BeamElement, DiscreteGradientAtEqualArgumentsIsTheGradient) {
  Fixture f;
  for (int trial = 0; trial < 4; ++trial) {
    const VecX q = trial < 2 ? VecX(f.q0 + random_vector(f.g, 24, 0.5)) : random_on_manifold(f.g);
    MatX K;
    const VecX dv = f.beam.discrete_gradient(q, q, &K);
    const VecX gr = f.beam.gradient(q);
    EXPECT_LT((dv - gr).norm(), 1e-14 * gr.norm());
    // and ∂DV/∂qₙ₊₁(q, q) = ½ Hessian.
    EXPECT_LT((K - 0.5 * MatX(f.beam.hessian(q))).norm(), 1e-14 * K.norm());
  }
}

// The discrete gradient respects the momentum maps (docs/theory/rigid-body.md §9): without gravity
// Σ DV_φ = 0 and Σ_k q_{k,n+½} × DV_k = 0 — the conditions for conservation of p and L.
TEST(BeamElement, DiscreteGradientHasNoNetForceOrMoment) {
  std::mt19937 g(7);
  const auto nodes = elements::straight_beam_nodes(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), 1);
  BeamElement beam(0, 1, nodes[0], nodes[1], test_section());
  for (int trial = 0; trial < 10; ++trial) {
    const VecX qn = random_on_manifold(g), qn1 = random_on_manifold(g);
    const VecX dv = beam.discrete_gradient(qn, qn1, nullptr);
    const VecX qm = 0.5 * (qn + qn1);
    Vec3 force = Vec3::Zero(), moment = Vec3::Zero();
    for (int b = 0; b < 8; ++b) {
      if (b % 4 == 0) force += dv.segment<3>(3 * b);
      moment += qm.segment<3>(3 * b).cross(dv.segment<3>(3 * b));
    }
    EXPECT_LT(force.norm(), 1e-13 * dv.norm()) << trial;
    EXPECT_LT(moment.norm(), 1e-13 * dv.norm() * qm.norm()) << trial;
  }
}

TEST(BeamElement, RigidMotionGivesZeroStrainsAndGradient) {
  Fixture f;
  BeamElement weightless(0, 1, f.qa, f.qb, test_section());
  for (int trial = 0; trial < 10; ++trial) {
    const Mat3 R = random_rotation(f.g);
    const Vec3 c = random_vector(f.g, 3, 5.0);
    const VecX q = rigid_motion(f.q0, R, c);
    const auto e = weightless.strains(q);
    EXPECT_LT(e.Gamma.norm() + e.K.norm(), 1e-14) << trial;
    // Scale: a unit strain gives forces of order max(C) = EA, so round-off is 1e-14 EA.
    EXPECT_LT(weightless.gradient(q).norm(), 1e-14 * test_section().EA) << trial;
    EXPECT_LT(std::abs(weightless.potential(q)), 1e-20) << trial;
  }
}

TEST(BeamElement, PotentialInvariantUnderRigidMotion) {
  Fixture f;
  BeamElement weightless(0, 1, f.qa, f.qb, test_section());
  for (int trial = 0; trial < 10; ++trial) {
    const VecX q = f.q0 + random_vector(f.g, 24, 0.5);
    const VecX qr = rigid_motion(q, random_rotation(f.g), random_vector(f.g, 3, 5.0));
    const double V = weightless.potential(q);
    EXPECT_NEAR(weightless.potential(qr), V, 1e-13 * V) << trial;
    const auto e = weightless.strains(q), er = weightless.strains(qr);
    EXPECT_LT((e.Gamma - er.Gamma).norm() + (e.K - er.K).norm(), 1e-13) << trial;
  }
  // With gravity: invariant under rotations about g and translations orthogonal to g.
  const Vec3 gdir = Vec3(0.0, -9.81, 1.0).normalized();
  const VecX q = f.q0 + random_vector(f.g, 24, 0.5);
  const VecX qr = rigid_motion(q, rodrigues(0.7 * gdir), gdir.unitOrthogonal() * 3.0);
  EXPECT_NEAR(f.beam.potential(qr), f.beam.potential(q), 1e-12 * std::abs(f.beam.potential(q)));
}

TEST(BeamElement, StraightReferenceHasStandardReferenceStrains) {
  const auto nodes = elements::straight_beam_nodes(Vec3(1, 2, 3), Vec3(1, 2, 3) + Vec3(2, -1, 2),
                                                   Vec3(0, 0, 1), 1);
  BeamElement beam(0, 1, nodes[0], nodes[1], test_section());
  EXPECT_NEAR(beam.reference_length(), 3.0, 1e-15);
  const auto e0 = beam.reference_strains();
  EXPECT_LT((e0.Gamma - Vec3(0, 0, 1)).norm(), 1e-15);  // Γ⁰ = (0, 0, 1): d₃ is the axis
  EXPECT_LT(e0.K.norm(), 1e-15);
}

TEST(BeamElement, StrainsOfKnownDeformations) {
  const double L = 0.8;
  const BeamSection s = test_section();
  const auto nodes = elements::straight_beam_nodes(Vec3::Zero(), Vec3(0, 0, L), Vec3(1, 0, 0), 1);
  BeamElement beam(0, 1, nodes[0], nodes[1], s);
  const VecX q0 = stack(nodes[0], nodes[1]);
  {  // Pure stretch by λ: Γ₃ = λ − 1, n₃ = EA(λ − 1), everything else zero.
    const double lambda = 1.37;
    VecX q = q0;
    q.segment<3>(12) *= lambda;
    const auto e = beam.strains(q);
    EXPECT_LT((e.Gamma - Vec3(0, 0, lambda - 1)).norm(), 1e-15);
    EXPECT_LT(e.K.norm(), 1e-15);
    const auto r = beam.stress_resultants(q);
    EXPECT_NEAR(r.n(2), s.EA * (lambda - 1), 1e-10);
    EXPECT_NEAR(beam.potential(q), 0.5 * L * s.EA * (lambda - 1) * (lambda - 1), 1e-9);
  }
  {  // Shear: node b moved by γ L along d₁ (triads fixed) gives Γ₁ = γ; along d₂ gives Γ₂.
    const double gamma = 0.21;
    VecX q = q0;
    q.segment<3>(12) += gamma * L * Vec3(1, 0, 0) - 0.5 * gamma * L * Vec3(0, 1, 0);
    const auto e = beam.strains(q);
    EXPECT_LT((e.Gamma - Vec3(gamma, -0.5 * gamma, 0)).norm(), 1e-15);
    EXPECT_LT(e.K.norm(), 1e-15);
    EXPECT_NEAR(beam.stress_resultants(q).n(0), s.GA1 * gamma, 1e-10);
  }
  {  // Twist: triad b rotated by α about d₃ gives K₃ = sin α / L (→ α/L), right-handed positive.
    const double alpha = 0.3;
    VecX q = q0;
    q.tail<12>() = frame_node::make(Vec3(0, 0, L), rodrigues(Vec3(0, 0, alpha)));
    const auto e = beam.strains(q);
    EXPECT_LT((e.K - Vec3(0, 0, std::sin(alpha) / L)).norm(), 1e-14);
    EXPECT_LT(e.Gamma.norm(), 1e-15);
    EXPECT_NEAR(beam.stress_resultants(q).m(2), s.GJ * std::sin(alpha) / L, 1e-9);
  }
  {  // Uniform bending onto an arc of curvature κ about d₁ (arc length L), and about d₂:
     // K = sin(κL)/L along the bending axis, Γ₃ = sin(κL)/(κL) − 1, no shear.
    const double kappa = 0.9, alpha = kappa * L;
    const VecX q = stack(arc_node(kappa, 0.0), arc_node(kappa, L));
    const auto e = beam.strains(q);
    EXPECT_LT((e.K - Vec3(std::sin(alpha) / L, 0, 0)).norm(), 1e-14);
    EXPECT_LT((e.Gamma - Vec3(0, 0, std::sin(alpha) / alpha - 1)).norm(), 1e-15);
    // Bending about d₂: the same arc, rotated by 90° about e₃ (e₁ ↦ e₂).
    const Mat3 Rz = rodrigues(Vec3(0, 0, std::numbers::pi / 2));
    VecX q2 = rigid_motion(q, Rz, Vec3::Zero());
    // Conjugate the triads (D ↦ Rz D Rzᵀ) so that the triad at s = 0 is again (e₁, e₂, e₃).
    for (int n = 0; n < 2; ++n) {
      const Mat3 D = frame_node::directors(q2.segment<12>(12 * n)) * Rz.transpose();
      q2.segment<12>(12 * n) = frame_node::make(q2.segment<3>(12 * n), D);
    }
    const auto e2 = beam.strains(q2);
    EXPECT_LT((e2.K - Vec3(0, std::sin(alpha) / L, 0)).norm(), 1e-14);
    EXPECT_LT((e2.Gamma - Vec3(0, 0, std::sin(alpha) / alpha - 1)).norm(), 1e-15);
    // Refinement: an element of length h on the arc has K₁ = sin(κh)/h → κ at second order.
    for (const double h : {0.4, 0.2, 0.1}) {
      const auto na = elements::straight_beam_nodes(Vec3::Zero(), Vec3(0, 0, h), Vec3(1, 0, 0), 1);
      BeamElement short_beam(0, 1, na[0], na[1], s);
      const double K1 = short_beam.strains(stack(arc_node(kappa, 0.0), arc_node(kappa, h))).K(0);
      EXPECT_NEAR(K1, kappa, kappa * kappa * kappa * h * h / 6 * 1.001) << h;
      EXPECT_GT(std::abs(K1 - kappa), kappa * kappa * kappa * h * h / 6 * 0.98) << h;
    }
  }
}

// A reference on a circular arc (initial curvature through the reference triads) is stress free,
// its K⁰ is the discrete curvature, and bending it onto another arc gives the difference.
TEST(BeamElement, InitiallyCurvedReference) {
  const double kappa0 = 1.5, kappa1 = 0.4, ds = 0.25;  // arc length per element
  const int n = 6;
  const double alpha0 = kappa0 * ds, alpha1 = kappa1 * ds;
  const double chord = 2.0 * std::sin(alpha0 / 2) / kappa0;
  std::mt19937 g(5);
  for (int e = 0; e < n; ++e) {
    const auto qa = arc_node(kappa0, e * ds), qb = arc_node(kappa0, (e + 1) * ds);
    BeamElement beam(e, e + 1, qa, qb, test_section());
    EXPECT_NEAR(beam.reference_length(), chord, 1e-14);
    const VecX q0 = stack(qa, qb);
    const auto s0 = beam.strains(q0);
    EXPECT_LT(s0.Gamma.norm() + s0.K.norm(), 1e-15);
    EXPECT_LT(beam.gradient(q0).norm(), 1e-14 * test_section().EA);
    EXPECT_NEAR(beam.reference_strains().K(0), std::sin(alpha0) / chord, 1e-13);
    // Still zero after a rigid motion of the curved reference.
    const auto sr = beam.strains(rigid_motion(q0, random_rotation(g), random_vector(g, 3)));
    EXPECT_LT(sr.Gamma.norm() + sr.K.norm(), 1e-14);
    // Rebent onto the arc of curvature κ₁ with the same arc length: uniform strain in every
    // element, K₁ = (sin α₁ − sin α₀)/L₀, Γ₃ = (sin α₁/κ₁ − sin α₀/κ₀)/L₀.
    const VecX q1 = stack(arc_node(kappa1, e * ds), arc_node(kappa1, (e + 1) * ds));
    const auto s1 = beam.strains(q1);
    EXPECT_NEAR(s1.K(0), (std::sin(alpha1) - std::sin(alpha0)) / chord, 1e-13);
    EXPECT_NEAR(s1.Gamma(2), (std::sin(alpha1) / kappa1 - std::sin(alpha0) / kappa0) / chord,
                1e-14);
    EXPECT_LT(s1.K.tail<2>().norm() + s1.Gamma.head<2>().norm(), 1e-14);
  }
}

TEST(BeamElement, MassMatrix) {
  const BeamSection s = test_section();
  const double L = 1.7;
  const auto nodes = elements::straight_beam_nodes(Vec3(0, 1, 0), Vec3(L, 1, 0), Vec3(0, 1, 1), 1);
  BeamElement beam(0, 1, nodes[0], nodes[1], s);
  const MatX M = beam.mass();
  ASSERT_EQ(M.rows(), 24);
  EXPECT_EQ((M - M.transpose()).norm(), 0.0);
  // Translation with velocity v: kinetic energy ½ A_ρ L₀ |v|² (total mass A_ρ L₀).
  const Vec3 v(0.3, -1.2, 0.5);
  VecX qdot = VecX::Zero(24);
  qdot.segment<3>(0) = v;
  qdot.segment<3>(12) = v;
  EXPECT_NEAR(qdot.dot(M * qdot), s.A_rho * L * v.squaredNorm(), 1e-12);
  // Spin ω about the axis: ḋ_κ = ω × d_κ, T = ½ (M_ρ¹ + M_ρ²) L ω².
  const double w = 2.5;
  const Vec3 omega = w * frame_node::director(nodes[0], 2);
  VecX spin = VecX::Zero(24);
  for (int n = 0; n < 2; ++n)
    for (int i = 0; i < 3; ++i)
      spin.segment<3>(12 * n + 3 + 3 * i) = omega.cross(frame_node::director(nodes[n], i));
  EXPECT_NEAR(spin.dot(M * spin), (s.M_rho1 + s.M_rho2) * L * w * w, 1e-11);
  // Positive semi-definite: eigenvalues of (L/6)[[2,1],[1,2]] times ρ_f, i.e. L/6 and L/2 times
  // A_ρ, M_ρ¹, M_ρ², and six zeros (d₃ carries no inertia).
  Eigen::SelfAdjointEigenSolver<MatX> eig(M);
  EXPECT_GT(eig.eigenvalues().minCoeff(), -1e-14);
  int zeros = 0;
  for (int i = 0; i < 24; ++i) zeros += std::abs(eig.eigenvalues()(i)) < 1e-12;
  EXPECT_EQ(zeros, 6);
  EXPECT_NEAR(eig.eigenvalues().maxCoeff(), L / 2 * s.A_rho, 1e-12);
}

TEST(BeamElement, GravityPotential) {
  const BeamSection s = test_section();
  const Vec3 gvec(0, 0, -9.81);
  const auto nodes = elements::straight_beam_nodes(Vec3(0, 0, 1), Vec3(2, 0, 3), Vec3(0, 1, 0), 1);
  BeamElement beam(0, 1, nodes[0], nodes[1], s, gvec);
  const VecX q0 = stack(nodes[0], nodes[1]);
  const double m = s.A_rho * beam.reference_length();
  EXPECT_NEAR(beam.potential(q0), -m * gvec.dot(Vec3(1, 0, 2)), 1e-12);  // at the centre
  // Gravity is linear: it adds the same constant force to the gradient and the discrete gradient.
  EXPECT_NEAR(beam.gradient(q0).segment<3>(0).dot(gvec) / gvec.squaredNorm(), -0.5 * m, 1e-12);
}

TEST(BeamElement, RejectsBadInput) {
  const auto nodes = elements::straight_beam_nodes(Vec3::Zero(), Vec3(1, 0, 0), Vec3(0, 1, 0), 1);
  const BeamSection s = test_section();
  EXPECT_THROW(BeamElement(0, 1, nodes[0], nodes[0], s), std::invalid_argument);
  BeamSection bad = s;
  bad.GJ = std::nan("");
  EXPECT_THROW(BeamElement(0, 1, nodes[0], nodes[1], bad), std::invalid_argument);
  bad = s;
  bad.M_rho1 = -1.0;
  EXPECT_THROW(BeamElement(0, 1, nodes[0], nodes[1], bad), std::invalid_argument);
  frame_node::Q skewed = nodes[1];
  skewed.segment<3>(3) *= 1.01;
  EXPECT_THROW(BeamElement(0, 1, nodes[0], skewed, s), std::invalid_argument);
}

TEST(BeamMesh, StraightBeamNodes) {
  const Vec3 a(1, -1, 0.5), b(3, 1, -0.5);
  const auto nodes = elements::straight_beam_nodes(a, b, Vec3(0, 0, 2), 4);
  ASSERT_EQ(nodes.size(), 5u);
  const Vec3 axis = (b - a).normalized();
  for (int i = 0; i <= 4; ++i) {
    EXPECT_LT((frame_node::phi(nodes[i]) - (a + i / 4.0 * (b - a))).norm(), 1e-15);
    const Mat3 R = frame_node::directors(nodes[i]);
    EXPECT_LT((R.transpose() * R - Mat3::Identity()).norm(), 1e-15);
    EXPECT_NEAR(R.determinant(), 1.0, 1e-15);
    EXPECT_LT((R.col(2) - axis).norm(), 1e-15);
    EXPECT_NEAR(R.col(1).dot(Vec3(0, 0, 1)), 0.0, 1e-15);  // d₁ in the plane of axis and hint
    EXPECT_GT(R.col(0).dot(Vec3(0, 0, 1)), 0.0);
  }
  EXPECT_THROW(elements::straight_beam_nodes(a, a, Vec3(0, 0, 1), 2), std::invalid_argument);
  EXPECT_THROW(elements::straight_beam_nodes(a, b, b - a, 2), std::invalid_argument);
  EXPECT_THROW(elements::straight_beam_nodes(a, b, Vec3(0, 0, 1), 0), std::invalid_argument);
}
