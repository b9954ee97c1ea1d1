// KLShellPatch::viscous_force_into: the Kelvin–Voigt viscous force of IGA-thesis §3.5,
// f_v = ∫ Bᵀ η D B ẋ dA, and its derivatives in x and ẋ (docs/theory/kl-shell.md §11).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "isoflex/elements/kl_shell_patch.hpp"
#include "support/finite_difference.hpp"
#include "support/kl_patches.hpp"

using namespace isoflex;
using namespace isoflex::test;
using elements::KLKinematics;
using elements::KLShellPatch;

namespace {

void report(const char* what, double v) {
  std::printf("  [kl-viscous] %-48s %.3e\n", what, v);
  ::testing::Test::RecordProperty(what, sci(v));
}

elements::KLShellSection damped(double eta = 0.02) {
  elements::KLShellSection s = section();
  s.eta = eta;
  return s;
}

// cx ∂f_v/∂x + cv ∂f_v/∂ẋ, dense.
MatX tangent(const KLShellPatch& patch, const VecX& x, const VecX& v, KLKinematics kin, double cx,
             double cv) {
  elements::SpMat K = patch.pattern();
  patch.viscous_force_into(x, v, kin, cx, cv, K.valuePtr());
  return dense(K);
}

}  // namespace

// Both derivatives against central differences, degrees 2 and 3, large deformations with finite
// rotations, nonlinear and linear kinematics; the x-derivative is not symmetric.
TEST(KLShellViscous, TangentsMatchFiniteDifferences) {
  std::mt19937 g(51);
  double worst_x = 0.0, worst_v = 0.0, asym = 0.0;
  for (int p : {2, 3}) {
    const KLShellPatch patch(curved_patch(g, p), damped());
    const VecX X = patch.reference_positions();
    for (const auto kin : {KLKinematics::nonlinear, KLKinematics::linear}) {
      const VecX x = deformed(g, X), v = random_vector(g, static_cast<int>(X.size()), 2.0);
      auto in_x = [&](const VecX& y) -> VecX {
        return patch.viscous_force_into(y, v, kin, 0, 0, nullptr);
      };
      auto in_v = [&](const VecX& w) -> VecX {
        return patch.viscous_force_into(x, w, kin, 0, 0, nullptr);
      };
      const MatX Kx = tangent(patch, x, v, kin, 1, 0), Kv = tangent(patch, x, v, kin, 0, 1);
      const double ex = rel_diff(Kx, central_jacobian(in_x, x), 1e-12);
      const double ev = rel_diff(Kv, central_jacobian(in_v, v));
      if (kin == KLKinematics::nonlinear) {
        EXPECT_LT(ex, 1e-6) << p;
        worst_x = std::max(worst_x, ex);
        asym = std::max(asym, (Kx - Kx.transpose()).norm() / Kx.norm());
      } else {
        EXPECT_EQ(Kx.norm(), 0.0);  // B(X) does not depend on x
      }
      EXPECT_LT(ev, 1e-6) << p << " " << static_cast<int>(kin);
      worst_v = std::max(worst_v, ev);
      // The damping matrix η ∫ Bᵀ D B is symmetric; the two parts combine linearly.
      EXPECT_LT((Kv - Kv.transpose()).norm(), 1e-13 * Kv.norm());
      EXPECT_LT((tangent(patch, x, v, kin, 0.5, 7.0) - (0.5 * Kx + 7.0 * Kv)).norm(),
                1e-13 * (Kx.norm() + 7.0 * Kv.norm()));
      // f_v is linear in ẋ: f_v = (∂f_v/∂ẋ) ẋ.
      const VecX f = in_v(v);
      EXPECT_LT((Kv * v - f).norm(), 1e-12 * f.norm());
    }
  }
  EXPECT_GT(asym, 1e-3);
  report("df_v/dx vs central FD (rel)", worst_x);
  report("df_v/dxdot vs central FD (rel)", worst_v);
  report("asymmetry |Kx - Kx^T| / |Kx|", asym);
}

