// KLShellPatch: the isogeometric Kirchhoff–Love shell (docs/theory/kl-shell.md §9).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <string>

#include "isoflex/elements/kl_shell_patch.hpp"
#include "isoflex/geometry/builders.hpp"
#include "isoflex/geometry/quadrature.hpp"
#include "isoflex/geometry/refinement.hpp"
#include "isoflex/math/skew.hpp"
#include "support/finite_difference.hpp"
#include "support/geometry.hpp"

using namespace isoflex;
using namespace isoflex::test;
using elements::KLKinematics;
using elements::KLShellPatch;
using elements::KLShellSection;
using geometry::NurbsSurface;

namespace {

// Prints a measured number and records it for the XML report.
void report(const char* what, double v) {
  std::printf("  [kl-shell] %-44s %.3e\n", what, v);
  ::testing::Test::RecordProperty(what, sci(v));
}

KLShellSection section(double E = 1.0e3, double nu = 0.3, double t = 0.3, double rho = 7.0) {
  KLShellSection s;
  s.young = E;
  s.poisson = nu;
  s.thickness = t;
  s.density = rho;
  return s;
}

// Rational cylinder sector (80°, weights ≠ 1), elevated to bicubic and refined, with every control
// point moved randomly by up to `jitter`.
NurbsSurface curved_patch(std::mt19937& g, double jitter) {
  NurbsSurface s = geometry::cylinder_sector(1.0, 1.2, 80.0 * kPi / 180.0);
  s = geometry::k_refine(s, 1, 2, 2, 1);
  for (auto& p : s.points) p += random_vector(g, 3, jitter);
  return s;
}

// [0, lx] × [0, ly] at degree (p, q), n_u × n_v elements, interior control points moved in the
// plane by up to `jitter` (the boundary and the polynomial parametrization are kept).
NurbsSurface flat_plate(std::mt19937& g, double lx, double ly, int p, int q, int n_u, int n_v,
                        double jitter) {
  NurbsSurface s = geometry::planar_rectangle(lx, ly);
  s = geometry::k_refine(s, p - 1, q - 1, n_u - 1, n_v - 1);
  for (int j = 1; j + 1 < s.n_v(); ++j)
    for (int i = 1; i + 1 < s.n_u(); ++i) {
      const Vec3 d = random_vector(g, 3, jitter);
      s.points[s.index(i, j)] += Vec3(d.x(), d.y(), 0.0);
    }
  return s;
}

VecX positions(const NurbsSurface& s) {
  VecX x(3 * s.points.size());
  for (std::size_t i = 0; i < s.points.size(); ++i) x.segment<3>(3 * i) = s.points[i];
  return x;
}

// x_A = F X_A + c for every control point (affine maps are exact on NURBS).
VecX affine(const VecX& X, const Mat3& F, const Vec3& c = Vec3::Zero()) {
  VecX x(X.size());
  for (int i = 0; i < X.size() / 3; ++i) x.segment<3>(3 * i) = F * X.segment<3>(3 * i) + c;
  return x;
}

MatX dense(const elements::SpMat& K) {
  return MatX(K);
}

// Plane-stress matrix in Cartesian Voigt components (ε₁₁, ε₂₂, 2ε₁₂) (IGA-thesis (3.18)).
Mat3 plane_stress(double E, double nu) {
  Mat3 D;
  D << 1.0, nu, 0.0, nu, 1.0, 0.0, 0.0, 0.0, 0.5 * (1.0 - nu);
  return E / (1.0 - nu * nu) * D;
}

}  // namespace

TEST(KLShellPatch, Basics) {
  std::mt19937 g(11);
  const NurbsSurface s = curved_patch(g, 0.0);
  const KLShellPatch patch(s, section());
  EXPECT_EQ(patch.control_points(), s.n_u() * s.n_v());
  EXPECT_EQ(patch.dofs(), 3 * patch.control_points());
  EXPECT_EQ(patch.elements(), 3 * 2);
  EXPECT_EQ(patch.quadrature_points(), 6 * 16);
  EXPECT_EQ(patch.reference_positions(), positions(s));
  EXPECT_EQ(patch.pattern().rows(), patch.dofs());
  EXPECT_TRUE(patch.pattern().isCompressed());
  EXPECT_GT(patch.reference_bytes_per_point(), 0u);
  report("reference bytes per quadrature point",
         static_cast<double>(patch.reference_bytes_per_point()));
  // The reference is stress free.
  const VecX X = patch.reference_positions();
  for (const auto kin : {KLKinematics::nonlinear, KLKinematics::linear}) {
    EXPECT_EQ(patch.energy(X, kin), 0.0);
    EXPECT_LT(patch.internal_force(X, kin, nullptr).norm(), 1e-12);
  }
  // The pattern holds exactly the pairs of control points sharing an element; a different K is
  // replaced by the pattern, values overwritten.
  elements::SpMat K(3, 3);
  patch.internal_force(X, KLKinematics::nonlinear, &K);
  EXPECT_EQ(K.nonZeros(), patch.pattern().nonZeros());
  EXPECT_EQ(patch.mass().nonZeros(), patch.pattern().nonZeros());
  const double before = K.norm();
  patch.internal_force(X, KLKinematics::nonlinear, &K);
  EXPECT_DOUBLE_EQ(K.norm(), before);
}

