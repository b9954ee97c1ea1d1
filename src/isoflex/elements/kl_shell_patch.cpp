// KLShellPatch: construction (checks, pre-evaluation of the reference geometry, fixed pattern,
// constant mass) and assembly of energy, internal force and tangent over the knot-span elements
// (IGA-thesis §4.3, (4.22)–(4.24); the point kernel is kl_shell_point.*).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include "isoflex/elements/kl_shell_patch_impl.hpp"
#include "isoflex/geometry/element_basis.hpp"
#include "isoflex/math/exact_text.hpp"
#include "isoflex/math/sparse_pattern.hpp"

namespace isoflex::elements {

namespace {

[[noreturn]] void fail(const std::string& msg) {
  throw std::invalid_argument("KLShellPatch: " + msg);
}

using kl::LocalVector;

// What one thread of internal_force works in.
struct ElementWork {
  geometry::ElementBasis eb;
  kl::LocalPoints xl, Xl;
  LocalVector re;
  std::vector<kl::PackedTangent> Tg;
  MatX Rho, W, Ke;
};

}  // namespace

VecX KLShellPatch::Impl::reference_positions() const {
  VecX X(3 * static_cast<Eigen::Index>(ref.points.size()));
  for (std::size_t i = 0; i < ref.points.size(); ++i) X.segment<3>(3 * i) = ref.points[i];
  return X;
}

void KLShellPatch::Impl::gather(const VecX& x, int e, kl::LocalPoints& xl) const {
  xl.resize(3, n_fun);
  const int* c = conn.data() + static_cast<std::size_t>(e) * n_fun;
  for (int k = 0; k < n_fun; ++k) xl.col(k) = x.segment<3>(3 * c[k]);
}

int KLShellPatch::Impl::workers(int threads) const {
  // Below ~2000 quadrature points per thread the start of a thread costs more than it saves.
  constexpr std::size_t kPointsPerWorker = 2048;
  const auto most = static_cast<int>(std::max<std::size_t>(1, points.size() / kPointsPerWorker));
  return std::clamp(threads, 1, most);
}

void KLShellPatch::Impl::check_size(const VecX& x, const char* what) const {
  const auto n = 3 * static_cast<Eigen::Index>(ref.points.size());
  if (x.size() != n)
    fail(std::string(what) + ": x has " + std::to_string(x.size()) + " entries, expected " +
         std::to_string(n) + " (3 per control point)");
  if (!x.allFinite()) fail(std::string(what) + ": x is not finite");
}

KLShellPatch::KLShellPatch(geometry::NurbsSurface reference, KLShellSection section, int rule_u,
                           int rule_v) {
  reference.validate();
  const int p = reference.degree_u(), q = reference.degree_v();
  if (p < 2 || q < (section.bending_strip ? 1 : 2))
    fail("degree (" + std::to_string(p) + ", " + std::to_string(q) +
         (section.bending_strip
              ? "): a bending strip needs degree ≥ 2 across (ξ) and ≥ 1 along (η)"
              : "): a Kirchhoff–Love shell needs degree ≥ 2 in both directions (C¹, second "
                "derivatives)"));
  if ((p + 1) * (q + 1) > kl::kMaxFunctions)
    fail("degree (" + std::to_string(p) + ", " + std::to_string(q) +
         "): (p+1)(q+1) = " + std::to_string((p + 1) * (q + 1)) + " > " +
         std::to_string(kl::kMaxFunctions) + " functions per element");
  if (!(section.young > 0.0) || !std::isfinite(section.young))
    fail("Young's modulus must be positive, got " + exact_text(section.young));
  if (!(section.poisson > -1.0 && section.poisson < 0.5))
    fail("Poisson's ratio must lie in (-1, 0.5), got " + exact_text(section.poisson));
  if (!(section.thickness > 0.0) || !std::isfinite(section.thickness))
    fail("thickness must be positive, got " + exact_text(section.thickness));
  if (!(section.density >= 0.0) || !std::isfinite(section.density))
    fail("density must be >= 0, got " + exact_text(section.density));
  if (rule_u < 0 || rule_v < 0)
    fail("Gauss points per span must be >= 0 (0 = degree + 1), got " + std::to_string(rule_u) +
         ", " + std::to_string(rule_v));

  auto im = std::make_shared<Impl>();
  Impl& m = *im;
  m.ref = std::move(reference);
  m.sec = section;
  m.rule_u = geometry::gauss_legendre(rule_u > 0 ? rule_u : p + 1);
  m.rule_v = geometry::gauss_legendre(rule_v > 0 ? rule_v : q + 1);
  m.elems = geometry::surface_elements(m.ref);
  {
    // Blocks of p × q elements: blocks of one colour share no control point.
    int nu = 0;
    while (nu < static_cast<int>(m.elems.size()) && m.elems[nu].span_v == m.elems[0].span_v) ++nu;
    m.loop = ColouredElementLoop(nu, static_cast<int>(m.elems.size()) / nu, p, q);
    m.elements_u = nu;
  }
  m.n_fun = (p + 1) * (q + 1);
  m.n_qp = m.rule_u.size() * m.rule_v.size();
  const int ne = static_cast<int>(m.elems.size());
  const int ncp = static_cast<int>(m.ref.points.size());

  // Pre-evaluation of the reference geometry (IGA-thesis §6.2.2) and the connectivity.
  m.points.resize(static_cast<std::size_t>(ne) * m.n_qp);
  m.conn.resize(static_cast<std::size_t>(ne) * m.n_fun);
  const VecX X = m.reference_positions();
  geometry::ElementBasis eb;
  kl::LocalPoints Xl;
  for (int e = 0; e < ne; ++e) {
    const auto& el = m.elems[e];
    geometry::element_basis(m.ref, el, m.rule_u, m.rule_v, eb);
    for (int k = 0; k < m.n_fun; ++k) m.conn[e * m.n_fun + k] = eb.global_index(m.ref, k);
    m.gather(X, e, Xl);
    const double jac = 0.25 * (el.u1 - el.u0) * (el.v1 - el.v0);
    for (int g = 0; g < m.n_qp; ++g) {
      const int i = g % eb.n_u, j = g / eb.n_u;
      const double w = m.rule_u.weights[i] * m.rule_v.weights[j] * jac;
      kl::ReferencePoint& r = m.points[static_cast<std::size_t>(e) * m.n_qp + g];
      r = kl::reference_point(Impl::view(eb, g), Xl, w, section.young, section.poisson);
      if (section.bending_strip) {
        // (4.29)–(4.31): Ê₁₁ = ‖A₁‖⁻² E₁₁ in the Cartesian frame e₁ = A₁/‖A₁‖, so the one
        // non-zero curvilinear entry is E_s ‖A₁‖⁻⁴.
        r.C.setZero();
        r.C(0, 0) = section.young / (r.A_cov(0) * r.A_cov(0));
      }
      if (!(r.J0 > 1e-12 * r.A1.norm() * r.A2.norm()))
        fail("degenerate reference geometry at (xi, eta) = (" + exact_text(eb.xi[i]) + ", " +
             exact_text(eb.eta[j]) + "): |A1 x A2| = " + exact_text(r.J0));
    }
  }

  // The fixed pattern: control points A, B sharing an element, all 3 × 3 blocks.
  std::vector<std::vector<int>> nbr(ncp);
  for (int e = 0; e < ne; ++e) {
    const int* c = m.conn.data() + static_cast<std::size_t>(e) * m.n_fun;
    for (int l = 0; l < m.n_fun; ++l)
      for (int k = 0; k < m.n_fun; ++k) nbr[c[l]].push_back(c[k]);
  }
  std::size_t nnz = 0;
  for (auto& v : nbr) {
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
    nnz += 9 * v.size();
  }
  if (nnz > static_cast<std::size_t>(std::numeric_limits<int>::max()))
    fail("pattern too large (" + std::to_string(nnz) + " non-zeros)");
  const int n = 3 * ncp;
  m.pattern = SpMat(n, n);
  m.pattern.resizeNonZeros(static_cast<Eigen::Index>(nnz));
  m.col_nnz.resize(ncp);
  std::vector<int> col_start(ncp);
  {
    int* outer = m.pattern.outerIndexPtr();
    int* inner = m.pattern.innerIndexPtr();
    int pos = 0;
    for (int B = 0; B < ncp; ++B) {
      col_start[B] = pos;
      m.col_nnz[B] = 3 * static_cast<int>(nbr[B].size());
      for (int c = 0; c < 3; ++c) {
        outer[3 * B + c] = pos;
        for (int A : nbr[B])
          for (int i = 0; i < 3; ++i) inner[pos++] = 3 * A + i;
      }
    }
    outer[n] = pos;
    std::fill_n(m.pattern.valuePtr(), nnz, 0.0);
  }
  m.block_pos.resize(static_cast<std::size_t>(ne) * m.n_fun * m.n_fun);
  for (int e = 0; e < ne; ++e) {
    const int* c = m.conn.data() + static_cast<std::size_t>(e) * m.n_fun;
    for (int l = 0; l < m.n_fun; ++l) {
      const auto& v = nbr[c[l]];
      for (int k = 0; k < m.n_fun; ++k) {
        const auto r = std::lower_bound(v.begin(), v.end(), c[k]) - v.begin();
        m.block_pos[(static_cast<std::size_t>(e) * m.n_fun + l) * m.n_fun + k] =
            col_start[c[l]] + 3 * static_cast<int>(r);
      }
    }
  }

  impl_ = std::move(im);
}

// Constant consistent mass (IGA-thesis (4.24)): M_AB = 2ε ρ ∫ R_A R_B ν₀ dϑ ⊗ I₃, 2ε = t.
const SpMat& KLShellPatch::Impl::consistent_mass() const {
  std::call_once(mass_once, [&] {
    const double rho_t = sec.density * sec.thickness;
    mass = pattern;
    double* val = mass.valuePtr();
    geometry::ElementBasis eb;
    for (int e = 0; e < static_cast<int>(elems.size()); ++e) {
      geometry::element_basis(ref, elems[e], rule_u, rule_v, eb);
      const int* c = conn.data() + static_cast<std::size_t>(e) * n_fun;
      for (int g = 0; g < n_qp; ++g) {
        const kl::BasisView R = view(eb, g);
        const double dA = points[static_cast<std::size_t>(e) * n_qp + g].dA * rho_t;
        for (int l = 0; l < n_fun; ++l) {
          const int* bp = block_pos.data() + (static_cast<std::size_t>(e) * n_fun + l) * n_fun;
          const int stride = col_nnz[c[l]];
          for (int k = 0; k < n_fun; ++k) {
            const double mkl = dA * (R(0, k) * R(0, l));  // symmetric in k, l bit for bit
            for (int i = 0; i < 3; ++i) val[bp[k] + i * stride + i] += mkl;
          }
        }
      }
    }
  });
  return mass;
}

const geometry::NurbsSurface& KLShellPatch::reference() const {
  return impl_->ref;
}
const KLShellSection& KLShellPatch::section() const {
  return impl_->sec;
}
int KLShellPatch::control_points() const {
  return static_cast<int>(impl_->ref.points.size());
}
int KLShellPatch::elements() const {
  return static_cast<int>(impl_->elems.size());
}
int KLShellPatch::quadrature_points() const {
  return static_cast<int>(impl_->points.size());
}
std::size_t KLShellPatch::reference_bytes_per_point() const {
  return sizeof(kl::ReferencePoint);
}
VecX KLShellPatch::reference_positions() const {
  return impl_->reference_positions();
}
void KLShellPatch::set_keep_linear_tangent(bool keep) {
  keep_linear_tangent_ = keep;
  if (keep) return;
  const std::lock_guard<std::mutex> lock(impl_->linear_mutex);
  std::vector<double>().swap(impl_->linear_values);
}

void KLShellPatch::set_partition(int part, int parts) {
  if (!(parts >= 1 && part >= 0 && part < parts))
    throw std::invalid_argument("KLShellPatch::set_partition: part " + std::to_string(part) +
                                " of " + std::to_string(parts));
  part_ = part;
  parts_ = parts;
}

KLShellPatch::RowRange KLShellPatch::partition_rows() const {
  const long long rows = elements() / impl_->elements_u;
  return {static_cast<int>(rows * part_ / parts_), static_cast<int>(rows * (part_ + 1) / parts_)};
}

int KLShellPatch::threads_used() const {
  return impl_->workers(threads_);
}
const SpMat& KLShellPatch::pattern() const {
  return impl_->pattern;
}
const SpMat& KLShellPatch::mass() const {
  return impl_->consistent_mass();
}

double KLShellPatch::kinetic_energy(const VecX& velocity) const {
  if (velocity.size() != dofs())
    throw std::invalid_argument("KLShellPatch::kinetic_energy: wrong size of the velocity");
  return 0.5 * velocity.dot(mass() * velocity);
}

double KLShellPatch::energy(const VecX& x, KLKinematics kin) const {
  const Impl& m = *impl_;
  m.check_size(x, "energy");
  const double t = m.membrane_thickness(), tb = m.bending_thickness();
  const bool linear = kin == KLKinematics::linear;
  const VecX X = linear ? m.reference_positions() : VecX();
  geometry::ElementBasis eb;
  kl::LocalPoints xl, Xl;
  kl::BBlocks B;
  double U = 0.0;
  for (int e = 0; e < static_cast<int>(m.elems.size()); ++e) {
    geometry::element_basis(m.ref, m.elems[e], m.rule_u, m.rule_v, eb);
    m.gather(x, e, xl);
    if (linear) {
      m.gather(X, e, Xl);
      xl -= Xl;  // u = x − X
    }
    for (int g = 0; g < m.n_qp; ++g) {
      const kl::BasisView R = Impl::view(eb, g);
      const kl::ReferencePoint& ref = m.points[static_cast<std::size_t>(e) * m.n_qp + g];
      Vec3 Em, Ef;
      if (linear) {
        // Strains linearized about the reference: E = B(X) u (kl-shell.md §3).
        const kl::CurrentPoint cur = kl::as_current(ref);
        kl::b_matrix(R, cur, kl::normal_factors(cur), B);
        Vec<6> E = Vec<6>::Zero();
        for (int k = 0; k < m.n_fun; ++k) E.noalias() += B[k] * xl.col(k);
        Em = E.head<3>();
        Ef = E.tail<3>();
      } else {
        kl::strains(ref, kl::current_point(R, xl), Em, Ef);
      }
      const kl::Resultants s{t * (ref.C * Em), tb * (ref.C * Ef)};
      U += ref.dA * kl::energy_density(Em, Ef, s);  // IGA-thesis (3.22)
    }
  }
  return U;
}

void KLShellPatch::Impl::adopt_pattern(SpMat& K) const {
  if (!has_pattern(K, pattern)) K = pattern;
}

void KLShellPatch::Impl::scatter_full(int e, const MatX& Ke, double* values) const {
  const int* cn = conn.data() + static_cast<std::size_t>(e) * n_fun;
  for (int l = 0; l < n_fun; ++l) {
    const int* bp = block_pos.data() + (static_cast<std::size_t>(e) * n_fun + l) * n_fun;
    const int stride = col_nnz[cn[l]];
    for (int cc = 0; cc < 3; ++cc) {
      double* col = values + cc * stride;
      for (int k = 0; k < n_fun; ++k) {
        const double* src = &Ke(9 * l + 3 * cc, k);
        double* dst = col + bp[k];
        for (int i = 0; i < 3; ++i) dst[i] += src[i];
      }
    }
  }
}

VecX KLShellPatch::internal_force(const VecX& x, KLKinematics kin, SpMat* K) const {
  if (!K) return internal_force_into(x, kin, nullptr);
  impl_->adopt_pattern(*K);
  return internal_force_into(x, kin, K->valuePtr());
}

VecX KLShellPatch::internal_force_into(const VecX& x, KLKinematics kin, double* values) const {
  const Impl& m = *impl_;
  m.check_size(x, "internal_force");
  const double t = m.membrane_thickness(), tb = m.bending_thickness();
  const bool linear = kin == KLKinematics::linear;
  const int nf = m.n_fun;
  const VecX X = linear ? m.reference_positions() : VecX();
  VecX r = VecX::Zero(x.size());
  const Eigen::Index nnz = m.pattern.nonZeros();
  bool tangent = values != nullptr;  // false: the values are the cached linear tangent
  // The cached tangent is the whole patch's: a part of it computes its own.
  const bool cache = linear && parts_ == 1;
  const RowRange own = partition_rows();
  if (values && cache) {
    const std::lock_guard<std::mutex> lock(m.linear_mutex);
    if (!m.linear_values.empty()) {
      std::copy(m.linear_values.begin(), m.linear_values.end(), values);
      tangent = false;
    }
  }
  if (tangent) std::fill_n(values, nnz, 0.0);
  // One work space per thread, allocated once per call: the point factors T^g of one element,
  // the basis derivatives ρ^g(k) (5G × n), the scratch W and the element blocks K_kl
  // (kl-shell.md §5).
  const int workers = m.workers(threads_);
  std::vector<ElementWork> work(static_cast<std::size_t>(workers));
  for (ElementWork& w : work) {
    w.re.resize(3 * nf);
    if (!tangent) continue;
    w.Tg.resize(static_cast<std::size_t>(m.n_qp));
    w.Rho.resize(kl::kDerivatives * m.n_qp, nf);
    w.Ke.resize(9 * nf, nf);
  }
  // Elements of one colour share no control point (coloured_element_loop.hpp): their scatters
  // into r and K do not overlap.
  m.loop.run(workers, [&](int e, int worker) {
    const int row = e / m.elements_u;
    if (row < own.begin || row >= own.end) return;  // another part's element (set_partition)
    ElementWork& w = work[static_cast<std::size_t>(worker)];
    kl::LocalPoints& xl = w.xl;
    geometry::ElementBasis& eb = w.eb;
    LocalVector& re = w.re;
    kl::StrainOperator E;
    kl::PointTangent T;
    geometry::element_basis(m.ref, m.elems[e], m.rule_u, m.rule_v, eb);
    m.gather(x, e, xl);
    if (linear) {
      m.gather(X, e, w.Xl);
      xl -= w.Xl;  // u = x − X
    }
    re.setZero();
    for (int g = 0; g < m.n_qp; ++g) {
      const kl::BasisView R = Impl::view(eb, g);
      const kl::ReferencePoint& ref = m.points[static_cast<std::size_t>(e) * m.n_qp + g];
      const kl::CurrentPoint cur = linear ? kl::as_current(ref) : kl::current_point(R, xl);
      const kl::NormalFactors nfac = kl::normal_factors(cur);
      kl::strain_operator(cur, nfac, E);
      kl::Resultants s;
      if (linear) {
        // r = K_lin (x − X), K_lin = ∫ B(X)ᵀ D B(X) dA (kl-shell.md §3): the strains
        // B(X) u = Σ_i E_i Σ_k ρ_i(k) u_k.
        const Vec<6> Eu = E * kl::gather_derivatives(R, xl);
        s.n = t * (ref.C * Eu.head<3>());
        s.m = tb * (ref.C * Eu.tail<3>());
      } else {
        Vec3 Em, Ef;
        kl::strains(ref, cur, Em, Ef);
        s.n = t * (ref.C * Em);  // S^m = C E^m (3.14), pre-integrated over the thickness
        s.m = tb * (ref.C * Ef);
      }
      if (tangent) {
        // IGA-thesis (3.36) as Σ_ij ρ_i(k) ρ_j(l) T_ij (kl-shell.md §5); the linear tangent is
        // the material part at the reference.
        kl::material_tangent(E, cur.a3, (ref.dA * t) * ref.C, (ref.dA * tb) * ref.C, T);
        if (!linear) kl::add_geometric_tangent(cur, nfac, s, ref.dA, T);
        kl::pack_tangent(T, w.Tg[static_cast<std::size_t>(g)]);
        for (int k = 0; k < nf; ++k)
          for (int i = 0; i < kl::kDerivatives; ++i)
            w.Rho(kl::kDerivatives * g + i, k) = R(1 + i, k);
      }
      // IGA-thesis (3.34)–(3.35): a(u, v) = ∫ (n·E^m_*(v) + m·E^f_*(v)) ν₀ dϑ, i.e.
      // r_k += B_kᵀ S dA = Σ_i ρ_i(k) E_iᵀ S dA.
      Vec<6> S;
      S << s.n, s.m;
      S *= ref.dA;
      kl::spread(R, E.transpose() * S, re);
    }
    const int* c = m.conn.data() + static_cast<std::size_t>(e) * nf;
    for (int k = 0; k < nf; ++k) r.segment<3>(3 * c[k]) += re.segment<3>(3 * k);
    if (tangent) {
      kl::element_tangent(w.Tg.data(), m.n_qp, w.Rho, w.W, w.Ke);
      const MatX& Ke = w.Ke;
      // Scatter by the precomputed positions; Ke holds the upper block triangle (k ≤ l), block
      // (k, l) column-major in rows 9l … 9l + 8 of column k.
      double* val = values;
      for (int l = 0; l < nf; ++l) {
        const int* bp = m.block_pos.data() + (static_cast<std::size_t>(e) * nf + l) * nf;
        const int stride = m.col_nnz[c[l]];
        for (int cc = 0; cc < 3; ++cc) {  // column 3B + cc of K, rows in the order of k
          double* col = val + cc * stride;
          for (int k = 0; k <= l; ++k) {  // K_kl(i, cc) at i + 3cc
            const double* src = &Ke(9 * l + 3 * cc, k);
            double* dst = col + bp[k];
            for (int i = 0; i < 3; ++i) dst[i] += src[i];
          }
          for (int k = l + 1; k < nf; ++k) {  // K_kl = K_lkᵀ: K_lk(cc, i) at cc + 3i
            const double* src = &Ke(9 * k + cc, l);
            double* dst = col + bp[k];
            for (int i = 0; i < 3; ++i) dst[i] += src[3 * i];
          }
        }
      }
    }
  });
  if (tangent && cache && keep_linear_tangent_) {
    const std::lock_guard<std::mutex> lock(m.linear_mutex);
    m.linear_values.assign(values, values + nnz);
  }
  return r;
}

}  // namespace isoflex::elements
