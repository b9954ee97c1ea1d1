#include "isoflex/loads/kl_patch_loads.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <utility>

#include "isoflex/geometry/element_basis.hpp"
#include "isoflex/geometry/projection.hpp"
#include "isoflex/math/skew.hpp"

namespace isoflex::loads {

namespace {

std::string fmt_e(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.3e", v);
  return buf;
}

// Reference tangents A₁, A₂ at a quadrature point.
void reference_tangents(const geometry::NurbsSurface& s, const PatchQuadrature::Point& q, Vec3& A1,
                        Vec3& A2) {
  A1.setZero();
  A2.setZero();
  for (std::size_t k = 0; k < q.cp.size(); ++k) {
    const Vec3& X = s.points[static_cast<std::size_t>(q.cp[k])];
    A1 += q.R(1, static_cast<Eigen::Index>(k)) * X;
    A2 += q.R(2, static_cast<Eigen::Index>(k)) * X;
  }
}

// Current tangents a₁, a₂ at a quadrature point.
void current_tangents(const PatchQuadrature::Point& q, const VecX& x, Vec3& a1, Vec3& a2) {
  a1.setZero();
  a2.setZero();
  for (std::size_t k = 0; k < q.cp.size(); ++k) {
    const auto kk = static_cast<Eigen::Index>(k);
    a1 += q.R(1, kk) * x.segment<3>(3 * q.cp[k]);
    a2 += q.R(2, kk) * x.segment<3>(3 * q.cp[k]);
  }
}

// f_A = ∫ R_A g(A₁, A₂) dξ dη for a constant-in-x integrand g.
template <class Integrand>
VecX integrate_reference(const geometry::NurbsSurface& s, const PatchQuadrature& quad,
                         Integrand&& g) {
  VecX f = VecX::Zero(3 * static_cast<Eigen::Index>(s.points.size()));
  Vec3 A1, A2;
  for (const auto& q : quad.points) {
    reference_tangents(s, q, A1, A2);
    const Vec3 v = q.weight * g(A1, A2);
    for (std::size_t k = 0; k < q.cp.size(); ++k)
      f.segment<3>(3 * q.cp[k]) += q.R(0, static_cast<Eigen::Index>(k)) * v;
  }
  return f;
}

}  // namespace

void PatchLoad::add_tangent(const VecX& /*x*/, double /*scale*/, SpMat& /*K*/) const {}

PatchQuadrature PatchQuadrature::build(const geometry::NurbsSurface& s,
                                       geometry::QuadratureOrder order) {
  s.validate();
  const geometry::GaussRule ru =
      geometry::gauss_legendre(order.n_u > 0 ? order.n_u : s.degree_u() + 1);
  const geometry::GaussRule rv =
      geometry::gauss_legendre(order.n_v > 0 ? order.n_v : s.degree_v() + 1);
  PatchQuadrature out;
  geometry::ElementBasis eb;
  for (const auto& e : geometry::surface_elements(s)) {
    geometry::element_basis(s, e, ru, rv, eb);
    const auto qps = geometry::element_quadrature(e, ru, rv);
    for (int g = 0; g < eb.n_points(); ++g) {
      Point p;
      p.weight = qps[static_cast<std::size_t>(g)].weight;
      p.cp.resize(static_cast<std::size_t>(eb.n_functions));
      for (int k = 0; k < eb.n_functions; ++k)
        p.cp[static_cast<std::size_t>(k)] = eb.global_index(s, k);
      p.R = eb.R(g).topRows(3);
      out.points.push_back(std::move(p));
    }
  }
  return out;
}

// ---------------------------------------------------------------------------------------------

DeadPressure::DeadPressure(const geometry::NurbsSurface& s, double p, TimeFunction factor,
                           geometry::QuadratureOrder order)
    : PatchLoad(std::move(factor)) {
  if (!std::isfinite(p)) throw std::invalid_argument("DeadPressure: pressure is not finite");
  const PatchQuadrature quad = PatchQuadrature::build(s, order);
  // p A₃ dA = p A₁ × A₂ dξ dη.
  f_ = integrate_reference(
      s, quad, [p](const Vec3& A1, const Vec3& A2) -> Vec3 { return p * A1.cross(A2); });
}

VecX DeadPressure::force(const VecX& /*x*/) const {
  return f_;
}

// ---------------------------------------------------------------------------------------------

FollowerPressure::FollowerPressure(const geometry::NurbsSurface& s, double p, TimeFunction factor,
                                   geometry::QuadratureOrder order)
    : PatchLoad(std::move(factor)),
      ncp_(static_cast<int>(s.points.size())),
      p_(p),
      quad_(PatchQuadrature::build(s, order)) {
  if (!std::isfinite(p)) throw std::invalid_argument("FollowerPressure: pressure is not finite");
}

VecX FollowerPressure::force(const VecX& x) const {
  if (x.size() != 3 * ncp_)
    throw std::invalid_argument("FollowerPressure: x has " + std::to_string(x.size()) +
                                " entries, expected " + std::to_string(3 * ncp_));
  VecX f = VecX::Zero(3 * ncp_);
  for (const auto& q : quad_.points) {
    Vec3 a1, a2;
    current_tangents(q, x, a1, a2);
    const Vec3 v = (q.weight * p_) * a1.cross(a2);  // p a₃ |a₁ × a₂|
    for (std::size_t k = 0; k < q.cp.size(); ++k)
      f.segment<3>(3 * q.cp[k]) += q.R(0, static_cast<Eigen::Index>(k)) * v;
  }
  return f;
}

void FollowerPressure::add_tangent(const VecX& x, double scale, SpMat& K) const {
  if (x.size() != 3 * ncp_ || K.rows() != 3 * ncp_ || K.cols() != 3 * ncp_)
    throw std::invalid_argument("FollowerPressure::add_tangent: wrong sizes");
  for (const auto& q : quad_.points) {
    Vec3 a1, a2;
    current_tangents(q, x, a1, a2);
    const Mat3 S1 = skew(a1), S2 = skew(a2);
    const double c = scale * p_ * q.weight;
    // ∂(a₁ × a₂)/∂x_B = R_B,η [a₁]× − R_B,ξ [a₂]×.
    for (std::size_t b = 0; b < q.cp.size(); ++b) {
      const auto bb = static_cast<Eigen::Index>(b);
      const Mat3 D = q.R(2, bb) * S1 - q.R(1, bb) * S2;
      for (std::size_t a = 0; a < q.cp.size(); ++a) {
        const Mat3 block = (c * q.R(0, static_cast<Eigen::Index>(a))) * D;
        const int ra = 3 * q.cp[a], cb = 3 * q.cp[b];
        for (int j = 0; j < 3; ++j)
          for (int i = 0; i < 3; ++i) K.coeffRef(ra + i, cb + j) += block(i, j);
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------

AreaForce::AreaForce(const geometry::NurbsSurface& s, const Vec3& q, TimeFunction factor,
                     geometry::QuadratureOrder order)
    : PatchLoad(std::move(factor)) {
  if (!q.allFinite()) throw std::invalid_argument("AreaForce: force per area is not finite");
  const PatchQuadrature quad = PatchQuadrature::build(s, order);
  f_ = integrate_reference(
      s, quad, [&q](const Vec3& A1, const Vec3& A2) -> Vec3 { return A1.cross(A2).norm() * q; });
}

VecX AreaForce::force(const VecX& /*x*/) const {
  return f_;
}

AreaForce self_weight(const geometry::NurbsSurface& s, double density, double thickness,
                      const Vec3& g, TimeFunction factor) {
  if (!(density >= 0.0) || !(thickness >= 0.0))
    throw std::invalid_argument("self_weight: density " + fmt_e(density) + " and thickness " +
                                fmt_e(thickness) + " must be >= 0");
  return AreaForce(s, density * thickness * g, std::move(factor));
}

// ---------------------------------------------------------------------------------------------

LineLoad::LineLoad(const geometry::NurbsSurface& s, PatchEdge edge, const Vec3& q,
                   TimeFunction factor, int n_points)
    : PatchLoad(std::move(factor)) {
  if (!q.allFinite()) throw std::invalid_argument("LineLoad: force per length is not finite");
  s.validate();
  const bool along_v = edge_runs_along_v(edge);
  const geometry::KnotVector& kv = along_v ? s.v : s.u;
  const double fixed = edge_parameter(s, edge);
  const geometry::GaussRule rule =
      geometry::gauss_legendre(n_points > 0 ? n_points : kv.degree() + 1);
  f_ = VecX::Zero(3 * static_cast<Eigen::Index>(s.points.size()));
  for (const auto& e : geometry::span_elements(kv)) {
    for (const auto& qp : geometry::span_quadrature(e, rule)) {
      const double xi = along_v ? fixed : qp.xi;
      const double eta = along_v ? qp.xi : fixed;
      const geometry::SurfaceBasis B = geometry::surface_basis(s, xi, eta);
      const int nf = static_cast<int>(B.R.cols());
      Vec3 t = Vec3::Zero();
      for (int k = 0; k < nf; ++k)
        t += B.R(along_v ? 2 : 1, k) * s.points[static_cast<std::size_t>(B.global_index(s, k))];
      const double dl = qp.weight * t.norm();  // |∂_θ S| dθ, the ν_α of (3.27)
      length_ += dl;
      for (int k = 0; k < nf; ++k) {
        const double R = B.R(0, k);
        if (R != 0.0) f_.segment<3>(3 * B.global_index(s, k)) += (R * dl) * q;
      }
    }
  }
}

VecX LineLoad::force(const VecX& /*x*/) const {
  return f_;
}

// ---------------------------------------------------------------------------------------------

PointLoad::PointLoad(const geometry::NurbsSurface& s, const Vec3& point, const Vec3& F,
                     TimeFunction factor, double tolerance)
    : PatchLoad(std::move(factor)) {
  if (!point.allFinite() || !F.allFinite())
    throw std::invalid_argument("PointLoad: point or force is not finite");
  s.validate();
  if (!(tolerance > 0.0)) {
    Vec3 lo = s.points.front(), hi = s.points.front();
    for (const Vec3& P : s.points) {
      lo = lo.cwiseMin(P);
      hi = hi.cwiseMax(P);
    }
    tolerance = 1e-8 * std::max((hi - lo).norm(), 1e-300);
  }
  const geometry::ProjectionResult pr = geometry::project_point(s, point);
  if (!(pr.distance <= tolerance))
    throw std::invalid_argument("PointLoad: the point (" + fmt_e(point.x()) + ", " +
                                fmt_e(point.y()) + ", " + fmt_e(point.z()) +
                                ") is not on the surface: distance " + fmt_e(pr.distance) +
                                " > tolerance " + fmt_e(tolerance));
  distribute(s, pr.xi, pr.eta, F);
}

PointLoad::PointLoad(const geometry::NurbsSurface& s, double xi, double eta, const Vec3& F,
                     TimeFunction factor)
    : PatchLoad(std::move(factor)) {
  if (!std::isfinite(xi) || !std::isfinite(eta) || !F.allFinite())
    throw std::invalid_argument("PointLoad: parameters or force not finite");
  s.validate();
  distribute(s, xi, eta, F);
}

void PointLoad::distribute(const geometry::NurbsSurface& s, double xi, double eta, const Vec3& F) {
  xi_ = xi;
  eta_ = eta;
  const geometry::SurfaceBasis B = geometry::surface_basis(s, xi_, eta_);
  f_ = VecX::Zero(3 * static_cast<Eigen::Index>(s.points.size()));
  for (int k = 0; k < static_cast<int>(B.R.cols()); ++k)
    f_.segment<3>(3 * B.global_index(s, k)) += B.R(0, k) * F;
}

VecX PointLoad::force(const VecX& /*x*/) const {
  return f_;
}

}  // namespace isoflex::loads