TEST(KLShellPatch, ThrowsOnBadInput) {
  std::mt19937 g(12);
  const NurbsSurface plate1 = geometry::planar_rectangle(2.0, 1.0);  // degree 1
  EXPECT_NE(message_of([&] { KLShellPatch(plate1, section()); }).find("degree"), std::string::npos);
  const NurbsSurface mixed = geometry::elevate_degree(plate1, geometry::Direction::u, 2);
  EXPECT_THROW(KLShellPatch(mixed, section()), std::invalid_argument);  // (3, 1)
  const NurbsSurface plate = flat_plate(g, 2.0, 1.0, 2, 2, 2, 2, 0.0);
  EXPECT_NO_THROW(KLShellPatch(plate, section()));
  EXPECT_THROW(KLShellPatch(geometry::k_refine(plate, 4, 4, 0, 0), section()),
               std::invalid_argument);  // 49 functions per element
  EXPECT_THROW(KLShellPatch(plate, section(0.0)), std::invalid_argument);
  EXPECT_THROW(KLShellPatch(plate, section(std::nan(""))), std::invalid_argument);
  EXPECT_THROW(KLShellPatch(plate, section(1.0, 0.5)), std::invalid_argument);
  EXPECT_THROW(KLShellPatch(plate, section(1.0, -1.0)), std::invalid_argument);
  EXPECT_THROW(KLShellPatch(plate, section(1.0, 0.3, 0.0)), std::invalid_argument);
  EXPECT_THROW(KLShellPatch(plate, section(1.0, 0.3, 0.1, -1.0)), std::invalid_argument);
  EXPECT_NO_THROW(KLShellPatch(plate, section(1.0, 0.3, 0.1, 0.0)));
  EXPECT_THROW(KLShellPatch(plate, section(), -1, 0), std::invalid_argument);
  // Degenerate reference: the plate collapsed onto a line.
  NurbsSurface line = plate;
  for (auto& p : line.points) p.y() = 0.0;
  EXPECT_NE(message_of([&] { KLShellPatch(line, section()); }).find("degenerate"),
            std::string::npos);
  const KLShellPatch patch(plate, section());
  EXPECT_THROW(patch.energy(VecX::Zero(5), KLKinematics::linear), std::invalid_argument);
  EXPECT_THROW(patch.internal_force(VecX::Zero(patch.dofs() + 3), KLKinematics::nonlinear, nullptr),
               std::invalid_argument);
  const VecX X = patch.reference_positions();
  EXPECT_THROW(patch.stress(X, 1.5, 0.5, KLKinematics::linear), std::invalid_argument);
  EXPECT_THROW(patch.stress(X, 0.5, std::nan(""), KLKinematics::linear), std::invalid_argument);
}

// Energy gradient vs central differences of the energy and tangent vs central differences of the
// residual, on a perturbed rational cylinder sector at randomly perturbed states.
TEST(KLShellPatch, ResidualAndTangentMatchFiniteDifferences) {
  std::mt19937 g(2024);
  const KLShellPatch patch(curved_patch(g, 0.05), section());
  const VecX X = patch.reference_positions();
  double worst_g = 0.0, worst_k = 0.0, worst_sym = 0.0;
  for (const auto kin : {KLKinematics::nonlinear, KLKinematics::linear}) {
    for (int trial = 0; trial < 2; ++trial) {
      const VecX x = X + random_vector(g, patch.dofs(), 0.08);
      auto U = [&](const VecX& y) -> VecX { return VecX::Constant(1, patch.energy(y, kin)); };
      auto r = [&](const VecX& y) -> VecX { return patch.internal_force(y, kin, nullptr); };
      elements::SpMat K;
      const VecX f = patch.internal_force(x, kin, &K);
      const MatX Kd = dense(K);
      const double eg = rel_diff(f.transpose(), central_jacobian(U, x));
      const double ek = rel_diff(Kd, central_jacobian(r, x));
      const double es = (Kd - Kd.transpose()).norm() / Kd.norm();
      EXPECT_LT(eg, 1e-7) << static_cast<int>(kin) << " " << trial;
      EXPECT_LT(ek, 1e-7) << static_cast<int>(kin) << " " << trial;
      EXPECT_LT(es, 1e-14);
      worst_g = std::max(worst_g, eg);
      worst_k = std::max(worst_k, ek);
      worst_sym = std::max(worst_sym, es);
    }
  }
  report("gradient vs FD of energy (rel)", worst_g);
  report("tangent vs FD of residual (rel)", worst_k);
  report("tangent asymmetry |K-K^T|/|K|", worst_sym);
}

