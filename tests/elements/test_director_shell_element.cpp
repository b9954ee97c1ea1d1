#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <iomanip>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "isoflex/elements/director_shell_element.hpp"
#include "isoflex/math/rotation.hpp"
#include "support/finite_difference.hpp"

using namespace isoflex;
using namespace isoflex::test;
using elements::DirectorShellElement;
using elements::ShellMaterial;

namespace {

// Measured values for RecordProperty, with enough digits to be useful.
std::string sci(double v) {
  std::ostringstream s;
  s << std::setprecision(6) << v;
  return s.str();
}

// Membrane (Eh = 10³), bending (Eh³/12 ≈ 0.83) and shear (κ_s G h ≈ 3·10²) stiffnesses of very
// different size, so that a term paired with the wrong stiffness shows.
ShellMaterial test_material() {
  ShellMaterial m;
  m.E = 1.0e4;
  m.nu = 0.3;
  m.thickness = 0.1;
  m.density = 7.0;
  return m;
}

Vec<24> stack(const std::array<Vec3, 4>& x, const std::array<Vec3, 4>& d) {
  Vec<24> q;
  for (int a = 0; a < 4; ++a) {
    q.segment<3>(6 * a) = x[a];
    q.segment<3>(6 * a + 3) = d[a];
  }
  return q;
}

// A curved (non-planar), skewed, non-rectangular reference whose directors are neither parallel
// nor exactly normal: the surface normal at each corner, tilted by a different small rotation.
Vec<24> curved_reference() {
  const std::array<Vec3, 4> x = {Vec3(0.0, 0.0, 0.0), Vec3(1.1, 0.15, 0.08),
                                 Vec3(0.95, 1.05, -0.12), Vec3(-0.1, 0.9, 0.1)};
  const std::array<Vec3, 4> tilt = {Vec3(0.05, -0.1, 0.02), Vec3(-0.08, 0.03, 0.1),
                                    Vec3(0.1, 0.07, -0.05), Vec3(-0.02, -0.09, 0.04)};
  std::array<Vec3, 4> d;
  for (int a = 0; a < 4; ++a) {
    // Corner normal of the bilinear surface: (x_next − x_a) × (x_prev − x_a).
    const Vec3 n = (x[(a + 1) % 4] - x[a]).cross(x[(a + 3) % 4] - x[a]).normalized();
    d[a] = rodrigues(tilt[a]) * n;
  }
  return stack(x, d);
}

// φ blocks rotated and translated, director blocks rotated.
VecX rigid_motion(const VecX& q, const Mat3& R, const Vec3& c) {
  VecX out(q.size());
  for (int b = 0; b < q.size() / 3; ++b) {
    out.segment<3>(3 * b) = R * q.segment<3>(3 * b);
    if (b % 2 == 0) out.segment<3>(3 * b) += c;
  }
  return out;
}

struct Fixture {
  std::mt19937 g{1603};
  Vec<24> q0 = curved_reference();
  Vec3 gravity{0.0, -9.81, 1.0};
  DirectorShellElement ans{{2, 5, 9, 4}, q0, test_material(), gravity, true};
  DirectorShellElement plain{{2, 5, 9, 4}, q0, test_material(), gravity, false};
  // Typical internal force: a unit strain in the membrane over an element of size 1.
  double force_scale = test_material().E * test_material().thickness;

  // A strongly deformed configuration: off the manifold (q₀ plus a large perturbation) or on it
  // (moved positions, random unit directors).
  VecX deformed(int kind) {
    if (kind % 2 == 0) return q0 + random_vector(g, 24, 0.4);
    VecX q = q0;
    for (int a = 0; a < 4; ++a) {
      q.segment<3>(6 * a) += random_vector(g, 3, 0.4);
      q.segment<3>(6 * a + 3) = random_rotation(g) * Vec3::UnitZ();
    }
    return q;
  }
};

}  // namespace

TEST(DirectorShellElement, ContractBasics) {
  Fixture f;
  EXPECT_EQ(f.ans.nodes(), (std::vector<int>{2, 5, 9, 4}));
  EXPECT_EQ(f.ans.gradient(f.q0).size(), 24);
  EXPECT_EQ(f.ans.mass().rows(), 24);
  EXPECT_THROW(f.ans.potential(VecX::Zero(18)), std::invalid_argument);
  EXPECT_THROW(f.ans.discrete_gradient(f.q0, VecX::Zero(25), nullptr), std::invalid_argument);
  // The reference is stress free (curved, skewed, tilted directors) with or without ANS.
  for (const bool ans : {true, false}) {
    DirectorShellElement weightless({0, 1, 2, 3}, f.q0, test_material(), Vec3::Zero(), ans);
    EXPECT_LT(std::abs(weightless.potential(f.q0)), 1e-28 * f.force_scale) << ans;
    EXPECT_LT(weightless.gradient(f.q0).norm(), 1e-14 * f.force_scale) << ans;
  }
}

TEST(DirectorShellElement, GradientAndStiffnessMatchFiniteDifferences) {
  Fixture f;
  double worst_g = 0.0, worst_k = 0.0;
  for (const DirectorShellElement* e : {&f.ans, &f.plain}) {
    for (int trial = 0; trial < 4; ++trial) {
      const VecX q = f.deformed(trial);
      auto V = [&](const VecX& x) -> VecX { return VecX::Constant(1, e->potential(x)); };
      auto grad = [&](const VecX& x) -> VecX { return e->gradient(x); };
      const double eg = rel_diff(e->gradient(q).transpose(), central_jacobian(V, q));
      const MatX K = e->stiffness(q);
      const double ek = rel_diff(K, central_jacobian(grad, q));
      EXPECT_LT(eg, 1e-8) << trial;
      EXPECT_LT(ek, 1e-8) << trial;
      EXPECT_LT((K - K.transpose()).norm(), 1e-13 * K.norm());
      worst_g = std::max(worst_g, eg);
      worst_k = std::max(worst_k, ek);
    }
  }
  RecordProperty("worst_gradient_fd", sci(worst_g));
  RecordProperty("worst_stiffness_fd", sci(worst_k));
}

