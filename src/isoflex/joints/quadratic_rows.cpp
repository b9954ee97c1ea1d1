#include "isoflex/joints/quadratic_rows.hpp"

#include <stdexcept>
#include <utility>

namespace isoflex::joints {

QuadraticRows::QuadraticRows(std::vector<int> nodes, std::vector<MatX> H, MatX B, VecX c)
    : nodes_(std::move(nodes)), H_(std::move(H)), B_(std::move(B)), c_(std::move(c)) {
  const Eigen::Index n = B_.cols();
  if (static_cast<Eigen::Index>(H_.size()) != B_.rows() || c_.size() != B_.rows())
    throw std::invalid_argument("QuadraticRows: H, B and c must have one entry per row");
  if (!B_.allFinite() || !c_.allFinite())
    throw std::invalid_argument("QuadraticRows: non-finite B or c");
  for (const MatX& h : H_) {
    if (h.size() == 0) continue;
    if (h.rows() != n || h.cols() != n)
      throw std::invalid_argument("QuadraticRows: H_r must be n × n");
    if (!h.allFinite() || (h - h.transpose()).cwiseAbs().maxCoeff() > 0.0)
      throw std::invalid_argument("QuadraticRows: H_r must be finite and symmetric");
  }
}

VecX QuadraticRows::constraints(CRef q_c) const {
  VecX phi = B_ * q_c + c_;
  for (std::size_t r = 0; r < H_.size(); ++r)
    if (H_[r].size() != 0) phi(static_cast<Eigen::Index>(r)) += 0.5 * q_c.dot(H_[r] * q_c);
  return phi;
}

MatX QuadraticRows::jacobian(CRef q_c) const {
  MatX G = B_;
  for (std::size_t r = 0; r < H_.size(); ++r)
    if (H_[r].size() != 0) G.row(static_cast<Eigen::Index>(r)) += (H_[r] * q_c).transpose();
  return G;
}

void QuadraticRows::add_constraint_hessian(CRef, CRef lambda, MatX& H) const {
  for (std::size_t r = 0; r < H_.size(); ++r)
    if (H_[r].size() != 0) H += lambda(static_cast<Eigen::Index>(r)) * H_[r];
}

}  // namespace isoflex::joints