// Linear kinematics: r = K_lin (x − X), U = ½ (x − X)ᵀ K_lin (x − X), and the nonlinear tangent at
// the reference is K_lin.
TEST(KLShellPatch, LinearIsTheLinearizationAtTheReference) {
  std::mt19937 g(7);
  const KLShellPatch patch(curved_patch(g, 0.05), section());
  const VecX X = patch.reference_positions();
  elements::SpMat Klin, K0;
  patch.internal_force(X, KLKinematics::linear, &Klin);
  patch.internal_force(X, KLKinematics::nonlinear, &K0);
  const double e0 = dense(K0 - Klin).norm() / dense(Klin).norm();
  EXPECT_LT(e0, 1e-14);
  const VecX u = random_vector(g, patch.dofs(), 0.1);
  const VecX r = patch.internal_force(X + u, KLKinematics::linear, nullptr);
  const double er = (r - Klin * u).norm() / (Klin * u).norm();
  const double uKu = u.dot(Klin * u);
  const double eu = std::abs(patch.energy(X + u, KLKinematics::linear) - 0.5 * uKu) / uKu;
  EXPECT_LT(er, 1e-13);
  EXPECT_LT(eu, 1e-13);
  // The linear tangent does not depend on x.
  elements::SpMat K1;
  patch.internal_force(X + u, KLKinematics::linear, &K1);
  EXPECT_EQ(dense(K1), dense(Klin));
  // Small displacements: nonlinear ≈ linear to O(|u|²).
  const VecX du = 1e-6 * u;
  const double esmall =
      (patch.internal_force(X + du, KLKinematics::nonlinear, nullptr) - Klin * du).norm() /
      (Klin * du).norm();
  EXPECT_LT(esmall, 1e-4);
  report("nonlinear K(X) vs linear K (rel)", e0);
  report("linear r vs K_lin u (rel)", er);
  report("linear U vs 1/2 u K_lin u (rel)", eu);
  report("nonlinear vs linear r at |u|~1e-7 (rel)", esmall);
}

// Rigid translation and finite rotation: zero energy and zero force (nonlinear); translation and
// infinitesimal rotation for the linear kinematics.
TEST(KLShellPatch, RigidMotionIsStressFree) {
  std::mt19937 g(99);
  const KLShellPatch patch(curved_patch(g, 0.05), section());
  const VecX X = patch.reference_positions();
  elements::SpMat Klin;
  patch.internal_force(X, KLKinematics::linear, &Klin);
  // Scales: the force and energy of a comparable deformation δ (|δ| ~ |rigid displacement|).
  const VecX delta = random_vector(g, patch.dofs(), 1.0);
  const double f_scale = (Klin * delta).norm(), U_scale = 0.5 * delta.dot(Klin * delta);
  double worst_f = 0.0, worst_U = 0.0;
  for (int trial = 0; trial < 3; ++trial) {
    const Mat3 Q = random_rotation(g);
    const Vec3 c = random_vector(g, 3, 2.0);
    const VecX x = affine(X, Q, c);
    const double ef = patch.internal_force(x, KLKinematics::nonlinear, nullptr).norm() / f_scale;
    const double eU = std::abs(patch.energy(x, KLKinematics::nonlinear)) / U_scale;
    EXPECT_LT(ef, 1e-13);
    EXPECT_LT(eU, 1e-13);
    worst_f = std::max(worst_f, ef);
    worst_U = std::max(worst_U, eU);
    // Linear: translation plus infinitesimal rotation u = c + ω × X.
    const Vec3 w = random_vector(g, 3, 1.0);
    const VecX xl = affine(X, Mat3::Identity() + skew(w), c);
    const double el = patch.internal_force(xl, KLKinematics::linear, nullptr).norm() / f_scale;
    EXPECT_LT(el, 1e-13);
    worst_f = std::max(worst_f, el);
  }
  report("rigid motion |r| / |K delta|", worst_f);
  report("rigid motion |U| / (1/2 delta K delta)", worst_U);
}