TEST(DirectorShellElement, DiscreteGradientDerivativeMatchesFiniteDifferences) {
  Fixture f;
  double worst = 0.0;
  for (const DirectorShellElement* e : {&f.ans, &f.plain}) {
    for (int trial = 0; trial < 4; ++trial) {
      const VecX qn = f.deformed(trial), qn1 = f.deformed(trial + 1);
      MatX K;
      e->discrete_gradient(qn, qn1, &K);
      ASSERT_EQ(K.rows(), 24);
      auto DV = [&](const VecX& x) -> VecX { return e->discrete_gradient(qn, x, nullptr); };
      const double err = rel_diff(K, central_jacobian(DV, qn1));
      EXPECT_LT(err, 1e-8) << trial;
      worst = std::max(worst, err);
    }
  }
  RecordProperty("worst_dv_dqn1_fd", sci(worst));
}

// The mixed integration point tangent (docs/theory/schemes.md §6): the same force; linearized at
// qₙ₊₁ itself it is the exact ∂DV/∂qₙ₊₁ with no stress force; linearized at a point at distance
// ε it differs from it by O(ε²) (Ê − E(qₙ₊₁) = −½ ΔqᵀHΔq, E quadratic); at a Newton start it
// takes the stresses of the strains at qₙ.
TEST(DirectorShellElement, MixedTangentIsTheExactOneUpToTheSquareOfTheLinearizationDistance) {
  Fixture f;
  for (const DirectorShellElement* e : {&f.ans, &f.plain}) {
    for (int trial = 0; trial < 3; ++trial) {
      const VecX qn = f.deformed(trial), qn1 = f.deformed(trial + 1);
      MatX K;
      const VecX dv = e->discrete_gradient(qn, qn1, &K);
      Mat<24, 24> Km;
      VecX stress_force;
      const VecX dvm =
          e->mixed_discrete_gradient_in_pattern(qn, qn1, &qn1, Km.data(), &stress_force);
      EXPECT_LT((dvm - dv).norm(), 1e-14 * f.force_scale) << trial;
      EXPECT_LT(rel_diff(MatX(Km), K), 1e-14) << trial;
      EXPECT_LT(stress_force.norm(), 1e-14 * f.force_scale) << trial;
      const VecX dir = random_vector(f.g, 24, 0.1);
      double diff[2];
      for (int h = 0; h < 2; ++h) {
        const VecX ql = qn1 + (h ? 0.5 : 1.0) * dir;
        e->mixed_discrete_gradient_in_pattern(qn, qn1, &ql, Km.data(), &stress_force);
        diff[h] = (MatX(Km) - K).norm();
      }
      EXPECT_GT(diff[1], 0.0) << trial;
      EXPECT_NEAR(diff[0] / diff[1], 4.0, 0.1) << trial;  // O(ε²)
      // The algorithmic dissipative stress's tangent (docs/theory/schemes.md §10) the same way.
      const VecX qp = f.deformed(trial + 2);
      Mat<24, 24> Kd = Mat<24, 24>::Zero(), Kdm = Mat<24, 24>::Zero();
      const VecX fd = e->strain_dissipation_force_in_pattern(qp, qn, qn1, 0.1, 0.8, Kd.data());
      const VecX fdm = e->mixed_strain_dissipation_force_in_pattern(qp, qn, qn1, &qn1, 0.1, 0.8,
                                                                    Kdm.data(), &stress_force);
      EXPECT_LT((fdm - fd).norm(), 1e-14 * f.force_scale) << trial;
      EXPECT_LT(rel_diff(MatX(Kdm), MatX(Kd)), 1e-14) << trial;
      EXPECT_LT(stress_force.norm(), 1e-15 * f.force_scale) << trial;
      for (int h = 0; h < 2; ++h) {
        const VecX ql = qn1 + (h ? 0.5 : 1.0) * dir;
        Kdm.setZero();
        e->mixed_strain_dissipation_force_in_pattern(qp, qn, qn1, &ql, 0.1, 0.8, Kdm.data(),
                                                     &stress_force);
        diff[h] = (MatX(Kdm) - MatX(Kd)).norm();
      }
      EXPECT_NEAR(diff[0] / diff[1], 4.0, 0.1) << trial;
      // At a start Ê = E(qₙ): exact where qₙ₊₁ has qₙ's strains, a rigid motion of it.
      const VecX moved = rigid_motion(qn, rodrigues(Vec3(0.3, -0.2, 0.5)), Vec3(0.1, 0.2, -0.3));
      e->discrete_gradient(qn, moved, &K);
      e->mixed_discrete_gradient_in_pattern(qn, moved, nullptr, Km.data(), nullptr);
      EXPECT_LT(rel_diff(MatX(Km), K), 1e-12) << trial;
      e->mixed_discrete_gradient_in_pattern(qn, qn1, nullptr, Km.data(), nullptr);
      e->discrete_gradient(qn, qn1, &K);
      EXPECT_GT(rel_diff(MatX(Km), K), 1e-6) << trial;
    }
  }
}

