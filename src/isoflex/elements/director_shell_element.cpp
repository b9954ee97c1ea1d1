#include "isoflex/elements/director_shell_element.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace isoflex::elements {

namespace {

using Coeff8 = Vec<8>;
using Mat2 = Eigen::Matrix2d;

// Natural coordinates of the nodes, counter-clockwise (DNSM-III (39) with bilinear N_a).
constexpr double kNodeXi[4][2] = {{-1.0, -1.0}, {1.0, -1.0}, {1.0, 1.0}, {-1.0, 1.0}};

// Block of φ_a (field 0) or d_a (field 1) among the eight 3-vector blocks of q.
constexpr int block(int node, int field) {
  return 2 * node + field;
}

// Values N_a(ξ) and derivatives N_a,α(ξ) of the bilinear shape functions.
struct Shape {
  Vec<4> N;
  Mat<4, 2> dN;
};

Shape shape(double xi1, double xi2) {
  Shape s;
  for (int a = 0; a < 4; ++a) {
    const double s1 = kNodeXi[a][0], s2 = kNodeXi[a][1];
    s.N(a) = 0.25 * (1.0 + s1 * xi1) * (1.0 + s2 * xi2);
    s.dN(a, 0) = 0.25 * s1 * (1.0 + s2 * xi2);
    s.dN(a, 1) = 0.25 * s2 * (1.0 + s1 * xi1);
  }
  return s;
}

// Coefficients over the eight blocks of the interpolated fields at one point:
// φ,α = Σ N_a,α φ_a,  d = Σ N_a d_a,  d,α = Σ N_a,α d_a.
struct Fields {
  std::array<Coeff8, 2> phi_d;
  Coeff8 dir;
  std::array<Coeff8, 2> dir_d;
};

Fields fields(double xi1, double xi2) {
  const Shape s = shape(xi1, xi2);
  Fields f;
  f.dir.setZero();
  for (int al = 0; al < 2; ++al) {
    f.phi_d[al].setZero();
    f.dir_d[al].setZero();
  }
  for (int a = 0; a < 4; ++a) {
    f.dir(block(a, 1)) = s.N(a);
    for (int al = 0; al < 2; ++al) {
      f.phi_d[al](block(a, 0)) = s.dN(a, al);
      f.dir_d[al](block(a, 1)) = s.dN(a, al);
    }
  }
  return f;
}

// u·v with u = Σ α_b q_b, v = Σ β_b q_b equals ½ Σ h(b, c) q_b·q_c with h = αβᵀ + βαᵀ.
Mat<8, 8> bilinear(const Coeff8& alpha, const Coeff8& beta) {
  return alpha * beta.transpose() + beta * alpha.transpose();
}

// γ_α = φ,α·d at one point (theory-notes, Reissner–Mindlin director shell).
Mat<8, 8> shear_form(const Fields& f, int al) {
  return bilinear(f.phi_d[al], f.dir);
}

// Strain forms at ξ in the order ε₁₁, ε₂₂, ε₁₂, κ₁₁, κ₂₂, κ₁₂, γ₁, γ₂; with assumed_shear the
// transverse shear of MITC4 (Dvorkin–Bathe): γ₁ from the edge midpoints (0, ∓1), linear in ξ²;
// γ₂ from (∓1, 0), linear in ξ¹. The tying values are quadratic forms themselves, so the
// interpolated ones are too.
std::array<Mat<8, 8>, 8> strain_forms(double xi1, double xi2, bool assumed_shear) {
  const Fields f = fields(xi1, xi2);
  constexpr int kPair[3][2] = {{0, 0}, {1, 1}, {0, 1}};
  std::array<Mat<8, 8>, 8> h;
  for (int i = 0; i < 3; ++i) {
    const int al = kPair[i][0], be = kPair[i][1];
    h[i] = 0.5 * bilinear(f.phi_d[al], f.phi_d[be]);
    h[3 + i] = 0.5 * (bilinear(f.phi_d[al], f.dir_d[be]) + bilinear(f.phi_d[be], f.dir_d[al]));
  }
  if (assumed_shear) {
    h[6] = 0.5 * (1.0 - xi2) * shear_form(fields(0.0, -1.0), 0) +
           0.5 * (1.0 + xi2) * shear_form(fields(0.0, 1.0), 0);
    h[7] = 0.5 * (1.0 - xi1) * shear_form(fields(-1.0, 0.0), 1) +
           0.5 * (1.0 + xi1) * shear_form(fields(1.0, 0.0), 1);
  } else {
    h[6] = shear_form(f, 0);
    h[7] = shear_form(f, 1);
  }
  return h;
}

// Reference geometry at ξ: covariant base vectors Φ,α, metric A_αβ, area element j.
struct Geometry {
  Vec3 G1, G2, normal;
  Mat2 A;
  double j;
};

Geometry geometry(const Mat<3, 8>& Q0, double xi1, double xi2) {
  const Fields f = fields(xi1, xi2);
  Geometry g;
  g.G1 = Q0 * f.phi_d[0];
  g.G2 = Q0 * f.phi_d[1];
  const Vec3 c = g.G1.cross(g.G2);
  g.j = c.norm();
  g.normal = c / g.j;
  g.A << g.G1.dot(g.G1), g.G1.dot(g.G2), g.G2.dot(g.G1), g.G2.dot(g.G2);
  return g;
}

// H^{αβγδ} = ν A^{αβ}A^{γδ} + ½(1 − ν)(A^{αγ}A^{βδ} + A^{αδ}A^{βγ}) (theory-notes).
double elasticity(const Mat2& Ai, double nu, int a, int b, int c, int d) {
  return nu * Ai(a, b) * Ai(c, d) + 0.5 * (1.0 - nu) * (Ai(a, c) * Ai(b, d) + Ai(a, d) * Ai(b, c));
}

// H in the strain order (11, 22, 12) with ε₁₂ standing for ε₁₂ and ε₂₁: Ĥ_ij = m_i m_j H^{(i)(j)},
// m = (1, 1, 2), so that ½ H^{αβγδ} ε_αβ ε_γδ = ½ eᵀ Ĥ e.
Mat3 voigt_elasticity(const Mat2& Ai, double nu) {
  constexpr int kPair[3][2] = {{0, 0}, {1, 1}, {0, 1}};
  constexpr double kMult[3] = {1.0, 1.0, 2.0};
  Mat3 H;
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k)
      H(i, k) = kMult[i] * kMult[k] *
                elasticity(Ai, nu, kPair[i][0], kPair[i][1], kPair[k][0], kPair[k][1]);
  return H;
}