// Membrane patch test: x = (I + G) X with an in-plane G on a flat plate (polynomial, interior
// control points moved) gives a constant strain and the exact energy ½ t A εᵀ D ε — the linear
// strain sym(G) for the linear, the Green–Lagrange strain ½(FᵀF − I) for the nonlinear kinematics.
TEST(KLShellPatch, MembranePatchTest) {
  std::mt19937 g(5);
  const double lx = 2.0, ly = 1.5, E = 1.0e3, nu = 0.3, t = 0.05;
  const Mat3 D = plane_stress(E, nu);
  double worst = 0.0, worst_interior = 0.0;
  for (const double jitter : {0.0, 0.08}) {
    const KLShellPatch patch(flat_plate(g, lx, ly, 3, 2, 4, 3, jitter), section(E, nu, t));
    const VecX X = patch.reference_positions();
    for (const auto kin : {KLKinematics::linear, KLKinematics::nonlinear}) {
      Mat3 G = Mat3::Zero();
      G.topLeftCorner<2, 2>() =
          (kin == KLKinematics::linear ? 1e-3 : 0.3) * Eigen::Matrix2d::Random();
      const VecX x = affine(X, Mat3::Identity() + G);
      Eigen::Matrix2d e;
      if (kin == KLKinematics::linear) {
        e = 0.5 * (G + G.transpose()).topLeftCorner<2, 2>();
      } else {
        const Mat3 F = Mat3::Identity() + G;
        e = 0.5 * (F.transpose() * F - Mat3::Identity()).topLeftCorner<2, 2>();
      }
      const Vec3 ev(e(0, 0), e(1, 1), 2.0 * e(0, 1));
      const double exact = 0.5 * t * lx * ly * ev.dot(D * ev);
      const double err = std::abs(patch.energy(x, kin) - exact) / exact;
      EXPECT_LT(err, 1e-12) << jitter << " " << static_cast<int>(kin);
      worst = std::max(worst, err);
      if (jitter == 0.0) {
        // Constant stress is in equilibrium inside: the interior control points carry no force
        // (affine parametrization: the quadrature is exact).
        const auto& s = patch.reference();
        const VecX r = patch.internal_force(x, kin, nullptr);
        double interior = 0.0;
        for (int j = 1; j + 1 < s.n_v(); ++j)
          for (int i = 1; i + 1 < s.n_u(); ++i)
            interior = std::max(interior, r.segment<3>(3 * s.index(i, j)).norm());
        const double rel = interior / r.norm();
        EXPECT_LT(rel, 1e-12);
        worst_interior = std::max(worst_interior, rel);
      }
    }
  }
  // A rational parametrization of the plate (random weights, the plate stays flat): the energy
  // is the constant density times the quadrature's area, which the mass matrix also sees.
  NurbsSurface s = flat_plate(g, lx, ly, 2, 3, 3, 3, 0.05);
  std::uniform_real_distribution<double> W(0.6, 1.5);
  for (auto& w : s.weights) w = W(g);
  const double rho = 3.0;
  const KLShellPatch patch(s, section(E, nu, t, rho));
  Mat3 G = Mat3::Zero();
  G.topLeftCorner<2, 2>() = 1e-3 * Eigen::Matrix2d::Random();
  const VecX x = affine(patch.reference_positions(), Mat3::Identity() + G);
  const Eigen::Matrix2d e = 0.5 * (G + G.transpose()).topLeftCorner<2, 2>();
  const Vec3 ev(e(0, 0), e(1, 1), 2.0 * e(0, 1));
  const double area_q = patch.mass().sum() / (3.0 * rho * t);
  const double err =
      std::abs(patch.energy(x, KLKinematics::linear) - 0.5 * t * area_q * ev.dot(D * ev)) /
      patch.energy(x, KLKinematics::linear);
  EXPECT_LT(err, 1e-12);
  report("membrane patch test energy (rel)", std::max(worst, err));
  report("membrane patch test interior force (rel)", worst_interior);
  report("rational plate: quadrature area - exact (rel)", std::abs(area_q - lx * ly) / (lx * ly));
}

// Pure bending, linear: w = X²/(2R) on a flat plate (exact in the spline space) is pure
// cylindrical bending, κ₁₁ = 1/R, no membrane strain: U = ½ D κ² A, D = E t³/(12(1 − ν²)).
TEST(KLShellPatch, PureBendingLinear) {
  const double L = 2.0, Wd = 1.0, R = 3.0, E = 1.0e3, t = 0.05;
  double worst = 0.0;
  for (const double nu : {0.0, 0.3}) {
    // Degree 2 × 2 on one element: control points at 0, L/2, L; the Bézier coefficients of
    // X²/(2R) are (0, 0, L²/(2R)). Refining reference and deformed nets alike keeps it exact.
    NurbsSurface ref = geometry::elevate_degree(
        geometry::elevate_degree(geometry::planar_rectangle(L, Wd), geometry::Direction::u, 1),
        geometry::Direction::v, 1);
    NurbsSurface def = ref;
    for (int j = 0; j < 3; ++j) def.points[def.index(2, j)].z() = L * L / (2.0 * R);
    ref = geometry::k_refine(ref, 1, 1, 3, 2);
    def = geometry::k_refine(def, 1, 1, 3, 2);
    const KLShellPatch patch(ref, section(E, nu, t));
    const double D = E * t * t * t / (12.0 * (1.0 - nu * nu));
    const double exact = 0.5 * D / (R * R) * L * Wd;
    const double err = std::abs(patch.energy(positions(def), KLKinematics::linear) - exact) / exact;
    EXPECT_LT(err, 1e-12) << nu;
    worst = std::max(worst, err);
  }
  report("linear pure bending energy vs D/(2R^2) A (rel)", worst);
}