// DV·(qₙ₊₁ − qₙ) = V(qₙ₊₁) − V(qₙ), relative to the size of the energies involved.
TEST(DirectorShellElement, DiscreteGradientPropertyToRoundOff) {
  Fixture f;
  double worst = 0.0;
  for (const DirectorShellElement* e : {&f.ans, &f.plain}) {
    for (int trial = 0; trial < 100; ++trial) {
      VecX qn = f.deformed(trial), qn1;
      if (trial % 3 < 2) {
        qn1 = f.deformed(trial + 1);  // a large move
      } else {                        // a small step on the manifold, as in a time step
        qn = f.deformed(1);
        qn1 = qn;
        for (int a = 0; a < 4; ++a) {
          qn1.segment<3>(6 * a) += random_vector(f.g, 3, 0.02);
          qn1.segment<3>(6 * a + 3) =
              rodrigues(random_vector(f.g, 3, 0.05)) * qn.segment<3>(6 * a + 3);
        }
      }
      const double Vn = e->potential(qn), Vn1 = e->potential(qn1);
      const VecX dv = e->discrete_gradient(qn, qn1, nullptr);
      const double err =
          std::abs(dv.dot(qn1 - qn) - (Vn1 - Vn)) / std::max(std::abs(Vn), std::abs(Vn1));
      worst = std::max(worst, err);
    }
  }
  EXPECT_LT(worst, 1e-12);
  RecordProperty("worst_relative_error", sci(worst));
}

TEST(DirectorShellElement, DiscreteGradientAtEqualArgumentsIsTheGradient) {
  Fixture f;
  for (int trial = 0; trial < 4; ++trial) {
    const VecX q = f.deformed(trial);
    MatX K;
    const VecX dv = f.ans.discrete_gradient(q, q, &K);
    const VecX gr = f.ans.gradient(q);
    EXPECT_LT((dv - gr).norm(), 1e-14 * gr.norm()) << trial;
    const MatX half_k = 0.5 * MatX(f.ans.stiffness(q));
    EXPECT_LT((K - half_k).norm(), 1e-14 * K.norm()) << trial;
  }
}

TEST(DirectorShellElement, RigidMotionGivesZeroEnergyAndGradient) {
  Fixture f;
  DirectorShellElement weightless({0, 1, 2, 3}, f.q0, test_material(), Vec3::Zero());
  const Mat3 frame0 = weightless.stress_resultants(f.q0).frame;
  double worst = 0.0;
  for (int trial = 0; trial < 10; ++trial) {
    const Mat3 R = random_rotation(f.g);
    const VecX q = rigid_motion(f.q0, R, random_vector(f.g, 3, 5.0));
    EXPECT_LT(std::abs(weightless.potential(q)), 1e-24 * f.force_scale) << trial;
    const double gn = weightless.gradient(q).norm();
    EXPECT_LT(gn, 1e-12 * f.force_scale) << trial;
    worst = std::max(worst, gn / f.force_scale);
    // The resultants vanish too; the output frame is that of the reference configuration.
    const auto r = weightless.stress_resultants(q);
    EXPECT_LT(r.n.norm() + r.m.norm() + r.q.norm(), 1e-12 * f.force_scale) << trial;
    EXPECT_LT((r.frame - frame0).norm(), 1e-15) << trial;  // the reference frame, not a spatial one
  }
  RecordProperty("worst_gradient_over_Eh", sci(worst));
}

TEST(DirectorShellElement, PotentialInvariantUnderRigidMotion) {
  Fixture f;
  DirectorShellElement weightless({0, 1, 2, 3}, f.q0, test_material(), Vec3::Zero());
  for (int trial = 0; trial < 10; ++trial) {
    const VecX q = f.deformed(trial);
    const VecX qr = rigid_motion(q, random_rotation(f.g), random_vector(f.g, 3, 5.0));
    const double V = weightless.potential(q);
    ASSERT_GT(V, 0.0);
    EXPECT_NEAR(weightless.potential(qr), V, 1e-12 * V) << trial;
  }
}

// Without gravity, Σ_a DV_φa = 0 and Σ_a (φ_{a,n+½} × DV_φa + d_{a,n+½} × DV_da) = 0 for every
// pair (qₙ, qₙ₊₁): the conditions for conservation of p and L (theory-notes, Notation).
TEST(DirectorShellElement, DiscreteGradientHasNoNetForceOrMoment) {
  Fixture f;
  DirectorShellElement weightless({0, 1, 2, 3}, f.q0, test_material(), Vec3::Zero());
  for (int trial = 0; trial < 10; ++trial) {
    const VecX qn = f.deformed(trial), qn1 = f.deformed(trial + 1);
    const VecX dv = weightless.discrete_gradient(qn, qn1, nullptr);
    const VecX qm = 0.5 * (qn + qn1);
    Vec3 force = Vec3::Zero(), moment = Vec3::Zero();
    for (int b = 0; b < 8; ++b) {
      if (b % 2 == 0) force += dv.segment<3>(3 * b);
      moment += qm.segment<3>(3 * b).cross(dv.segment<3>(3 * b));
    }
    EXPECT_LT(force.norm(), 1e-14 * dv.norm()) << trial;
    EXPECT_LT(moment.norm(), 1e-14 * dv.norm() * qm.norm()) << trial;
  }
}

