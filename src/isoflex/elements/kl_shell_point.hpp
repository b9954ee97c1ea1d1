#pragma once
// The quadrature-point kernel of the isogeometric Kirchhoff–Love shell (IGA-thesis §3.2, §4.3;
// derivations and the matrix forms used here: docs/theory/kl-shell.md). One point, its
// (p+1)(q+1) ≤ kKLMaxFunctions rational basis functions with first and second derivatives, the
// pre-evaluated reference geometry (§6.2.2) and the local control points; out come the strains,
// the energy density, the resultants, the strain–displacement matrix (first variations) and the
// geometric stiffness (second variations, incl. the second variation of the normal a₃).
//
// Everything is fixed size or fixed maximum size (no heap allocation): the patch calls these once
// per quadrature point of every element in every residual/tangent evaluation.
#include <array>
#include <cstddef>

#include "isoflex/math/types.hpp"

namespace isoflex::elements::kl {

// Largest number of basis functions per element, (p+1)(q+1): p = q = 5.
inline constexpr int kMaxFunctions = 36;

// Read-only view of the 6 × n basis matrix of one point (rows R, R_ξ, R_η, R_ξξ, R_ξη, R_ηη,
// columns the local functions), entry (d, k) at data[d·row_stride + k·col_stride]: this covers
// geometry::ElementBasis (row-major, col_stride 1) and geometry::SurfaceBasis (column-major 6 × n,
// row_stride 1, col_stride 6) without copying.
struct BasisView {
  const double* data = nullptr;
  int n = 0;
  std::ptrdiff_t row_stride = 0, col_stride = 0;
  double operator()(int d, int k) const { return data[d * row_stride + k * col_stride]; }
};

// Local control points of one element: column k is the control point of local function k.
using LocalPoints = Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::ColMajor, 3, kMaxFunctions>;

// The reference (undeformed) geometry of one quadrature point, evaluated once (§6.2.2).
// Voigt order of every 3-vector of components: (11, 22, 12).
struct ReferencePoint {
  Vec3 A1, A2, A3;     // covariant base vectors ∂_α c₀ and the unit normal n₀ (3.5)
  Vec3 X11, X22, X12;  // second derivatives ∂_αβ c₀ (linearized bending strain, kl-shell.md §3)
  Vec3 A_cov;          // covariant metric A_αβ = A_α·A_β (3.11)
  Vec3 A_con;          // contravariant metric A^{αβ}, the inverse of A_αβ (3.15)
  Vec3 B;              // curvature B_αβ = ∂_αβ c₀ · n₀ (3.12)
  Mat3 C;              // plane-stress material matrix in curvilinear components (3.15)–(3.17),
                       // scaled to the standard plane-stress tensor (kl-shell.md §2)
  double J0 = 0.0;     // |A₁ × A₂| = ν₀ (3.22)
  double dA = 0.0;     // J0 × quadrature weight (parameter-space weight incl. the span Jacobian)
};

// Reference quantities at one point from the basis and the reference control points X (local),
// with quadrature weight w (0 for a point that is not a quadrature point). C uses young, poisson.
// J0 is returned as computed; the caller decides whether it is degenerate.
ReferencePoint reference_point(const BasisView& R, const LocalPoints& X, double w, double young,
                               double poisson);

// The current geometry at one point (4.20)–(4.21): a_α, a_αβ, ã₃ = a₁ × a₂, j = |ã₃|, a₃ = ã₃/j.
struct CurrentPoint {
  Vec3 a1, a2, a11, a22, a12, a3;
  double j = 0.0;
};
CurrentPoint current_point(const BasisView& R, const LocalPoints& x);
// The reference point seen as a current point (a_α = A_α, …), for the linearized kinematics.
CurrentPoint as_current(const ReferencePoint& ref);

// Green–Lagrange membrane and bending strains in Voigt form (E₁₁, E₂₂, 2E₁₂) (3.11), (3.12),
// (3.16).
void strains(const ReferencePoint& ref, const CurrentPoint& cur, Vec3& Em, Vec3& Ef);

// The strain–displacement matrix: for local function k the 6 × 3 block B_k = ∂(E^m; E^f)/∂x_k, the
// first variations E^m_*, E^f_* of (3.33) with n^*(v) written as da₃/dx_k (kl-shell.md §4).
using BBlocks = std::array<Mat<6, 3>, kMaxFunctions>;
// The two matrices with da₃/dx_k = R_k,ξ M₁ + R_k,η M₂: M₁ = −P [a₂]ₓ / j, M₂ = P [a₁]ₓ / j,
// P = I − a₃a₃ᵀ (kl-shell.md §4).
struct NormalFactors {
  Mat3 M1, M2;
};
NormalFactors normal_factors(const CurrentPoint& cur);
void b_matrix(const BasisView& R, const CurrentPoint& cur, const NormalFactors& nf, BBlocks& B);

// Resultants n = t C E^m, m = t³/12 C E^f (contravariant, per unit reference length; kl-shell.md
// §2), the work conjugates of E^m, E^f in the energy density.
struct Resultants {
  Vec3 n, m;
};

// Energy density per unit reference area ½ (n·E^m + m·E^f) (3.22).
double energy_density(const Vec3& Em, const Vec3& Ef, const Resultants& s);

// The tangent (3.36) at one point as a bilinear form in the basis derivatives (kl-shell.md §5):
// with ρ(k) = (R_k,ξ, R_k,η, R_k,ξξ, R_k,ξη, R_k,ηη), rows 1–5 of the basis,
//   dA·(B_kᵀ D B_l + G_kl) = Σ_ij ρ_i(k) ρ_j(l) T_ij,
// the T_ij 3 × 3 matrices of the point alone (material part: T_ij = E_iᵀ D E_j, B_k = Σ_i ρ_i(k)
// E_i).
inline constexpr int kDerivatives = 5;
using PointTangent = Mat<3 * kDerivatives, 3 * kDerivatives>;  // block (3i, 3j) = T_ij
// The same numbers laid out for the element product: column j holds T_0j … T_4j, each
// column-major, i.e. entry (a, b) of T_ij at (9i + a + 3b, j).
using PackedTangent = Mat<9 * kDerivatives, kDerivatives>;
void pack_tangent(const PointTangent& T, PackedTangent& P);

// A vector over the local control points of one element, 3n ≤ 108 entries.
using LocalVector = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, 3 * kMaxFunctions, 1>;
// A vector in the derivative space of B_k = Σ_i ρ_i(k) E_i (kl-shell.md §5).
using Derivatives = Vec<3 * kDerivatives>;
// (Σ_k ρ_i(k) d_k)_i for local vectors d_k (positions, increments, velocities): the derivatives
// (d_ξ, d_η, d_ξξ, d_ξη, d_ηη) of the field d at the point, so that Σ_k B_k d_k = E · (this).
Derivatives gather_derivatives(const BasisView& R, const LocalPoints& d);
// v_k += Σ_i ρ_i(k) f_i for every local function k: B_kᵀ S from f = Eᵀ S.
void spread(const BasisView& R, const Derivatives& f, LocalVector& v);

// The strain operator E = [E_ξ, E_η, E_ξξ, E_ξη, E_ηη] (6 × 15) with B_k = Σ_i ρ_i(k) E_i
// (kl-shell.md §5); so B_kᵀ S = Σ_i ρ_i(k) E_iᵀ S for the residual.
using StrainOperator = Mat<6, 3 * kDerivatives>;
void strain_operator(const CurrentPoint& cur, const NormalFactors& nf, StrainOperator& E);
// The material part T_ij = E_iᵀ D E_j with D = diag(Cm, Cb), Cm = w t C, Cb = w t³/12 C (3.36);
// a3 is the normal of the point E belongs to.
void material_tangent(const StrainOperator& E, const Vec3& a3, const Mat3& Cm, const Mat3& Cb,
                      PointTangent& T);
// The mixed material product T_ij = E_L,iᵀ D E_R,j, D = diag(Cm, Cb), of two strain operators
// (generally of two configurations): the ρ-form of B_Lᵀ D B_R. With E_L = E_R it equals
// material_tangent up to round-off; the discrete gradient's ∂DV/∂x_{n+1} needs
// ½ B(x_{n+½})ᵀ D B(x_{n+1}) (kl-shell.md §10).
void material_tangent(const StrainOperator& EL, const StrainOperator& ER, const Mat3& Cm,
                      const Mat3& Cb, PointTangent& T);
// Adds the geometric part n·E^m_** + m·E^f_** (3.36) with the second variation of the normal
// n^** (kl-shell.md §5); s are the resultants, w the weight dA.
void add_geometric_tangent(const CurrentPoint& cur, const NormalFactors& nf, const Resultants& s,
                           double w, PointTangent& T);

// The element tangent from the point factors of its G points (kl-shell.md §5, eq. (K)):
//   K_kl = Σ_g Σ_i ρ_i^g(k) W_i^g(l),   W_i^g(l) = Σ_j T_ij^g ρ_j^g(l).
// Rho is 5G × n with column k = (ρ^0(k); …; ρ^{G−1}(k)); W is scratch (resized to 9n × 5G).
// K (9n × n, sized by the caller) receives K_kl column-major in rows 9l … 9l + 8 of column k,
// for k ≤ l (the upper block triangle of the element matrix); other entries are unspecified.
void element_tangent(const PackedTangent* T, int G, const MatX& Rho, MatX& W, MatX& K);
// The same product for a tangent that is not symmetric (T_ij ≠ T_jiᵀ, the discrete gradient's
// ∂DV/∂x_{n+1}): K receives every block K_kl, k, l < n, in rows 9l … 9l + 8 of column k.
void element_tangent_full(const PackedTangent* T, int G, const MatX& Rho, MatX& W, MatX& K);

}  // namespace isoflex::elements::kl