// n^{αβ} = c H^{αβγδ} t_γδ for a symmetric covariant t.
Mat2 contract(const Mat2& Ai, double nu, double c, const Mat2& t) {
  Mat2 r = Mat2::Zero();
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b)
      for (int g = 0; g < 2; ++g)
        for (int d = 0; d < 2; ++d) r(a, b) += c * elasticity(Ai, nu, a, b, g, d) * t(g, d);
  return r;
}

// Coefficients c with Ê₁₂ = c·(ε₁₁, ε₂₂, ε₁₂): the in-plane shear strain in the orthonormal frame
// (e₁, e₂) of the tangent plane at a point, Ê₁₂ = (e₁·G^α)(e₂·G^β) ε_αβ, G^α = A^{αβ} Φ,β
// (docs/theory/shell.md (3.1a); ε₁₂ standing for ε₁₂ and ε₂₁).
Vec3 cartesian_shear(const Geometry& g, const Vec3& e1, const Vec3& e2) {
  const Mat2 Ai = g.A.inverse();
  const Vec3 Gu1 = Ai(0, 0) * g.G1 + Ai(0, 1) * g.G2;
  const Vec3 Gu2 = Ai(1, 0) * g.G1 + Ai(1, 1) * g.G2;
  const double a1 = e1.dot(Gu1), a2 = e1.dot(Gu2), b1 = e2.dot(Gu1), b2 = e2.dot(Gu2);
  return Vec3(a1 * b1, a2 * b2, a1 * b2 + a2 * b1);
}