TEST(DirectorShellElement, MassMatrix) {
  Fixture f;
  const ShellMaterial m = test_material();
  const MatX M = f.ans.mass();
  ASSERT_EQ(M.rows(), 24);
  EXPECT_EQ((M - M.transpose()).norm(), 0.0);
  Eigen::SelfAdjointEigenSolver<MatX> eig(M);
  EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0);
  const double area = f.ans.reference_area();
  // Translation v of every φ: vᵀMv = ρh·area·|v|²; a uniform director rate w: (ρh³/12)·area·|w|².
  const Vec3 v(0.3, -1.2, 0.5), w(-0.7, 0.2, 0.4);
  VecX vt = VecX::Zero(24), wd = VecX::Zero(24);
  for (int a = 0; a < 4; ++a) {
    vt.segment<3>(6 * a) = v;
    wd.segment<3>(6 * a + 3) = w;
  }
  const double rho_h = m.density * m.thickness;
  EXPECT_NEAR(vt.dot(M * vt), rho_h * area * v.squaredNorm(), 1e-13 * rho_h * area);
  EXPECT_NEAR(wd.dot(M * wd), rho_h * m.thickness * m.thickness / 12.0 * area * w.squaredNorm(),
              1e-13 * rho_h * area);
  EXPECT_EQ(vt.dot(M * wd), 0.0);  // no coupling of φ and d (mid-surface = centroid)
  // Consistent, not lumped: on a flat parallelogram ∫ N_a N_b dA = area/36 · [4 2 1 2; 2 4 2 1; …].
  const Vec3 e1(1.2, 0.3, -0.4), e2(0.5, 0.9, 0.2), N = e1.cross(e2).normalized();
  const std::array<Vec3, 4> x = {Vec3::Zero(), e1, e1 + e2, e2};
  DirectorShellElement flat({0, 1, 2, 3}, stack(x, {N, N, N, N}), m, Vec3::Zero());
  const double A = e1.cross(e2).norm();
  const MatX Mf = flat.mass();
  const double pattern[4] = {4, 2, 1, 2};
  for (int p = 0; p < 4; ++p)
    for (int r = 0; r < 4; ++r) {
      const double nab = A / 36 * pattern[(r - p + 4) % 4];
      EXPECT_NEAR(Mf(6 * p, 6 * r), rho_h * nab, 1e-15) << p << r;
      EXPECT_NEAR(Mf(6 * p + 4, 6 * r + 4), rho_h * m.thickness * m.thickness / 12 * nab, 1e-15);
      EXPECT_EQ(Mf(6 * p, 6 * r + 1), 0.0);  // M = M̄ ⊗ I₃
    }
}

// Area, ∫N_a dA, ∫N_a N dA and gravity against values that are exact for a bilinear surface.
TEST(DirectorShellElement, AreasAndGravity) {
  Fixture f;
  const Vec<24>& q0 = f.q0;
  // ∫ Φ,₁ × Φ,₂ dξ (bilinear in ξ, so 2 × 2 Gauss is exact) is the vector area of the boundary
  // polygon, ½ (X₂ − X₀) × (X₃ − X₁).
  const Vec3 vector_area =
      0.5 * (q0.segment<3>(12) - q0.segment<3>(0)).cross(q0.segment<3>(18) - q0.segment<3>(6));
  EXPECT_LT((f.ans.nodal_normal_areas().rowwise().sum() - vector_area).norm(), 1e-15);
  EXPECT_NEAR(f.ans.nodal_areas().sum(), f.ans.reference_area(), 1e-15);
  EXPECT_GT(f.ans.reference_area(), vector_area.norm());  // curved: more area than its shadow
  // Flat parallelogram: area |a × b|, ∫N_a dA = area/4, ∫N_a N dA = N area/4.
  const Vec3 a(1.2, 0.3, -0.4), b(0.5, 0.9, 0.2), N = a.cross(b).normalized();
  const std::array<Vec3, 4> x = {Vec3(0.3, 0.1, 0.2), Vec3(0.3, 0.1, 0.2) + a,
                                 Vec3(0.3, 0.1, 0.2) + a + b, Vec3(0.3, 0.1, 0.2) + b};
  const Vec<24> qp = stack(x, {N, N, N, N});
  DirectorShellElement flat({0, 1, 2, 3}, qp, test_material(), f.gravity);
  const double area = a.cross(b).norm();
  EXPECT_NEAR(flat.reference_area(), area, 1e-15);
  EXPECT_LT((flat.nodal_areas() - Vec<4>::Constant(area / 4)).norm(), 1e-15);
  EXPECT_LT((flat.nodal_normal_areas() - N * Vec<4>::Constant(area / 4).transpose()).norm(), 1e-15);
  // Gravity: V(q₀) = −ρh·area g·(centroid); the force on the φ blocks adds up to ρh·area g.
  const double mass = test_material().density * test_material().thickness * area;
  const Vec3 centroid = 0.25 * (x[0] + x[1] + x[2] + x[3]);
  EXPECT_NEAR(flat.potential(qp), -mass * f.gravity.dot(centroid), 1e-12);
  const VecX gr = flat.gradient(qp);
  Vec3 total = Vec3::Zero();
  for (int n = 0; n < 4; ++n) total += gr.segment<3>(6 * n);
  EXPECT_LT((total + mass * f.gravity).norm(), 1e-12);
}

