// KLShellPatch::discrete_gradient: the discrete gradient of the KL shell's internal energy for
// energy–momentum schemes (docs/theory/kl-shell.md §10).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "isoflex/elements/kl_shell_patch.hpp"
#include "isoflex/geometry/builders.hpp"
#include "isoflex/geometry/refinement.hpp"
#include "isoflex/math/rotation.hpp"
#include "support/finite_difference.hpp"
#include "support/geometry.hpp"
#include "support/kl_patches.hpp"

using namespace isoflex;
using namespace isoflex::test;
using elements::KLKinematics;
using elements::KLShellPatch;
using elements::KLShellSection;
using geometry::NurbsSurface;

namespace {

void report(const char* what, double v) {
  std::printf("  [kl-dg] %-52s %.3e\n", what, v);
  ::testing::Test::RecordProperty(what, sci(v));
}

}  // namespace

// DV·(x₁ − x₀) = Π(x₁) − Π(x₀) to round-off, for large deformations with finite rotations,
// degrees 2 and 3, nonlinear and linear kinematics.
TEST(KLShellDiscreteGradient, EnergyDifferenceIsExact) {
  std::mt19937 g(31);
  double worst = 0.0, worst_lin = 0.0, largest_dpi = 0.0, smallest_miss = 1e30;
  for (int p : {2, 3}) {
    const KLShellPatch patch(curved_patch(g, p), section());
    const VecX X = patch.reference_positions();
    for (int trial = 0; trial < 4; ++trial) {
      const VecX x0 = deformed(g, X), x1 = deformed(g, X);
      for (const auto kin : {KLKinematics::nonlinear, KLKinematics::linear}) {
        const double P0 = patch.energy(x0, kin), P1 = patch.energy(x1, kin);
        const VecX DV = patch.discrete_gradient(x0, x1, kin, nullptr);
        const double err = std::abs(DV.dot(x1 - x0) - (P1 - P0)) / std::max(P0, P1);
        EXPECT_LT(err, 1e-12) << p << " " << trial << " " << static_cast<int>(kin);
        if (kin == KLKinematics::linear) {
          worst_lin = std::max(worst_lin, err);
          continue;
        }
        worst = std::max(worst, err);
        largest_dpi = std::max(largest_dpi, std::abs(P1 - P0) / std::max(P0, P1));
        // The plain midpoint gradient misses ΔΠ by O(|Δx|³): the test would see a missing or
        // wrong correction.
        const VecX rm = patch.internal_force(0.5 * (x0 + x1), kin, nullptr);
        const double miss = std::abs(rm.dot(x1 - x0) - (P1 - P0)) / std::max(P0, P1);
        EXPECT_GT(miss, 1e-3);
        smallest_miss = std::min(smallest_miss, miss);
      }
    }
  }
  report("|DV.dx - dPi| / max Pi, nonlinear", worst);
  report("|DV.dx - dPi| / max Pi, linear", worst_lin);
  report("largest |dPi| / max Pi of the trials", largest_dpi);
  report("smallest miss of the plain midpoint gradient", smallest_miss);
}

// ‖DV(x − h d, x + h d) − ∇Π(x)‖ = O(h²): ratio ≈ 4 per halving of h, three halvings.
TEST(KLShellDiscreteGradient, SecondOrderConsistency) {
  std::mt19937 g(32);
  for (int p : {2, 3}) {
    const KLShellPatch patch(curved_patch(g, p), section());
    const VecX X = patch.reference_positions();
    const VecX x = deformed(g, X);
    // A deformation increment with a rotation of ~0.3 rad per unit h.
    const VecX d =
        affine(x, rodrigues(random_vector(g, 3, 0.3))) - x + random_vector(g, patch.dofs(), 0.1);
    const VecX r = patch.internal_force(x, KLKinematics::nonlinear, nullptr);
    std::vector<double> err;
    for (double h = 0.2; h > 0.02; h *= 0.5)
      err.push_back(
          (patch.discrete_gradient(x - h * d, x + h * d, KLKinematics::nonlinear, nullptr) - r)
              .norm() /
          r.norm());
    for (std::size_t i = 0; i + 1 < err.size(); ++i) {
      const double ratio = err[i] / err[i + 1];
      EXPECT_GT(ratio, 3.6) << p << " " << i;
      EXPECT_LT(ratio, 4.4) << p << " " << i;
      std::printf("  [kl-dg] p = %d, h = %.4f: |DV - grad Pi|/|grad Pi| = %.3e, ratio %.3f\n", p,
                  0.2 * std::pow(0.5, static_cast<double>(i + 1)), err[i + 1], ratio);
    }
  }
}