// Pure bending, nonlinear: a flat plate rolled into an exact circular cylinder of radius R (a
// rational quadratic arc, the reference plate with the same weights). The bending part of the
// energy is separated from the membrane part by two thicknesses, U(t) = a t + b t³. No NURBS with
// the arc's weights maps the plate isometrically onto the arc (the arc length of a rational
// quadratic is an arctan), so the cylinder carries a small membrane strain a₁₁/A₁₁ − 1 = O(φ²);
// the bending energy ∫ t³/24 E (a₁₁/(R A₁₁))² dA (ν = 0) is checked to round-off and against the
// closed form ½ D A / R² to the size of that strain.
TEST(KLShellPatch, PureBendingNonlinearCylinder) {
  const double R = 2.0, phi = 0.15, Wd = 0.7, E = 1.0e3;
  const double w = std::cos(phi), a = R * phi;  // arc length 2Rφ = plate length 2a
  NurbsSurface ref, def;
  ref.u = def.u = geometry::KnotVector(2, {0, 0, 0, 1, 1, 1});
  ref.v = def.v = geometry::KnotVector(2, {0, 0, 0, 1, 1, 1});
  const Vec3 arc[3] = {{-R * std::sin(phi), 0.0, R * (1.0 - std::cos(phi))},
                       {0.0, 0.0, R * (1.0 - 1.0 / std::cos(phi))},
                       {R * std::sin(phi), 0.0, R * (1.0 - std::cos(phi))}};
  const double X[3] = {-a, 0.0, a}, wts[3] = {1.0, w, 1.0};
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) {
      const double y = 0.5 * Wd * j;
      ref.points.push_back(Vec3(X[i], y, 0.0));
      def.points.push_back(arc[i] + Vec3(0.0, y, 0.0));
      ref.weights.push_back(wts[i]);
      def.weights.push_back(wts[i]);
    }
  ref = geometry::k_refine(ref, 1, 0, 3, 1);
  def = geometry::k_refine(def, 1, 0, 3, 1);
  const VecX x = positions(def);
  const double t1 = 0.01, t2 = 0.02;
  const KLShellPatch p1(ref, section(E, 0.0, t1)), p2(ref, section(E, 0.0, t2));
  const double U1 = p1.energy(x, KLKinematics::nonlinear),
               U2 = p2.energy(x, KLKinematics::nonlinear);
  const double b = (U2 / t2 - U1 / t1) / (t2 * t2 - t1 * t1);  // U = a t + b t³
  // Independent quadrature of ∫ E/24 (a₁₁/(R A₁₁))² J₀ dξ dη with the patch's Gauss points.
  const auto rule = geometry::gauss_legendre(4);
  double expected = 0.0, area = 0.0, max_stretch = 0.0;
  for (const auto& el : geometry::surface_elements(ref))
    for (const auto& qp : geometry::element_quadrature(el, rule, rule)) {
      const auto P0 = geometry::evaluate(ref, qp.xi, qp.eta);
      const auto P = geometry::evaluate(def, qp.xi, qp.eta);
      const double A11 = P0.xu.squaredNorm(), a11 = P.xu.squaredNorm();
      const double J0 = P0.xu.cross(P0.xv).norm();
      expected += E / 24.0 * std::pow(a11 / (R * A11), 2) * J0 * qp.weight;
      area += J0 * qp.weight;
      max_stretch = std::max(max_stretch, std::abs(a11 / A11 - 1.0));
    }
  const double err = std::abs(b - expected) / expected;
  const double closed = E / 24.0 / (R * R) * 2.0 * a * Wd;  // ½ D κ² A / t³
  const double err_closed = std::abs(b - closed) / closed;
  EXPECT_LT(err, 1e-6);  // the two-thickness split cancels U ≈ 10⁴ × the bending part
  EXPECT_LT(err_closed, 4.0 * max_stretch);
  EXPECT_LT(std::abs(area - 2.0 * a * Wd) / (2.0 * a * Wd), 1e-12);
  report("nonlinear cylinder bending vs quadrature (rel)", err);
  report("nonlinear cylinder bending vs D/(2R^2) A (rel)", err_closed);
  report("  its membrane stretch max|a11/A11 - 1|", max_stretch);
}

