#include "isoflex/loads/kl_edge_moment.hpp"

#include <stdexcept>

#include "isoflex/math/skew.hpp"

namespace isoflex::loads {

EdgeMoment::EdgeMoment(const geometry::NurbsSurface& s, PatchEdge edge, const Vec3& axis, double m,
                       TimeFunction factor, int n_points)
    : PatchLoad(std::move(factor)), ncp_(static_cast<int>(s.points.size())), m_(m) {
  if (!(axis.norm() > 0) || !axis.allFinite())
    throw std::invalid_argument("EdgeMoment: the axis must be a non-zero finite vector");
  if (!std::isfinite(m)) throw std::invalid_argument("EdgeMoment: the moment is not finite");
  s.validate();
  e_ = axis.normalized();
  const bool along_v = edge_runs_along_v(edge);
  const geometry::KnotVector& kv = along_v ? s.v : s.u;
  const double fixed = edge_parameter(s, edge);
  const geometry::GaussRule rule =
      geometry::gauss_legendre(n_points > 0 ? n_points : kv.degree() + 1);
  for (const auto& span : geometry::span_elements(kv))
    for (const auto& qp : geometry::span_quadrature(span, rule)) {
      const double xi = along_v ? fixed : qp.xi;
      const double eta = along_v ? qp.xi : fixed;
      const geometry::SurfaceBasis B = geometry::surface_basis(s, xi, eta);
      const int along = along_v ? 2 : 1, across = along_v ? 1 : 2;  // rows R_η / R_ξ
      Vec3 tangent = Vec3::Zero();
      Point p;
      for (int k = 0; k < B.R.cols(); ++k) {
        const int A = B.global_index(s, k);
        tangent += B.R(along, k) * s.points[static_cast<std::size_t>(A)];
        if (B.R(across, k) != 0.0) {
          p.cp.push_back(A);
          p.dR.push_back(B.R(across, k));
        }
      }
      p.ds = qp.weight * tangent.norm();
      points_.push_back(std::move(p));
    }
}

Vec3 EdgeMoment::t_across(const Point& p, const VecX& x) const {
  Vec3 t = Vec3::Zero();
  for (std::size_t k = 0; k < p.cp.size(); ++k) t += p.dR[k] * x.segment<3>(3 * p.cp[k]);
  return t - t.dot(e_) * e_;
}

VecX EdgeMoment::force(const VecX& x) const {
  if (x.size() != 3 * ncp_) throw std::invalid_argument("EdgeMoment::force: wrong size of x");
  VecX f = VecX::Zero(3 * ncp_);
  for (const Point& p : points_) {
    const Vec3 t = t_across(p, x);
    const Vec3 g = (m_ * p.ds / t.squaredNorm()) * e_.cross(t);
    for (std::size_t k = 0; k < p.cp.size(); ++k) f.segment<3>(3 * p.cp[k]) += p.dR[k] * g;
  }
  return f;
}

void EdgeMoment::add_tangent(const VecX& x, double scale, SpMat& K) const {
  if (x.size() != 3 * ncp_ || K.rows() != 3 * ncp_ || K.cols() != 3 * ncp_)
    throw std::invalid_argument("EdgeMoment::add_tangent: wrong sizes");
  const Mat3 P = Mat3::Identity() - e_ * e_.transpose();
  for (const Point& p : points_) {
    const Vec3 t = t_across(p, x);
    const double t2 = t.squaredNorm();
    const Mat3 dg =
        (scale * m_ * p.ds / t2) * (skew(e_) * P - (2.0 / t2) * e_.cross(t) * t.transpose());
    for (std::size_t a = 0; a < p.cp.size(); ++a)
      for (std::size_t b = 0; b < p.cp.size(); ++b) {
        const Mat3 block = (p.dR[a] * p.dR[b]) * dg;
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) K.coeffRef(3 * p.cp[a] + i, 3 * p.cp[b] + j) += block(i, j);
      }
  }
}

}  // namespace isoflex::loads