// ∂DV/∂x₁ against central differences of DV(x₀, ·), nonlinear (degrees 2 and 3) and linear.
TEST(KLShellDiscreteGradient, TangentMatchesFiniteDifferences) {
  std::mt19937 g(33);
  double worst = 0.0, asym = 0.0;
  for (int p : {2, 3}) {
    const KLShellPatch patch(curved_patch(g, p), section());
    const VecX X = patch.reference_positions();
    for (const auto kin : {KLKinematics::nonlinear, KLKinematics::linear}) {
      const VecX x0 = deformed(g, X), x1 = deformed(g, X);
      elements::SpMat K;
      patch.discrete_gradient(x0, x1, kin, &K);
      auto DV = [&](const VecX& y) -> VecX { return patch.discrete_gradient(x0, y, kin, nullptr); };
      const MatX Kd = dense(K);
      const double e = rel_diff(Kd, central_jacobian(DV, x1));
      EXPECT_LT(e, 1e-6) << p << " " << static_cast<int>(kin);
      worst = std::max(worst, e);
      if (kin == KLKinematics::nonlinear)
        asym = std::max(asym, (Kd - Kd.transpose()).norm() / Kd.norm());
      EXPECT_EQ(K.nonZeros(), patch.pattern().nonZeros());
    }
  }
  EXPECT_GT(asym, 1e-3);  // the tangent of a discrete gradient is not symmetric
  report("dDV/dx1 vs central FD (rel)", worst);
  report("asymmetry |K - K^T| / |K| (nonlinear)", asym);
}