// Total mass ρ t A on curved surfaces with exact areas: cylinder sector A = R θ L, sphere zone
// A = R² Δλ (sin β₁ − sin β₀) (the sum of all entries of M ⊗ I₃ is 3 ρ t A).
TEST(KLShellPatch, MassMatrixTotalMass) {
  const double rho = 7.8, t = 0.02;
  double worst = 0.0, worst_sym = 0.0;
  struct Case {
    NurbsSurface s;
    double area;
    int rule;
  };
  const double R = 1.3;
  std::vector<Case> cases;
  for (const int rule : {0, 8}) {
    cases.push_back({geometry::k_refine(geometry::cylinder_sector(R, 2.0, kPi / 2), 1, 1, 3, 2),
                     R * kPi / 2 * 2.0, rule});
    cases.push_back({geometry::k_refine(geometry::sphere_sector(R, kPi / 2, -0.3, 0.9), 0, 0, 3, 3),
                     R * R * kPi / 2 * (std::sin(0.9) - std::sin(-0.3)), rule});
  }
  double err_default = 0.0;
  for (const auto& c : cases) {
    const KLShellPatch patch(c.s, section(1.0, 0.3, t, rho), c.rule, c.rule);
    const elements::SpMat& M = patch.mass();
    const double err = std::abs(M.sum() / 3.0 - rho * t * c.area) / (rho * t * c.area);
    const MatX Md = dense(M);
    worst_sym = std::max(worst_sym, (Md - Md.transpose()).norm() / Md.norm());
    if (c.rule == 0) {
      EXPECT_LT(err, 1e-5);
      err_default = std::max(err_default, err);
    } else {
      EXPECT_LT(err, 1e-12);
      worst = std::max(worst, err);
    }
    // M ⊗ I₃: every 3 × 3 block is a multiple of I₃.
    double off = 0.0;
    for (int A = 0; A < patch.control_points(); ++A)
      for (int B = 0; B < patch.control_points(); ++B) {
        const Mat3 blk = Md.block<3, 3>(3 * A, 3 * B);
        off = std::max(off, (blk - blk(0, 0) * Mat3::Identity()).cwiseAbs().maxCoeff());
      }
    EXPECT_EQ(off, 0.0);
    EXPECT_GT(Md.diagonal().minCoeff(), 0.0);
    // Kinetic energy (3.23) of a rigid translation: ½ m |v|², m = Σ M / 3.
    if (c.rule == 8) {
      const Vec3 v(0.3, -1.2, 0.7);
      VecX xdot(patch.dofs());
      for (int A = 0; A < patch.control_points(); ++A) xdot.segment<3>(3 * A) = v;
      const double m = M.sum() / 3.0;
      EXPECT_NEAR(patch.kinetic_energy(xdot), 0.5 * m * v.squaredNorm(),
                  1e-13 * m * v.squaredNorm());
    }
  }
  EXPECT_THROW(KLShellPatch(cases[0].s, section(1.0, 0.3, t, rho)).kinetic_energy(VecX::Zero(3)),
               std::invalid_argument);
  EXPECT_EQ(worst_sym, 0.0);
  report("total mass, default rule (rel)", err_default);
  report("total mass, 8x8 rule (rel)", worst);
}

