#include "isoflex/joints/triple_continuity_rows.hpp"

#include <stdexcept>
#include <string>
#include <utility>

namespace isoflex::joints {

namespace {

using Row9 = Eigen::Matrix<double, 1, 9>;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using Mat9 = Eigen::Matrix<double, 9, 9>;

struct Legs {
  Vec3 a, b;
};

Legs legs(const Eigen::Ref<const VecX>& q, int k) {
  const Vec3 xa = q.segment<3>(9 * k), xs = q.segment<3>(9 * k + 3), xb = q.segment<3>(9 * k + 6);
  return {xs - xa, xb - xs};
}

// A gradient over the legs (g_a, g_b) as one over the points (x_a, x_s, x_b).
Row9 over_points(const Vec3& ga, const Vec3& gb) {
  Row9 r;
  r << -ga.transpose(), (ga - gb).transpose(), gb.transpose();
  return r;
}

// The kinked row's gradient over the points from ∂Φ/∂π₂ = p2, ∂Φ/∂π₃ = p3 (∂Φ/∂π₁ = 1) and the
// invariants' gradients at legs L: ∇π₁ = (b, a), ∇π₂ = (2a, 0), ∇π₃ = (0, 2b).
Row9 kink_gradient(const Legs& L, double p2, double p3) {
  return over_points(L.b + 2.0 * p2 * L.a, L.a + 2.0 * p3 * L.b);
}

}  // namespace

std::optional<std::array<double, 3>> TripleContinuityRows::straight_rows(const Vec3& xa,
                                                                         const Vec3& xs,
                                                                         const Vec3& xb) {
  const Vec3 a = xs - xa, b = xb - xs;
  const double la = a.norm(), lb = b.norm();
  if (!(a.cross(b).norm() <= straight_tolerance * la * lb && a.dot(b) > 0.0)) return std::nullopt;
  const double c = la / lb;
  return std::array<double, 3>{-1.0, 1.0 + c, -c};
}

TripleContinuityRows::TripleContinuityRows(std::vector<int> nodes, const VecX& X, double scale)
    : nodes_(std::move(nodes)), scale_(scale) {
  if (nodes_.size() % 3 != 0 || X.size() != 3 * static_cast<Eigen::Index>(nodes_.size()))
    throw std::invalid_argument("TripleContinuityRows: " + std::to_string(nodes_.size()) +
                                " nodes and " + std::to_string(X.size()) +
                                " coordinates are not triples of points");
  const int n = static_cast<int>(nodes_.size() / 3);
  for (int k = 0; k < n; ++k) {
    const Legs L = legs(X, k);
    const double la = L.a.norm(), lb = L.b.norm();
    if (!(la > 0.0) || !(lb > 0.0))
      throw std::invalid_argument("TripleContinuityRows: triple " + std::to_string(k) +
                                  " has a leg of zero length");
    Triple t{};
    const auto tied =
        straight_rows(X.segment<3>(9 * k), X.segment<3>(9 * k + 3), X.segment<3>(9 * k + 6));
    t.straight = tied.has_value();
    t.c = t.straight ? -(*tied)[2] : L.a.dot(L.b) / (la * lb);
    t.phi0 = t.straight ? 0.0 : L.a.dot(L.b) - t.c * la * lb;
    t.row = rows_;
    for (int i = 0; i < 3; ++i) t.X[i] = X.segment<3>(9 * k + 3 * i);
    rows_ += t.straight ? 3 : 1;
    kinks_ += t.straight ? 0 : 1;
    triples_.push_back(t);
  }
}

VecX TripleContinuityRows::constraints(CRef q) const {
  VecX phi(rows_);
  for (int k = 0; k < static_cast<int>(triples_.size()); ++k) {
    const Triple& t = triples_[static_cast<std::size_t>(k)];
    if (t.straight) {  // (5.36): −(x_a − X_a) + (1 + c)(x_s − X_s) − c (x_b − X_b)
      phi.segment<3>(t.row) = -(q.segment<3>(9 * k) - t.X[0]) +
                              (1.0 + t.c) * (q.segment<3>(9 * k + 3) - t.X[1]) -
                              t.c * (q.segment<3>(9 * k + 6) - t.X[2]);
      continue;
    }
    const Legs L = legs(q, k);  // (5.37)
    phi(t.row) = L.a.dot(L.b) - t.c * L.a.norm() * L.b.norm() - t.phi0;
  }
  return scale_ * phi;
}

MatX TripleContinuityRows::jacobian(CRef q) const {
  MatX G = MatX::Zero(rows_, 3 * static_cast<Eigen::Index>(nodes_.size()));
  for (int k = 0; k < static_cast<int>(triples_.size()); ++k) {
    const Triple& t = triples_[static_cast<std::size_t>(k)];
    if (t.straight) {
      G.block<3, 3>(t.row, 9 * k) = -Mat3::Identity();
      G.block<3, 3>(t.row, 9 * k + 3) = (1.0 + t.c) * Mat3::Identity();
      G.block<3, 3>(t.row, 9 * k + 6) = -t.c * Mat3::Identity();
      continue;
    }
    const Legs L = legs(q, k);
    const double s2 = L.a.norm(), s3 = L.b.norm();
    G.block<1, 9>(t.row, 9 * k) = kink_gradient(L, -t.c * s3 / (2.0 * s2), -t.c * s2 / (2.0 * s3));
  }
  return scale_ * G;
}

MatX TripleContinuityRows::discrete_jacobian(CRef qa, CRef qb) const {
  MatX G = jacobian(0.5 * (qa + qb));  // the straight rows; the kinked ones replaced
  for (int k = 0; k < static_cast<int>(triples_.size()); ++k) {
    const Triple& t = triples_[static_cast<std::size_t>(k)];
    if (t.straight) continue;
    const Legs A = legs(qa, k), B = legs(qb, k);
    const Legs M{0.5 * (A.a + B.a), 0.5 * (A.b + B.b)};
    const double s2a = A.a.norm(), s2b = B.a.norm(), s3a = A.b.norm(), s3b = B.b.norm();
    const double p2 = -t.c * 0.5 * (s3a + s3b) / (s2a + s2b);
    const double p3 = -t.c * 0.5 * (s2a + s2b) / (s3a + s3b);
    G.block<1, 9>(t.row, 9 * k) = scale_ * kink_gradient(M, p2, p3);
  }
  return G;
}

void TripleContinuityRows::add_constraint_hessian(CRef q, CRef lambda, MatX& H) const {
  // Σ ∂Φ/∂πₖ ∇²πₖ + Σ ∂²Φ/∂πₖ∂πₗ ∇πₖ ∇πₗᵀ over the legs, then to the points by a = x_s − x_a,
  // b = x_b − x_s. The straight rows are linear.
  Eigen::Matrix<double, 6, 9> T = Eigen::Matrix<double, 6, 9>::Zero();
  T.block<3, 3>(0, 0) = -Mat3::Identity();
  T.block<3, 3>(0, 3) = Mat3::Identity();
  T.block<3, 3>(3, 3) = -Mat3::Identity();
  T.block<3, 3>(3, 6) = Mat3::Identity();
  for (int k = 0; k < static_cast<int>(triples_.size()); ++k) {
    const Triple& t = triples_[static_cast<std::size_t>(k)];
    if (t.straight || lambda(t.row) == 0.0) continue;
    const Legs L = legs(q, k);
    const double s2 = L.a.norm(), s3 = L.b.norm(), c = t.c;
    const double p2 = -c * s3 / (2.0 * s2), p3 = -c * s2 / (2.0 * s3);
    const double p22 = c * s3 / (4.0 * s2 * s2 * s2), p33 = c * s2 / (4.0 * s3 * s3 * s3),
                 p23 = -c / (4.0 * s2 * s3);
    Mat6 h = Mat6::Zero();
    h.block<3, 3>(0, 3) = h.block<3, 3>(3, 0) = Mat3::Identity();  // ∇²π₁
    h.block<3, 3>(0, 0) = 2.0 * p2 * Mat3::Identity() + 4.0 * p22 * L.a * L.a.transpose();
    h.block<3, 3>(3, 3) = 2.0 * p3 * Mat3::Identity() + 4.0 * p33 * L.b * L.b.transpose();
    h.block<3, 3>(0, 3) += 4.0 * p23 * L.a * L.b.transpose();
    h.block<3, 3>(3, 0) += 4.0 * p23 * L.b * L.a.transpose();
    const Mat9 hx = T.transpose() * h * T;
    H.block<9, 9>(9 * k, 9 * k) += (scale_ * lambda(t.row)) * hx;
  }
}

}  // namespace isoflex::joints