// Σ_A DV_A = 0 and Σ_A x_{n+½,A} × DV_A = 0 for arbitrary states; a rigid increment
// x₁ = Q x₀ + c (finite Q) gives DV·Δx = 0 = ΔΠ, no correction (c_i = 0: DV is the midpoint
// gradient with the averaged stresses, DV − ∇Π(x_{n+½}) = O(θ²), not round-off, since x_{n+½} is
// x₀ contracted by ½(I + Q)), and DV = 0 for a rigidly moved reference.
TEST(KLShellDiscreteGradient, MomentaAndRigidIncrements) {
  std::mt19937 g(34);
  double worst_f = 0.0, worst_m = 0.0, worst_q = 0.0;
  for (int p : {2, 3}) {
    const KLShellPatch patch(curved_patch(g, p), section());
    const VecX X = patch.reference_positions();
    for (int trial = 0; trial < 4; ++trial) {
      const VecX x0 = deformed(g, X), x1 = deformed(g, X);
      const VecX xm = 0.5 * (x0 + x1);
      const VecX DV = patch.discrete_gradient(x0, x1, KLKinematics::nonlinear, nullptr);
      const double ef = sum(DV).norm() / abs_sum(DV),
                   em = moment(xm, DV).norm() / abs_moment(xm, DV);
      EXPECT_LT(ef, 1e-14);
      EXPECT_LT(em, 1e-14);
      worst_f = std::max(worst_f, ef);
      worst_m = std::max(worst_m, em);
    }
    // Rigid increments of a stressed state.
    const VecX x0 = deformed(g, X);
    const Vec3 axis = random_vector(g, 3).normalized(), c = random_vector(g, 3, 0.5);
    const double P0 = patch.energy(x0, KLKinematics::nonlinear);
    std::vector<double> dev;
    for (double theta : {0.4, 0.2, 0.1, 0.05}) {
      const VecX x1 = affine(x0, rodrigues(theta * axis), theta * c);
      const VecX xm = 0.5 * (x0 + x1), dx = x1 - x0;
      const VecX DV = patch.discrete_gradient(x0, x1, KLKinematics::nonlinear, nullptr);
      const double dPi = patch.energy(x1, KLKinematics::nonlinear) - P0;
      EXPECT_LT(std::abs(DV.dot(dx)), 1e-13 * DV.norm() * dx.norm()) << theta;
      EXPECT_LT(std::abs(dPi), 1e-13 * P0) << theta;
      EXPECT_LT(sum(DV).norm(), 1e-14 * abs_sum(DV));
      EXPECT_LT(moment(xm, DV).norm(), 1e-14 * abs_moment(xm, DV));
      const VecX rm = patch.internal_force(xm, KLKinematics::nonlinear, nullptr);
      dev.push_back((DV - rm).norm() / rm.norm());
      // Equivariant to round-off: no correction was built from the round-off of w (which is
      // what the threshold is for; that one would be of size 10⁻⁴ and differ between copies).
      const Mat3 Q = random_rotation(g);
      const Vec3 b = random_vector(g, 3, 2.0);
      const VecX DVQ = patch.discrete_gradient(affine(x0, Q, b), affine(x1, Q, b),
                                               KLKinematics::nonlinear, nullptr);
      EXPECT_LT((DVQ - affine(DV, Q)).norm(), 1e-12 * DV.norm()) << theta;
      worst_q = std::max(worst_q, (DVQ - affine(DV, Q)).norm() / DV.norm());
    }
    for (std::size_t i = 0; i + 1 < dev.size(); ++i) {
      EXPECT_GT(dev[i] / dev[i + 1], 3.6) << p << " " << i;
      EXPECT_LT(dev[i] / dev[i + 1], 4.4) << p << " " << i;
    }
    std::printf(
        "  [kl-dg] p = %d rigid increment: |DV - grad Pi(x_mid)|/|grad Pi| = %.2e … %.2e "
        "(theta 0.4 … 0.05)\n",
        p, dev.front(), dev.back());
    // The reference moved rigidly, then a finite rigid increment: no stress, DV = 0, although
    // the contracted midpoint is stressed.
    const VecX y0 = affine(X, random_rotation(g), random_vector(g, 3, 0.5));
    const VecX y1 = affine(y0, random_rotation(g), random_vector(g, 3, 0.5));
    const VecX DV0 = patch.discrete_gradient(y0, y1, KLKinematics::nonlinear, nullptr);
    const double rmid =
        patch.internal_force(0.5 * (y0 + y1), KLKinematics::nonlinear, nullptr).norm();
    EXPECT_LT(DV0.norm(), 1e-12 * rmid);
    report(p == 2 ? "rigid reference p=2: |DV| / |grad Pi(x_mid)|"
                  : "rigid reference p=3: |DV| / |grad Pi(x_mid)|",
           DV0.norm() / rmid);
  }
  report("|sum DV| / sum |DV_A|", worst_f);
  report("|sum x_mid x DV| / sum |x_mid||DV_A|", worst_m);
  report("rigid increment: |DV(Qx+b) - Q DV(x)| / |DV|", worst_q);
}

// DV(Q x₀ + c, Q x₁ + c) = Q DV(x₀, x₁) blockwise, and ∂DV/∂x₁ likewise (Q K Qᵀ per block);
// DV(x₀, x₁) = DV(x₁, x₀) (the formula is symmetric in the two states).
TEST(KLShellDiscreteGradient, RigidMotionInvarianceAndSymmetry) {
  std::mt19937 g(35);
  const KLShellPatch patch(curved_patch(g, 3), section());
  const VecX X = patch.reference_positions();
  const int n = patch.control_points();
  double worst = 0.0, worst_k = 0.0, worst_s = 0.0;
  for (int trial = 0; trial < 3; ++trial) {
    const VecX x0 = deformed(g, X), x1 = deformed(g, X);
    const Mat3 Q = random_rotation(g);
    const Vec3 c = random_vector(g, 3, 2.0);
    elements::SpMat K, KQ;
    const VecX DV = patch.discrete_gradient(x0, x1, KLKinematics::nonlinear, &K);
    const VecX DVQ =
        patch.discrete_gradient(affine(x0, Q, c), affine(x1, Q, c), KLKinematics::nonlinear, &KQ);
    const double e = (DVQ - affine(DV, Q)).norm() / DV.norm();
    MatX Qb = MatX::Zero(3 * n, 3 * n);
    for (int i = 0; i < n; ++i) Qb.block<3, 3>(3 * i, 3 * i) = Q;
    const MatX Kd = dense(K);
    const double ek = (dense(KQ) - Qb * Kd * Qb.transpose()).norm() / Kd.norm();
    const double es =
        (patch.discrete_gradient(x1, x0, KLKinematics::nonlinear, nullptr) - DV).norm() / DV.norm();
    EXPECT_LT(e, 1e-12);
    EXPECT_LT(ek, 1e-12);
    EXPECT_LT(es, 1e-12);
    worst = std::max(worst, e);
    worst_k = std::max(worst_k, ek);
    worst_s = std::max(worst_s, es);
  }
  report("|DV(Qx+c) - Q DV(x)| / |DV|", worst);
  report("|K(Qx+c) - Q K Q^T| / |K|", worst_k);
  report("|DV(x1, x0) - DV(x0, x1)| / |DV|", worst_s);
}