void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument("DirectorShellElement: " + message);
}

}  // namespace

DirectorShellElement::DirectorShellElement(const std::array<int, 4>& nodes, const Vec<24>& q0,
                                           const ShellMaterial& m, const Vec3& gravity,
                                           bool assumed_shear, bool assumed_membrane_shear)
    : nodes_(nodes.begin(), nodes.end()), material_(m), g_(gravity) {
  // Checks at the boundary, written so that NaN fails.
  require(m.E > 0.0, "E must be > 0, got " + std::to_string(m.E));
  require(m.nu > -1.0 && m.nu < 0.5, "nu must be in (-1, 0.5), got " + std::to_string(m.nu));
  require(m.thickness > 0.0, "thickness must be > 0, got " + std::to_string(m.thickness));
  require(m.density >= 0.0, "density must be >= 0, got " + std::to_string(m.density));
  require(m.shear_correction > 0.0,
          "shear_correction must be > 0, got " + std::to_string(m.shear_correction));
  require(gravity.allFinite(), "gravity must be finite");
  require(q0.allFinite(), "reference coordinates must be finite");
  const Eigen::Map<const Mat<3, 8>> Q0(q0.data());
  for (int a = 0; a < 4; ++a) {
    const double err = std::abs(Q0.col(block(a, 1)).norm() - 1.0);
    require(err <= 1e-8, "reference director of node " + std::to_string(a) +
                             " is not a unit vector (| |D| - 1 | = " + std::to_string(err) + ")");
    // The bilinear map must be orientable with positive area at every corner (convex, not
    // folded), and the director must point to the side of Φ,₁ × Φ,₂: otherwise the node order is
    // clockwise with respect to the directors.
    const Geometry geo = geometry(Q0, kNodeXi[a][0], kNodeXi[a][1]);
    require(geo.j > 0.0, "degenerate element at node " + std::to_string(a));
    require(geo.normal.dot(Q0.col(block(a, 1))) > 0.0,
            "director of node " + std::to_string(a) +
                " points against the reference normal (nodes must be counter-clockwise seen from "
                "the director tips)");
  }

  const double h = m.thickness;
  const double G = m.E / (2.0 * (1.0 + m.nu));
  const double c_membrane = m.E * h / (1.0 - m.nu * m.nu);
  const double c_bending = m.E * h * h * h / (12.0 * (1.0 - m.nu * m.nu));
  const double c_shear = m.shear_correction * G * h;

  // Centre frame e₁ = Φ,₁/|Φ,₁|, e₂ = N × e₁ and the plain membrane forms there (§3.1).
  const Geometry c0 = geometry(Q0, 0.0, 0.0);
  Mat3 c_frame;
  c_frame.col(0) = c0.G1.normalized();
  c_frame.col(2) = c0.normal;
  c_frame.col(1) = c0.normal.cross(c_frame.col(0));
  const auto c_forms = strain_forms(0.0, 0.0, false);
  const Vec3 c_shear0 = cartesian_shear(c0, c_frame.col(0), c_frame.col(1));

  // 2 × 2 Gauss–Legendre, weights 1.
  const double gp = 1.0 / std::sqrt(3.0);
  constexpr double kGaussSign[4][2] = {{-1.0, -1.0}, {1.0, -1.0}, {1.0, 1.0}, {-1.0, 1.0}};
  area_ = 0.0;
  nodal_areas_.setZero();
  nodal_normal_areas_.setZero();
  mass_n_.setZero();
  for (int g = 0; g < kGauss; ++g) {
    const double xi1 = gp * kGaussSign[g][0], xi2 = gp * kGaussSign[g][1];
    const Geometry geo = geometry(Q0, xi1, xi2);
    require(geo.j > 0.0, "degenerate element at Gauss point " + std::to_string(g));
    const Mat2 Ai = geo.A.inverse();
    const double wj = geo.j;  // Gauss weight 1
    // DNSM-III (38) integrated through the thickness: W = ½(n:ε + m:κ + q·γ) per reference area.
    Block8 C = Block8::Zero();
    const Mat3 H = voigt_elasticity(Ai, m.nu);
    C.block<3, 3>(0, 0) = wj * c_membrane * H;
    C.block<3, 3>(3, 3) = wj * c_bending * H;
    C.block<2, 2>(6, 6) = wj * c_shear * Ai;
    C_[g] = C;

    auto forms = strain_forms(xi1, xi2, assumed_shear);
    if (assumed_membrane_shear) {
      // Assumed in-plane shear (docs/theory/shell.md (3.1a)–(3.1c)): the Cartesian Ê₁₂ in the
      // tangent frame (e₁, e₂) at the Gauss point is replaced by its value at the centre,
      // Δ = Ê₁₂(0) − Ê₁₂(ξ_g), through ε̃_αβ = ε_αβ + (T₁α T₂β + T₂α T₁β) Δ, T(i, α) = e_i·Φ,α,
      // which changes Ê₁₂ only. Δ combines quadratic forms with constant coefficients.
      Vec3 e1 = c_frame.col(0) - geo.normal.dot(c_frame.col(0)) * geo.normal;
      e1.normalize();
      const Vec3 e2 = geo.normal.cross(e1);
      const Vec3 cg = cartesian_shear(geo, e1, e2);
      Block8 delta = Block8::Zero();
      for (int i = 0; i < 3; ++i) delta += c_shear0(i) * c_forms[i] - cg(i) * forms[i];
      const double T[2][2] = {{e1.dot(geo.G1), e1.dot(geo.G2)}, {e2.dot(geo.G1), e2.dot(geo.G2)}};
      forms[0] += 2.0 * T[0][0] * T[1][0] * delta;
      forms[1] += 2.0 * T[0][1] * T[1][1] * delta;
      forms[2] += (T[0][0] * T[1][1] + T[1][0] * T[0][1]) * delta;
    }
    for (int k = 0; k < kPointStrains; ++k) h_[g * kPointStrains + k] = forms[k];

    const Vec<4> N = shape(xi1, xi2).N;
    area_ += wj;
    nodal_areas_ += wj * N;
    nodal_normal_areas_ += wj * geo.normal * N.transpose();
    // N Nᵀ evaluated first: symmetric bit for bit, also with FMA ((wN_a)N_b and (wN_b)N_a, which
    // Eigen forms from wj * (N Nᵀ) written inline, round differently).
    const Mat<4, 4> NN = N * N.transpose();
    mass_n_ += wj * NN;
  }

  Q q0e = q0;
  const Jacobian B0 = strain_jacobian(q0e);
  e0_ = 0.5 * B0 * q0e;

  // Centre data for the resultant output.
  h_centre_ = strain_forms(0.0, 0.0, assumed_shear);
  for (int k = 0; k < kPointStrains; ++k) {
    const Mat<3, 8> HQ = Q0.lazyProduct(h_centre_[k]);
    e0_centre_(k) = 0.5 * HQ.cwiseProduct(Q0).sum();
  }
  A_inv_centre_ = c0.A.inverse();
  frame_centre_ = c_frame;
  for (int i = 0; i < 2; ++i) {
    T_centre_(i, 0) = frame_centre_.col(i).dot(c0.G1);
    T_centre_(i, 1) = frame_centre_.col(i).dot(c0.G2);
  }
}