// Resultants of exact solutions on a rectangle a × b that is rotated in space: a cylindrical bend
// (nodes on an arc of curvature k, directors normal to it), a transverse shear, and the frame.
TEST(DirectorShellElement, StressResultantsOfKnownDeformations) {
  const ShellMaterial m = test_material();
  const double a = 0.8, b = 0.5, h = m.thickness;
  const double Dm = m.E * h / (1 - m.nu * m.nu), Db = m.E * h * h * h / (12 * (1 - m.nu * m.nu));
  const double Ds = m.shear_correction * m.E / (2 * (1 + m.nu)) * h;
  std::mt19937 g(31);
  const Mat3 R = random_rotation(g);
  const Vec3 c(0.4, -1.0, 2.0);
  const std::array<Vec3, 4> X = {Vec3(0, 0, 0), Vec3(a, 0, 0), Vec3(a, b, 0), Vec3(0, b, 0)};
  const Vec3 ez = Vec3::UnitZ();
  const VecX q0 = rigid_motion(stack(X, {ez, ez, ez, ez}), R, c);
  for (const bool ans : {true, false}) {
    DirectorShellElement e({0, 1, 2, 3}, q0, m, Vec3::Zero(), ans);
    const auto r0 = e.stress_resultants(q0);
    EXPECT_LT((r0.frame - R).norm(), 1e-14);  // e₁ along Φ,₁ (= R e_x), e₃ = R e_z
    {  // Cylindrical bend about the y axis: φ(X) = (sin kX/k, Y, (1 − cos kX)/k), d = (−sin kX, 0,
       // cos kX). Centre: ε_xx = ½(|chord|²/a² − 1), κ_xx = −2(1 − cos ka)/(k a²), γ = 0.
      const double k = 0.9;
      std::array<Vec3, 4> x, d;
      for (int n = 0; n < 4; ++n) {
        const double s = X[n].x();
        x[n] = Vec3(std::sin(k * s) / k, X[n].y(), (1 - std::cos(k * s)) / k);
        d[n] = Vec3(-std::sin(k * s), 0, std::cos(k * s));
      }
      const auto r = e.stress_resultants(rigid_motion(stack(x, d), R, c));
      const double chord2 = 2 * (1 - std::cos(k * a)) / (k * k);
      const double exx = 0.5 * (chord2 / (a * a) - 1),
                   kxx = -2 * (1 - std::cos(k * a)) / (k * a * a);
      EXPECT_NEAR(r.n(0, 0), Dm * exx, 1e-12 * Dm) << ans;
      EXPECT_NEAR(r.n(1, 1), Dm * m.nu * exx, 1e-12 * Dm) << ans;
      EXPECT_NEAR(r.m(0, 0), Db * kxx, 1e-12 * Db) << ans;
      EXPECT_NEAR(r.m(1, 1), Db * m.nu * kxx, 1e-12 * Db) << ans;
      EXPECT_NEAR(r.n(0, 1), 0.0, 1e-12 * Dm) << ans;
      EXPECT_NEAR(r.m(0, 1), 0.0, 1e-12 * Db) << ans;
      EXPECT_LT(r.q.norm(), 1e-12 * Ds) << ans;
    }
    {  // Transverse shear: w = γ y with d fixed gives γ₂ = γ, q₂ = κ_s G h γ; membrane ε_yy = ½γ².
      const double gam = 0.03;
      std::array<Vec3, 4> x;
      for (int n = 0; n < 4; ++n) x[n] = X[n] + gam * X[n].y() * ez;
      const auto r = e.stress_resultants(rigid_motion(stack(x, {ez, ez, ez, ez}), R, c));
      EXPECT_NEAR(r.q(1), Ds * gam, 1e-12 * Ds) << ans;
      EXPECT_NEAR(r.q(0), 0.0, 1e-12 * Ds) << ans;
      EXPECT_NEAR(r.n(1, 1), Dm * 0.5 * gam * gam, 1e-12 * Dm) << ans;
      EXPECT_LT(r.m.norm(), 1e-12 * Db) << ans;
    }
  }
}