// The viscous power ẋ·f_v = η ∫ Ėᵀ D Ė ≥ 0; a rigid velocity ẋ_A = ω × x_A + c has Ė = 0 and no
// viscous force; for any ẋ the force has no resultant and no moment about the origin (the strains
// are invariant), so viscosity conserves momenta.
TEST(KLShellViscous, DissipatesAndSparesRigidVelocitiesAndMomenta) {
  std::mt19937 g(52);
  const KLShellPatch patch(curved_patch(g, 3), damped());
  const VecX X = patch.reference_positions();
  double worst_rigid = 0.0, worst_f = 0.0, worst_m = 0.0, smallest_power = 1.0;
  for (int trial = 0; trial < 5; ++trial) {
    const VecX x = deformed(g, X), v = random_vector(g, static_cast<int>(X.size()), 2.0);
    const VecX f = patch.viscous_force_into(x, v, KLKinematics::nonlinear, 0, 0, nullptr);
    const double power = v.dot(f);
    EXPECT_GT(power, 0.0);
    smallest_power = std::min(smallest_power, power / (v.norm() * f.norm()));
    worst_f = std::max(worst_f, sum(f).norm() / abs_sum(f));
    worst_m = std::max(worst_m, moment(x, f).norm() / abs_moment(x, f));

    const Vec3 omega = random_vector(g, 3, 3.0), c = random_vector(g, 3, 1.0);
    VecX rigid(x.size());
    for (int i = 0; i < x.size() / 3; ++i)
      rigid.segment<3>(3 * i) = omega.cross(Vec3(x.segment<3>(3 * i))) + c;
    const VecX fr = patch.viscous_force_into(x, rigid, KLKinematics::nonlinear, 0, 0, nullptr);
    const VecX fs = patch.viscous_force_into(x, rigid + 1e-3 * v, KLKinematics::nonlinear, 0, 0,
                                             nullptr);  // the scale of a small deformation rate
    worst_rigid = std::max(worst_rigid, fr.norm() / (1e3 * fs.norm()));
  }
  EXPECT_LT(worst_rigid, 1e-12);
  EXPECT_LT(worst_f, 1e-14);
  EXPECT_LT(worst_m, 1e-14);
  report("|f_v(rigid)| / |f_v(deformation)|", worst_rigid);
  report("|sum f_v| / sum |f_v|", worst_f);
  report("|sum x x f_v| / sum |x||f_v|", worst_m);
  report("smallest v.f_v / (|v||f_v|)", smallest_power);
}

// η = 0 (the default) gives no force and no matrix entries; the force is proportional to η.
TEST(KLShellViscous, ProportionalToEta) {
  std::mt19937 g(53);
  const geometry::NurbsSurface s = curved_patch(g, 2);
  const KLShellPatch none(s, section()), a(s, damped(0.01)), b(s, damped(0.03));
  const VecX X = none.reference_positions();
  const VecX x = deformed(g, X), v = random_vector(g, static_cast<int>(X.size()));
  EXPECT_EQ(none.viscous_force_into(x, v, KLKinematics::nonlinear, 0, 0, nullptr).norm(), 0.0);
  EXPECT_EQ(tangent(none, x, v, KLKinematics::nonlinear, 1, 1).norm(), 0.0);
  const VecX fa = a.viscous_force_into(x, v, KLKinematics::nonlinear, 0, 0, nullptr);
  const VecX fb = b.viscous_force_into(x, v, KLKinematics::nonlinear, 0, 0, nullptr);
  EXPECT_LT((fb - 3.0 * fa).norm(), 1e-14 * fb.norm());
}

// Threads change nothing, bit for bit (the coloured element loop).
TEST(KLShellViscous, ThreadsGiveTheSameResultBitForBit) {
  std::mt19937 g(54);
  geometry::NurbsSurface s =
      geometry::k_refine(geometry::cylinder_sector(1.0, 1.5, kPi / 3), 1, 2, 23, 23);
  for (auto& q : s.points) q += random_vector(g, 3, 1e-3);
  KLShellPatch patch(s, damped());
  const VecX X = patch.reference_positions();
  const VecX x = X + random_vector(g, patch.dofs(), 1e-2), v = random_vector(g, patch.dofs());
  elements::SpMat K1 = patch.pattern(), K = patch.pattern();
  const VecX f1 = patch.viscous_force_into(x, v, KLKinematics::nonlinear, 0.5, 3.0, K1.valuePtr());
  for (int threads : {2, 3}) {
    patch.set_threads(threads);
    EXPECT_EQ(patch.threads_used(), threads);
    K = patch.pattern();
    EXPECT_EQ(patch.viscous_force_into(x, v, KLKinematics::nonlinear, 0.5, 3.0, K.valuePtr()), f1);
    EXPECT_TRUE(std::equal(K.valuePtr(), K.valuePtr() + K.nonZeros(), K1.valuePtr())) << threads;
  }
}