DirectorShellElement::Q DirectorShellElement::as_element_q(const VecX& q) {
  if (q.size() != kCoords)
    throw std::invalid_argument("DirectorShellElement: expected 24 coordinates, got " +
                                std::to_string(q.size()));
  return q;
}

DirectorShellElement::Jacobian DirectorShellElement::strain_jacobian(const Q& q) const {
  // Row k of B is (H_k q)ᵀ = ((h_k ⊗ I₃) q)ᵀ, i.e. the 3 × 8 matrix Q h_k read column by column.
  const Eigen::Map<const Mat<3, 8>> blocks(q.data());
  Jacobian B;
  for (int k = 0; k < kStrains; ++k) {
    const Mat<3, 8> row = blocks.lazyProduct(h_[k]);
    B.row(k) = Eigen::Map<const Q>(row.data()).transpose();
  }
  return B;
}

DirectorShellElement::Strains DirectorShellElement::stresses(const Strains& e) const {
  Strains S;
  for (int g = 0; g < kGauss; ++g)
    S.segment<kPointStrains>(kPointStrains * g) =
        C_[g] * e.segment<kPointStrains>(kPointStrains * g);
  return S;
}

Mat<DirectorShellElement::kCoords, DirectorShellElement::kCoords>
DirectorShellElement::weighted_strain_hessian(const Strains& S) const {
  Block8 h = Block8::Zero();
  for (int k = 0; k < kStrains; ++k) h += S(k) * h_[k];
  Mat<kCoords, kCoords> H = Mat<kCoords, kCoords>::Zero();
  for (int b = 0; b < 8; ++b)
    for (int c = 0; c < 8; ++c) H.block<3, 3>(3 * b, 3 * c).diagonal().setConstant(h(b, c));
  return H;
}