// Stress recovery against closed forms (IGA-thesis §3.4).
TEST(KLShellPatch, StressRecovery) {
  std::mt19937 g(31);
  const double lx = 2.0, ly = 1.0, E = 2.0e3, nu = 0.3, t = 0.04;
  const KLShellPatch patch(flat_plate(g, lx, ly, 3, 3, 3, 2, 0.0), section(E, nu, t));
  const VecX X = patch.reference_positions();
  const Mat3 D = plane_stress(E, nu);
  double worst = 0.0;
  auto check = [&](const Vec3& got, const Vec3& want, double scale) {
    const double e = (got - want).norm() / scale;
    EXPECT_LT(e, 1e-12) << got.transpose() << " vs " << want.transpose();
    worst = std::max(worst, e);
  };
  const double pts[3][2] = {{0.3, 0.4}, {0.77, 0.1}, {0.5, 0.95}};
  // 1. Uniform membrane strain (linear): n = t D ε, σ = n/t top and bottom, m = 0.
  {
    const double e11 = 1e-3, e22 = -4e-4, g12 = 6e-4;
    Mat3 G = Mat3::Zero();
    G << e11, 0.5 * g12, 0, 0.5 * g12, e22, 0, 0, 0, 0;
    const VecX x = affine(X, Mat3::Identity() + G);
    const Vec3 n = t * D * Vec3(e11, e22, g12);
    EXPECT_NEAR(n(0), E * t / (1 - nu * nu) * (e11 + nu * e22), 1e-12 * n.norm());
    for (const auto& p : pts) {
      const auto s = patch.stress(x, p[0], p[1], KLKinematics::linear);
      check(s.n, n, n.norm());
      check(s.m, Vec3::Zero(), n.norm() * t);
      check(s.sigma_top, n / t, n.norm() / t);
      check(s.sigma_bottom, n / t, n.norm() / t);
      check(s.frame.col(0), Vec3::UnitX(), 1.0);
      check(s.frame.col(2), Vec3::UnitZ(), 1.0);
      check(s.point, (Mat3::Identity() + G) * Vec3(lx * p[0], ly * p[1], 0.0), 1.0);
      const Vec3 sg = n / t;
      const double mid = 0.5 * (sg(0) + sg(1)), rad = std::hypot(0.5 * (sg(0) - sg(1)), sg(2));
      check(Vec3(s.principal_top(0), s.principal_top(1), 0), Vec3(mid + rad, mid - rad, 0),
            sg.norm());
      const double s1 = mid + rad, s2 = mid - rad;
      check(Vec3(s.von_mises_top, s.von_mises_bottom, 0),
            Vec3(1, 1, 0) * std::sqrt(s1 * s1 + s2 * s2 - s1 * s2), sg.norm());
    }
  }
  // 2. Finite stretch λ₁, λ₂ (nonlinear): Green–Lagrange E, S = D E, and in the current frame the
  // Cauchy-type resultant n̂₁₁ = t (λ₁/λ₂) S₁₁, n̂₂₂ = t (λ₂/λ₁) S₂₂ (3.44)–(3.46).
  {
    const double l1 = 1.3, l2 = 0.9;
    const VecX x = affine(X, Vec3(l1, l2, 1.0).asDiagonal());
    const Vec3 S = D * Vec3(0.5 * (l1 * l1 - 1), 0.5 * (l2 * l2 - 1), 0.0);
    const Vec3 n(t * l1 / l2 * S(0), t * l2 / l1 * S(1), 0.0);
    for (const auto& p : pts) {
      const auto s = patch.stress(x, p[0], p[1], KLKinematics::nonlinear);
      check(s.n, n, n.norm());
      check(s.sigma_top, n / t, n.norm() / t);
    }
  }
  // 3. Pure bending (linear) w = X²/(2R): m̂₁₁ = −D/R, m̂₂₂ = ν m̂₁₁ (the top fibre, on the side
  // of the centre of curvature, is compressed), σ_top = −σ_bottom = 6 m / t², n = 0.
  {
    const double R = 5.0;
    NurbsSurface ref = geometry::elevate_degree(
        geometry::elevate_degree(geometry::planar_rectangle(lx, ly), geometry::Direction::u, 1),
        geometry::Direction::v, 1);
    NurbsSurface def = ref;
    for (int j = 0; j < 3; ++j) def.points[def.index(2, j)].z() = lx * lx / (2.0 * R);
    ref = geometry::k_refine(ref, 1, 1, 2, 1);
    def = geometry::k_refine(def, 1, 1, 2, 1);
    const KLShellPatch bent(ref, section(E, nu, t));
    const double Dm = E * t * t * t / (12 * (1 - nu * nu));
    const Vec3 m(-Dm / R, -nu * Dm / R, 0.0);
    for (const auto& p : pts) {
      const auto s = bent.stress(positions(def), p[0], p[1], KLKinematics::linear);
      check(s.m, m, m.norm());
      check(s.n, Vec3::Zero(), m.norm() / t);
      check(s.sigma_top, 6.0 * m / (t * t), 6.0 * m.norm() / (t * t));
      check(s.sigma_bottom, -6.0 * m / (t * t), 6.0 * m.norm() / (t * t));
      EXPECT_LT(s.sigma_top(0), 0.0);
      const double s1 = s.principal_bottom(0), s2 = s.principal_bottom(1);
      EXPECT_NEAR(s1,
                  -6.0 * m(1) / (t * t) > -6.0 * m(0) / (t * t) ? -6.0 * m(1) / (t * t)
                                                                : -6.0 * m(0) / (t * t),
                  1e-9 * std::abs(s1));
      EXPECT_NEAR(s.von_mises_bottom, std::sqrt(s1 * s1 + s2 * s2 - s1 * s2), 1e-12 * s1);
      EXPECT_NEAR(s.von_mises_top, s.von_mises_bottom, 1e-12 * s1);
    }
  }
  report("stress recovery vs closed forms (rel)", worst);
}