// r and K bit for bit equal on 1, 2, 3 threads: 24 × 24 bicubic elements (9 216 points).
TEST(KLShellDiscreteGradient, ThreadsGiveTheSameResultBitForBit) {
  std::mt19937 g(36);
  NurbsSurface s = geometry::k_refine(geometry::cylinder_sector(1.0, 1.5, kPi / 3), 1, 2, 23, 23);
  for (auto& q : s.points) q += random_vector(g, 3, 1e-3);
  KLShellPatch patch(s, section(0.05));
  const VecX X = patch.reference_positions();
  const VecX x0 = X + random_vector(g, patch.dofs(), 1e-2);
  const VecX x1 =
      affine(X, rodrigues(random_vector(g, 3, 0.5))) + random_vector(g, patch.dofs(), 1e-2);
  patch.set_threads(1);
  elements::SpMat K1, K;
  const VecX r1 = patch.discrete_gradient(x0, x1, KLKinematics::nonlinear, &K1);
  for (int threads : {2, 3}) {
    patch.set_threads(threads);
    EXPECT_EQ(patch.threads_used(), threads);
    const VecX r = patch.discrete_gradient(x0, x1, KLKinematics::nonlinear, &K);
    EXPECT_EQ(r, r1) << threads;
    ASSERT_EQ(K.nonZeros(), K1.nonZeros());
    EXPECT_TRUE(std::equal(K.valuePtr(), K.valuePtr() + K.nonZeros(), K1.valuePtr())) << threads;
    EXPECT_EQ(patch.discrete_gradient(x0, x1, KLKinematics::nonlinear, nullptr), r1) << threads;
  }
}

// x₀ = x₁: DV = ∇Π(x₀) = internal_force and ∂DV/∂x₁ = ½ K(x₀); wrong sizes throw.
TEST(KLShellDiscreteGradient, EqualStatesGiveTheInternalForce) {
  std::mt19937 g(37);
  const KLShellPatch patch(curved_patch(g, 3), section());
  const VecX X = patch.reference_positions();
  double worst = 0.0, worst_k = 0.0;
  for (const auto kin : {KLKinematics::nonlinear, KLKinematics::linear}) {
    const VecX x = deformed(g, X);
    elements::SpMat K, Kr;
    const VecX DV = patch.discrete_gradient(x, x, kin, &K);
    const VecX r = patch.internal_force(x, kin, &Kr);
    const double e = (DV - r).norm() / r.norm();
    const double ek = (dense(K) - 0.5 * dense(Kr)).norm() / dense(Kr).norm();
    EXPECT_LT(e, 1e-13) << static_cast<int>(kin);
    EXPECT_LT(ek, 1e-13) << static_cast<int>(kin);
    worst = std::max(worst, e);
    worst_k = std::max(worst_k, ek);
  }
  report("x0 = x1: |DV - r| / |r|", worst);
  report("x0 = x1: |K - K_int/2| / |K_int|", worst_k);
  EXPECT_THROW(patch.discrete_gradient(X, VecX::Zero(5), KLKinematics::nonlinear, nullptr),
               std::invalid_argument);
  VecX bad = X;
  bad(0) = std::nan("");
  EXPECT_THROW(patch.discrete_gradient(bad, X, KLKinematics::nonlinear, nullptr),
               std::invalid_argument);
}