// Exact energies of linear director fields on a flat parallelogram (edges a e_x and s e_x + b e_y;
// φ = Φ, D = e_z; nodal directors e_z + d_x e_x + d_y e_y, not normalized: V is defined on all of
// R²⁴) with d_x = θ₀ + θ₁ξ¹ + θ₂ξ², d_y = ψ₀ + ψ₂ξ¹ + ψ₁ξ². Bending: constant κ = sym(∂d/∂X) (in
// plane), W_b = ½ D_b ((1 − ν) κ:κ + ν (tr κ)²). Shear, natural components γ_α = Φ,α·d: plain
// integration keeps all of it, |γ|² = d_x² + d_y²; MITC4 keeps γ₁ on the line ξ¹ = 0 and γ₂ on
// ξ² = 0, so γ^ANS = c₀ + c₁ξ¹ + c₂ξ² with W_s = ½ κ_s G h γᵀA⁻¹γ. The skew makes A^{12} ≠ 0, so
// the test also sees which coordinate each γ_α is interpolated in.
TEST(DirectorShellElement, AssumedShearSamplesTheEdgeMidpoints) {
  const ShellMaterial m = test_material();
  const double a = 0.8, b = 0.5, s = 0.3, h = m.thickness, area = a * b;
  const double Db = m.E * h * h * h / (12 * (1 - m.nu * m.nu));
  const double Ds = m.shear_correction * m.E / (2 * (1 + m.nu)) * h;
  const double th[3] = {0.011, -0.007, 0.004}, ps[3] = {-0.006, 0.009, 0.005};
  const std::array<Vec3, 4> X = {Vec3(0, 0, 0), Vec3(a, 0, 0), Vec3(a + s, b, 0), Vec3(s, b, 0)};
  const double xi[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  const Vec3 ez = Vec3::UnitZ();
  std::array<Vec3, 4> d;
  for (int n = 0; n < 4; ++n)
    d[n] = ez + (th[0] + th[1] * xi[n][0] + th[2] * xi[n][1]) * Vec3::UnitX() +
           (ps[0] + ps[2] * xi[n][0] + ps[1] * xi[n][1]) * Vec3::UnitY();
  const Vec<24> q = stack(X, d);
  // In-plane Jacobian J = [Φ,₁ Φ,₂] and ∂d/∂ξ; ∂d/∂X = (∂d/∂ξ) J⁻¹.
  Eigen::Matrix2d J, dd;
  J << a / 2, s / 2, 0, b / 2;
  dd << th[1], th[2], ps[2], ps[1];
  const Eigen::Matrix2d grad = dd * J.inverse();
  const Eigen::Matrix2d kap = 0.5 * (grad + grad.transpose());
  const double bending =
      0.5 * Db * area * ((1 - m.nu) * kap.squaredNorm() + m.nu * kap.trace() * kap.trace());
  const double shear_plain = 0.5 * Ds * area *
                             (th[0] * th[0] + ps[0] * ps[0] +
                              (th[1] * th[1] + th[2] * th[2] + ps[1] * ps[1] + ps[2] * ps[2]) / 3);
  // γ₁ = (a/2) d_x, γ₂ = (s/2) d_x + (b/2) d_y; ∫(c₀ + c₁ξ¹ + c₂ξ²)ᵀM(…) dA = area (c₀ᵀMc₀ + ⅓ …).
  const Eigen::Matrix2d Ai = (J.transpose() * J).inverse();
  const Eigen::Vector2d c0(a / 2 * th[0], s / 2 * th[0] + b / 2 * ps[0]);
  const Eigen::Vector2d c1(0.0, s / 2 * th[1] + b / 2 * ps[2]);
  const Eigen::Vector2d c2(a / 2 * th[2], 0.0);
  const double shear_ans =
      0.5 * Ds * area * (c0.dot(Ai * c0) + (c1.dot(Ai * c1) + c2.dot(Ai * c2)) / 3);
  const std::array<Vec3, 4> D = {ez, ez, ez, ez};
  DirectorShellElement ans({0, 1, 2, 3}, stack(X, D), m, Vec3::Zero(), true);
  DirectorShellElement plain({0, 1, 2, 3}, stack(X, D), m, Vec3::Zero(), false);
  EXPECT_NEAR(ans.potential(q), bending + shear_ans, 1e-13 * (bending + shear_ans));
  EXPECT_NEAR(plain.potential(q), bending + shear_plain, 1e-13 * (bending + shear_plain));
  EXPECT_GT(std::abs(shear_ans - shear_plain), 0.1 * shear_plain);  // the two differ here
  // At the centre both give the shear force κ_s G h (θ₀, ψ₀) and the moments of κ (frame e_x, e_y).
  const Eigen::Matrix2d m_exact =
      Db * ((1 - m.nu) * kap + m.nu * kap.trace() * Eigen::Matrix2d::Identity());
  for (const auto* e : {&ans, &plain}) {
    const auto r = e->stress_resultants(q);
    EXPECT_LT((r.frame - Mat3::Identity()).norm(), 1e-15);
    EXPECT_LT((r.q - Ds * Eigen::Vector2d(th[0], ps[0])).norm(), 1e-13 * Ds);
    EXPECT_LT((r.m - m_exact).norm(), 1e-13 * Db);
  }
}

// Membrane patch test: a flat 2 × 2 mesh of distorted quadrilaterals under the homogeneous
// deformation φ = Φ + G X (G in-plane) has the constant Green–Lagrange strain E = ½(FᵀF − I) in
// every element, the energy area · ½ n:E, and no out-of-balance force at the interior node.
TEST(DirectorShellElement, MembranePatchTest) {
  const ShellMaterial m = test_material();
  const Vec3 ez = Vec3::UnitZ();
  // 3 × 3 nodes of the unit square, interior and edge mid-nodes moved.
  std::vector<Vec3> X;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) X.emplace_back(0.5 * i, 0.5 * j, 0.0);
  X[4] = Vec3(0.58, 0.41, 0);  // interior
  X[1] = Vec3(0.43, 0, 0);
  X[5] = Vec3(1, 0.6, 0);
  X[7] = Vec3(0.62, 1, 0);
  X[3] = Vec3(0, 0.45, 0);
  Mat3 G = Mat3::Zero();
  G.topLeftCorner<2, 2>() << 0.012, 0.004, -0.003, 0.007;
  const Mat3 F = Mat3::Identity() + G;
  const Eigen::Matrix2d E = 0.5 * (F.transpose() * F - Mat3::Identity()).topLeftCorner<2, 2>();
  const double Dm = m.E * m.thickness / (1 - m.nu * m.nu);
  const Eigen::Matrix2d n_exact =
      Dm * ((1 - m.nu) * E + m.nu * E.trace() * Eigen::Matrix2d::Identity());
  const double W = 0.5 * (n_exact.cwiseProduct(E)).sum();

  VecX interior = VecX::Zero(6);
  double element_force = 0.0;  // largest nodal force of one element: the balance is not trivial
  double energy = 0.0, total_area = 0.0;
  for (int ej = 0; ej < 2; ++ej)
    for (int ei = 0; ei < 2; ++ei) {
      const int n0 = 3 * ej + ei;
      const std::array<int, 4> nodes = {n0, n0 + 1, n0 + 4, n0 + 3};
      std::array<Vec3, 4> x0, x;
      for (int a = 0; a < 4; ++a) {
        x0[a] = X[nodes[a]];
        x[a] = F * X[nodes[a]];
      }
      DirectorShellElement e(nodes, stack(x0, {ez, ez, ez, ez}), m, Vec3::Zero());
      // 2 × 2 Gauss is exact for the area of a flat quadrilateral (shoelace formula).
      const double shoelace = 0.5 * (x0[2] - x0[0]).cross(x0[3] - x0[1]).z();
      EXPECT_NEAR(e.reference_area(), shoelace, 1e-15);
      total_area += e.reference_area();
      const Vec<24> q = stack(x, {ez, ez, ez, ez});
      energy += e.potential(q);
      // The centre resultants, turned from (e₁, e₂) to (x, y), are the exact constant ones.
      const auto r = e.stress_resultants(q);
      const Eigen::Matrix2d R2 = r.frame.topLeftCorner<2, 2>();
      EXPECT_LT((R2 * r.n * R2.transpose() - n_exact).norm(), 1e-12 * n_exact.norm());
      EXPECT_LT(r.m.norm() + r.q.norm(), 1e-12 * n_exact.norm());
      // Assemble the interior node's force (its local index differs from element to element).
      const VecX gr = e.gradient(q);
      for (int a = 0; a < 4; ++a)
        if (nodes[a] == 4) interior += gr.segment<6>(6 * a);
      element_force = std::max(element_force, gr.segment<3>(0).norm());
    }
  EXPECT_NEAR(total_area, 1.0, 1e-15);
  EXPECT_NEAR(energy, W * total_area, 1e-12 * W);
  EXPECT_GT(element_force, 1e-3 * Dm * G.norm());
  EXPECT_LT(interior.norm(), 1e-12 * element_force);
  RecordProperty("interior_over_element_force", sci(interior.norm() / element_force));
}