Mat<DirectorShellElement::kCoords, DirectorShellElement::kCoords>
DirectorShellElement::material_stiffness(const Jacobian& Bl, const Jacobian& Br) const {
  Mat<kCoords, kCoords> K = Mat<kCoords, kCoords>::Zero();
  for (int g = 0; g < kGauss; ++g) {
    const Mat<kPointStrains, kCoords> CB =
        C_[g].lazyProduct(Br.middleRows<kPointStrains>(kPointStrains * g));
    K.noalias() += Bl.middleRows<kPointStrains>(kPointStrains * g).transpose().lazyProduct(CB);
  }
  return K;
}

Vec<DirectorShellElement::kCoords> DirectorShellElement::gravity_gradient() const {
  // V_g = −ρh ∫ g·φ dA = −ρh Σ_a (∫ N_a dA) g·φ_a: linear, so its own discrete gradient.
  Q f = Q::Zero();
  const double rho_h = material_.density * material_.thickness;
  for (int a = 0; a < 4; ++a) f.segment<3>(3 * block(a, 0)) = -rho_h * nodal_areas_(a) * g_;
  return f;
}

double DirectorShellElement::potential(const VecX& qx) const {
  const Q q = as_element_q(qx);
  // Homogeneous quadratic forms: E_k + E_k⁰ = ½ qᵀ H_k q = ½ (B q)_k.
  const Strains e = 0.5 * strain_jacobian(q) * q - e0_;
  return 0.5 * e.dot(stresses(e)) + gravity_gradient().dot(q);
}

VecX DirectorShellElement::gradient(const VecX& qx) const {
  const Q q = as_element_q(qx);
  const Jacobian B = strain_jacobian(q);
  const Strains S = stresses(0.5 * B * q - e0_);
  const Q g = B.transpose() * S + gravity_gradient();
  return g;
}

Mat<24, 24> DirectorShellElement::stiffness(const Vec<24>& q) const {
  const Jacobian B = strain_jacobian(q);
  const Strains S = stresses(0.5 * B * q - e0_);
  return material_stiffness(B, B) + weighted_strain_hessian(S);
}