// The threaded assembly (coloured blocks, coloured_element_loop.hpp) gives r and K bit for bit
// equal to one thread: 24 × 24 bicubic elements, 9 216 points, up to 4 threads.
TEST(KLShellPatch, ThreadsGiveTheSameResultBitForBit) {
  std::mt19937 g(21);
  NurbsSurface s = geometry::k_refine(geometry::cylinder_sector(1.0, 1.5, kPi / 3), 1, 2, 23, 23);
  for (auto& p : s.points) p += random_vector(g, 3, 1e-3);
  KLShellPatch patch(s, section(1.0e3, 0.3, 0.05));
  const VecX x = patch.reference_positions() + random_vector(g, patch.dofs(), 1e-2);
  for (const auto kin : {KLKinematics::nonlinear, KLKinematics::linear}) {
    patch.set_threads(1);
    elements::SpMat K1, K;
    const VecX r1 = patch.internal_force(x, kin, &K1);
    for (int threads : {2, 3, 4}) {
      patch.set_threads(threads);
      EXPECT_EQ(patch.threads(), threads);
      EXPECT_EQ(patch.threads_used(), threads);  // 9 216 points: up to 4
      const VecX r = patch.internal_force(x, kin, &K);
      EXPECT_EQ(r, r1) << threads;
      ASSERT_EQ(K.nonZeros(), K1.nonZeros());
      EXPECT_TRUE(std::equal(K.valuePtr(), K.valuePtr() + K.nonZeros(), K1.valuePtr())) << threads;
      EXPECT_EQ(patch.internal_force(x, kin, nullptr), r1) << threads;
    }
  }
  patch.set_threads(8);
  EXPECT_EQ(patch.threads_used(), 4);
  patch.set_threads(0);
  EXPECT_EQ(patch.threads(), 1);
}

// The parts of an MPI run (set_partition, docs/theory/solvers.md §6): each part sums the elements
// of its block of element rows, and the parts' r and K add up to the whole patch's (to round-off:
// the sums are in another order); a part's energy is the whole patch's. 5 × 7 bicubic elements
// in 1, 2, 3 and 7 parts (7: one row each), with threads, nonlinear and linear (no cached tangent
// in a part).
TEST(KLShellPatch, PartsAddUpToTheWholePatch) {
  std::mt19937 g(22);
  NurbsSurface s = geometry::k_refine(geometry::cylinder_sector(1.0, 1.5, kPi / 3), 1, 2, 4, 6);
  for (auto& p : s.points) p += random_vector(g, 3, 1e-3);
  const KLShellPatch whole(s, section(1.0e3, 0.3, 0.05));
  const VecX x = whole.reference_positions() + random_vector(g, whole.dofs(), 1e-2);
  EXPECT_EQ(whole.parts(), 1);
  EXPECT_EQ(whole.partition_rows().begin, 0);
  EXPECT_EQ(whole.partition_rows().end, 7);
  for (const auto kin : {KLKinematics::nonlinear, KLKinematics::linear}) {
    elements::SpMat K;
    const VecX r = whole.internal_force(x, kin, &K);
    for (int parts : {2, 3, 7}) {
      VecX r_sum = VecX::Zero(r.size());
      VecX K_sum = VecX::Zero(K.nonZeros());
      int rows = 0;
      for (int part = 0; part < parts; ++part) {
        KLShellPatch p = whole;
        p.set_threads(part % 2 + 1);
        p.set_partition(part, parts);
        EXPECT_EQ(p.partition_rows().begin, rows);
        rows = p.partition_rows().end;
        elements::SpMat Kp;
        const VecX rp = p.internal_force(x, kin, &Kp);
        ASSERT_EQ(Kp.nonZeros(), K.nonZeros());
        // The linear tangent is computed, not copied, on a second call too.
        const VecX rp2 = p.internal_force(x, kin, &Kp);
        EXPECT_EQ(rp2, rp);
        r_sum += rp;
        K_sum += Eigen::Map<const VecX>(Kp.valuePtr(), Kp.nonZeros());
        if (parts == 7) {
          EXPECT_GT(rp.norm(), 0.0) << part;  // every row has elements
        }
        EXPECT_EQ(p.energy(x, kin), whole.energy(x, kin));
      }
      EXPECT_EQ(rows, 7);
      EXPECT_LE((r_sum - r).lpNorm<Eigen::Infinity>(), 1e-13 * r.lpNorm<Eigen::Infinity>())
          << parts;
      const Eigen::Map<const VecX> Kv(K.valuePtr(), K.nonZeros());
      EXPECT_LE((K_sum - Kv).lpNorm<Eigen::Infinity>(), 1e-13 * Kv.lpNorm<Eigen::Infinity>())
          << parts;
    }
  }
  KLShellPatch p = whole;
  EXPECT_THROW(p.set_partition(2, 2), std::invalid_argument);
  EXPECT_THROW(p.set_partition(-1, 2), std::invalid_argument);
  EXPECT_THROW(p.set_partition(0, 0), std::invalid_argument);
}