namespace {

// Linear statics of a clamped strip (length L along x, width b, flat, D = e_z) on n × 1 elements:
// Pᵀ K(q₀) P Δ = Pᵀ f with P = blockdiag(I₃, [e_x e_y]) per free node (the director null space at
// q₀; the clamped nodes at x = 0 are eliminated). Tip loads: a force F_z and a moment M_y, each
// split on the two tip nodes; the moment acts on the directors as f_d = m × d.
struct StripSolution {
  double tip_deflection;  // mean w of the tip nodes
  double tip_rotation;    // mean rotation about y (Δd_x for d = e_z)
  double tip_inplane;     // mean u_y of the tip nodes (in-plane bending)
};

// along_xi2: number the element nodes so that ξ² (not ξ¹) runs along the strip, which puts the
// bending-induced transverse shear into γ₂ instead of γ₁.
// Mz: an in-plane tip moment about z, as the couple of forces ∓Mz/b along x on the tip nodes at
// y = 0 and y = b. assumed_membrane_shear as in the element's constructor.
StripSolution solve_strip(int n, bool assumed_shear, bool along_xi2, double Fz, double My,
                          double Mz = 0.0, bool assumed_membrane_shear = true) {
  const double L = 1.0, b = 0.1;
  ShellMaterial m;
  m.E = 1.0e7;
  m.nu = 0.0;
  m.thickness = 1.0e-3;
  m.density = 1.0;
  const int nodes = 2 * (n + 1);
  const Vec3 ez = Vec3::UnitZ();
  MatX K = MatX::Zero(6 * nodes, 6 * nodes);
  for (int i = 0; i < n; ++i) {
    const std::array<int, 4> en = along_xi2
                                      ? std::array<int, 4>{2 * i + 1, 2 * i, 2 * i + 2, 2 * i + 3}
                                      : std::array<int, 4>{2 * i, 2 * i + 2, 2 * i + 3, 2 * i + 1};
    std::array<Vec3, 4> x;
    for (int a = 0; a < 4; ++a) x[a] = Vec3(L * (en[a] / 2) / n, b * (en[a] % 2), 0.0);
    const Vec<24> q0 = stack(x, {ez, ez, ez, ez});
    const DirectorShellElement e(en, q0, m, Vec3::Zero(), assumed_shear, assumed_membrane_shear);
    const Mat<24, 24> Ke = e.stiffness(q0);
    for (int a = 0; a < 4; ++a)
      for (int c = 0; c < 4; ++c)
        K.block<6, 6>(6 * en[a], 6 * en[c]) += Ke.block<6, 6>(6 * a, 6 * c);
  }
  const int free = nodes - 2;
  MatX P = MatX::Zero(6 * nodes, 5 * free);
  for (int k = 2; k < nodes; ++k) {
    const int c = 5 * (k - 2);
    P.block<3, 3>(6 * k, c).setIdentity();
    P.block<3, 1>(6 * k + 3, c + 3) = Vec3::UnitX();
    P.block<3, 1>(6 * k + 3, c + 4) = Vec3::UnitY();
  }
  VecX f = VecX::Zero(6 * nodes);
  for (const int k : {nodes - 2, nodes - 1}) {
    f(6 * k + 2) = 0.5 * Fz;
    f.segment<3>(6 * k + 3) = (0.5 * My * Vec3::UnitY()).cross(ez);
    f(6 * k) = (k % 2 == 0 ? 1.0 : -1.0) * Mz / b;
  }
  const MatX Kr = P.transpose() * K * P;
  const Eigen::LLT<MatX> llt(Kr);
  EXPECT_EQ(llt.info(), Eigen::Success);
  const VecX dq = P * llt.solve(P.transpose() * f);
  StripSolution s{0.0, 0.0, 0.0};
  for (const int k : {nodes - 2, nodes - 1}) {
    s.tip_deflection += 0.5 * dq(6 * k + 2);
    s.tip_rotation += 0.5 * dq(6 * k + 3);
    s.tip_inplane += 0.5 * dq(6 * k + 1);
  }
  return s;
}

constexpr double kStripEI = 1.0e7 * 0.1 * 1.0e-9 / 12.0;  // E b h³/12, ν = 0

}  // namespace