VecX DirectorShellElement::discrete_gradient(const VecX& qnx, const VecX& qn1x,
                                             MatX* dv_dqn1) const {
  const Q qn = as_element_q(qnx);
  const Q qn1 = as_element_q(qn1x);
  const Jacobian Bn = strain_jacobian(qn);
  const Jacobian Bn1 = strain_jacobian(qn1);
  const Jacobian Bm = 0.5 * (Bn + Bn1);  // B is linear in q: B(q_{n+½})
  // Average strain Ē = ½(E(qₙ) + E(qₙ₊₁)), not E(q_{n+½}): with E quadratic,
  // E(qₙ₊₁) − E(qₙ) = B(q_{n+½})(qₙ₊₁ − qₙ) exactly, so DV·Δq = ΔV (theory-notes, average strain).
  const Strains e_avg = 0.25 * (Bn * qn + Bn1 * qn1) - e0_;
  const Strains S = stresses(e_avg);
  const Q dv = Bm.transpose() * S + gravity_gradient();
  if (dv_dqn1) {
    // ∂/∂qₙ₊₁ [B(q_{n+½})ᵀ S̄] = ½ Σ_k S̄_k H_k + ½ B(q_{n+½})ᵀ C B(qₙ₊₁) — not symmetric.
    const Mat<kCoords, kCoords> K =
        0.5 * (weighted_strain_hessian(S) + material_stiffness(Bm, Bn1));
    *dv_dqn1 = K;
  }
  return dv;
}

DirectorShellElement::Strains DirectorShellElement::estimated_strains(const Q& qn1,
                                                                      const VecX* q_lin,
                                                                      const Strains& en) const {
  if (!q_lin) return en;
  const Q ql = as_element_q(*q_lin);
  const Jacobian Bl = strain_jacobian(ql);
  return Bl * qn1 - 0.5 * Bl * ql;  // B(q) q = 2(E(q) + E⁰)
}

VecX DirectorShellElement::mixed_discrete_gradient_in_pattern(const VecX& qnx, const VecX& qn1x,
                                                              const VecX* q_lin, double* values,
                                                              VecX* stress_force) const {
  const Q qn = as_element_q(qnx);
  const Q qn1 = as_element_q(qn1x);
  const Jacobian Bn = strain_jacobian(qn);
  const Jacobian Bn1 = strain_jacobian(qn1);
  const Jacobian Bm = 0.5 * (Bn + Bn1);
  const Strains en = 0.5 * Bn * qn;  // E(qₙ) + E⁰ (B(q) q = 2(E(q) + E⁰), E quadratic)
  const Strains S = stresses(0.5 * (en + 0.5 * Bn1 * qn1) - e0_);
  const Q dv = Bm.transpose() * S + gravity_gradient();
  if (!values && !stress_force) return dv;
  const Strains S_hat = stresses(0.5 * (en + estimated_strains(qn1, q_lin, en)) - e0_);
  if (stress_force) *stress_force = Bm.transpose() * (S_hat - S);
  if (values) {
    Eigen::Map<Mat<kCoords, kCoords>> K(values);
    K = 0.5 * (weighted_strain_hessian(S_hat) + material_stiffness(Bm, Bn1));
  }
  return dv;
}

VecX DirectorShellElement::strain_dissipation_force_in_pattern(const VecX& q_prev, const VecX& qn,
                                                               const VecX& qn1, double chi,
                                                               double ratio, double* values) const {
  return dissipation(q_prev, qn, qn1, nullptr, false, chi, ratio, values, nullptr);
}

VecX DirectorShellElement::mixed_strain_dissipation_force_in_pattern(
    const VecX& q_prev, const VecX& qn, const VecX& qn1, const VecX* q_lin, double chi,
    double ratio, double* values, VecX* stress_force) const {
  return dissipation(q_prev, qn, qn1, q_lin, true, chi, ratio, values, stress_force);
}

VecX DirectorShellElement::dissipation(const VecX& q_prevx, const VecX& qnx, const VecX& qn1x,
                                       const VecX* q_lin, bool mixed, double chi, double ratio,
                                       double* values, VecX* stress_force) const {
  const Q qp = as_element_q(q_prevx);
  const Q qn = as_element_q(qnx);
  const Q qn1 = as_element_q(qn1x);
  const Jacobian Bn = strain_jacobian(qn);
  const Jacobian Bn1 = strain_jacobian(qn1);
  const Jacobian Bm = 0.5 * (Bn + Bn1);
  // E + E⁰ = ½ B(q) q: the strain differences without the reference strains.
  const Strains en = 0.5 * Bn * qn;
  const Strains back = ratio * (en - 0.5 * strain_jacobian(qp) * qp);  // r ΔEₙ
  const Strains S = chi * stresses(0.5 * Bn1 * qn1 - en - back);
  const Q f = Bm.transpose() * S;
  if (!values && !stress_force) return f;
  // The geometric part with Ê for E(qₙ₊₁) in the mixed iteration.
  const Strains S_geo =
      mixed ? Strains(chi * stresses(estimated_strains(qn1, q_lin, en) - en - back)) : S;
  if (stress_force) *stress_force = Bm.transpose() * (S_geo - S);
  if (values) {
    Eigen::Map<Mat<kCoords, kCoords>> K(values);
    K += 0.5 * weighted_strain_hessian(S_geo) + chi * material_stiffness(Bm, Bn1);
  }
  return f;
}