// Thin strip (L/h = 1000): with ANS the tip deflection under a tip force is within 2 % of the
// Euler–Bernoulli value P L³/(3EI) (shear deformation adds ~10⁻⁶ here); with plain 2 × 2
// integration of the shear the same mesh locks.
TEST(DirectorShellElement, CantileverTipForceNoShearLocking) {
  const double P = 1.0e-6, exact = P / (3.0 * kStripEI);
  for (const bool along_xi2 : {false, true})
    for (const int n : {4, 8}) {
      const double ans = solve_strip(n, true, along_xi2, P, 0.0).tip_deflection / exact;
      const double plain = solve_strip(n, false, along_xi2, P, 0.0).tip_deflection / exact;
      EXPECT_NEAR(ans, 1.0, 0.02) << n << along_xi2;
      EXPECT_LT(plain, 0.2) << n << along_xi2;
      EXPECT_GT(plain, 0.0) << n << along_xi2;
      const std::string tag = std::to_string(n) + (along_xi2 ? "_xi2" : "_xi1");
      RecordProperty("ans_ratio_" + tag, sci(ans));
      RecordProperty("plain_ratio_" + tag, sci(plain));
    }
}

// Pure bending: a tip moment M about y, applied as director forces m × d, turns the tip by M L/EI.
TEST(DirectorShellElement, CantileverTipMomentPureBending) {
  const double M = 1.0e-6, exact = M / kStripEI;
  for (const bool along_xi2 : {false, true})
    for (const int n : {4, 8}) {
      const double ratio = solve_strip(n, true, along_xi2, 0.0, M).tip_rotation / exact;
      EXPECT_NEAR(ratio, 1.0, 0.01) << n << along_xi2;
      RecordProperty("rotation_error_" + std::to_string(n) + (along_xi2 ? "_xi2" : "_xi1"),
                     sci(ratio - 1.0));
    }
}

// In-plane pure bending of the strip (ν = 0): the exact field u_x = −κ x (y − b/2), u_y = κ x²/2
// fits the clamp, and the tip moves by u_y = M L²/(2EI_z), I_z = h b³/12. The bilinear element with
// the in-plane shear at the centre (§3) represents pure bending of rectangles exactly; with Ê₁₂ at
// the Gauss points the parasitic shear of the bilinear u_x = ξ¹ξ² stiffens it
// (docs/theory/shell.md §3).
TEST(DirectorShellElement, InPlaneBendingNoParasiticShear) {
  const double M = 1.0e-6, EIz = 1.0e7 * 1.0e-3 * 1.0e-3 / 12.0, exact = M / (2.0 * EIz);
  for (const bool along_xi2 : {false, true})
    for (const int n : {4, 8}) {
      const double ans = solve_strip(n, true, along_xi2, 0.0, 0.0, M).tip_inplane / exact;
      const double plain = solve_strip(n, true, along_xi2, 0.0, 0.0, M, false).tip_inplane / exact;
      EXPECT_NEAR(ans, 1.0, 1e-9) << n << along_xi2;
      EXPECT_LT(plain, 0.9) << n << along_xi2;
      EXPECT_GT(plain, 0.0) << n << along_xi2;
      const std::string tag = std::to_string(n) + (along_xi2 ? "_xi2" : "_xi1");
      RecordProperty("inplane_ratio_" + tag, sci(ans));
      RecordProperty("inplane_plain_ratio_" + tag, sci(plain));
    }
}

TEST(DirectorShellElement, RejectsBadInput) {
  const Vec<24> q0 = curved_reference();
  const ShellMaterial ok = test_material();
  const Vec3 g0 = Vec3::Zero();
  const std::array<int, 4> nodes = {0, 1, 2, 3};
  EXPECT_NO_THROW(DirectorShellElement(nodes, q0, ok, g0));
  ShellMaterial bad = ok;
  bad.E = std::nan("");
  EXPECT_THROW(DirectorShellElement(nodes, q0, bad, g0), std::invalid_argument);
  bad = ok;
  bad.nu = 0.5;
  EXPECT_THROW(DirectorShellElement(nodes, q0, bad, g0), std::invalid_argument);
  bad = ok;
  bad.thickness = 0.0;
  EXPECT_THROW(DirectorShellElement(nodes, q0, bad, g0), std::invalid_argument);
  bad = ok;
  bad.density = -1.0;
  EXPECT_THROW(DirectorShellElement(nodes, q0, bad, g0), std::invalid_argument);
  bad = ok;
  bad.shear_correction = 0.0;
  EXPECT_THROW(DirectorShellElement(nodes, q0, bad, g0), std::invalid_argument);
  EXPECT_THROW(DirectorShellElement(nodes, q0, ok, Vec3(0, std::nan(""), 0)),
               std::invalid_argument);
  Vec<24> q = q0;
  q.segment<3>(9) *= 1.01;  // director of node 1 not a unit vector
  EXPECT_THROW(DirectorShellElement(nodes, q, ok, g0), std::invalid_argument);
  q = q0;
  q.segment<3>(3) *= -1.0;  // director of node 0 against the normal
  EXPECT_THROW(DirectorShellElement(nodes, q, ok, g0), std::invalid_argument);
  q = q0;
  q.segment<3>(6) = q.segment<3>(0);  // nodes 0 and 1 coincide
  EXPECT_THROW(DirectorShellElement(nodes, q, ok, g0), std::invalid_argument);
  // Clockwise node order (0, 3, 2, 1): every director now points against Φ,₁ × Φ,₂.
  Vec<24> cw;
  for (const int a : {0, 3, 2, 1}) cw.segment<6>(6 * (a == 0 ? 0 : 4 - a)) = q0.segment<6>(6 * a);
  EXPECT_THROW(DirectorShellElement(nodes, cw, ok, g0), std::invalid_argument);
}