VecX DirectorShellElement::viscous_force_in_pattern(const VecX& qx, const VecX& qdotx, double cq,
                                                    double cv, double* values) const {
  const Q q = as_element_q(qx), v = as_element_q(qdotx);
  const Jacobian B = strain_jacobian(q);
  const Strains Sv = material_.eta * stresses(B * v);  // η C Ė, Ė = B(q) q̇
  if (values) {
    const Jacobian Bv = strain_jacobian(v);
    const Mat<kCoords, kCoords> K =
        (cv * material_.eta) * material_stiffness(B, B) +
        cq * (weighted_strain_hessian(Sv) + material_.eta * material_stiffness(B, Bv));
    Eigen::Map<Mat<kCoords, kCoords>>(values) += K;  // the dense pattern, column-major
  }
  return B.transpose() * Sv;
}

MatX DirectorShellElement::mass() const {
  // T = ½ ∫ ρh (|φ̇|² + (h²/12)|ḋ|²) dA: M = (∫ N_a N_b dA) ⊗ diag(ρh, ρh³/12) ⊗ I₃.
  const double rho_h = material_.density * material_.thickness;
  const double rho[2] = {rho_h, rho_h * material_.thickness * material_.thickness / 12.0};
  Mat<kCoords, kCoords> M = Mat<kCoords, kCoords>::Zero();
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b)
      for (int f = 0; f < 2; ++f)
        M.block<3, 3>(3 * block(a, f), 3 * block(b, f))
            .diagonal()
            .setConstant(mass_n_(a, b) * rho[f]);
  return M;
}

DirectorShellElement::Resultants DirectorShellElement::stress_resultants(const Vec<24>& q) const {
  const Eigen::Map<const Mat<3, 8>> blocks(q.data());
  Vec<kPointStrains> e;
  for (int k = 0; k < kPointStrains; ++k) {
    const Mat<3, 8> HQ = blocks.lazyProduct(h_centre_[k]);
    e(k) = 0.5 * HQ.cwiseProduct(blocks).sum() - e0_centre_(k);
  }
  Mat2 eps, kap;
  eps << e(0), e(2), e(2), e(1);
  kap << e(3), e(5), e(5), e(4);
  const ShellMaterial& m = material_;
  const double h = m.thickness;
  const double G = m.E / (2.0 * (1.0 + m.nu));
  // Contravariant resultants in the natural basis (theory-notes), then in the orthonormal frame:
  // n = n^{αβ} Φ,α ⊗ Φ,β has components T n Tᵀ along (e₁, e₂), T(i, α) = e_i·Φ,α.
  const Mat2 n = contract(A_inv_centre_, m.nu, m.E * h / (1.0 - m.nu * m.nu), eps);
  const Mat2 mm =
      contract(A_inv_centre_, m.nu, m.E * h * h * h / (12.0 * (1.0 - m.nu * m.nu)), kap);
  const Eigen::Vector2d qs = m.shear_correction * G * h * A_inv_centre_ * e.tail<2>();
  Resultants r;
  r.frame = frame_centre_;
  r.n = T_centre_ * n * T_centre_.transpose();
  r.m = T_centre_ * mm * T_centre_.transpose();
  r.q = T_centre_ * qs;
  return r;
}

}  // namespace isoflex::elements
