#include "isoflex/joints/linear_rows.hpp"

#include <stdexcept>
#include <utility>

namespace isoflex::joints {

LinearRows::LinearRows(std::vector<int> nodes, MatX C, VecX Q, std::function<VecX(double)> d)
    : nodes_(std::move(nodes)), C_(std::move(C)), Q_(std::move(Q)), d_(std::move(d)) {
  if (C_.cols() != Q_.size())
    throw std::invalid_argument("LinearRows: C has " + std::to_string(C_.cols()) + " columns for " +
                                std::to_string(Q_.size()) + " coordinates");
  if (!C_.allFinite() || !Q_.allFinite())
    throw std::invalid_argument("LinearRows: C or Q is not finite");
}

VecX LinearRows::prescribed(double t) const {
  if (!d_) return VecX::Zero(C_.rows());
  VecX d = d_(t);
  if (d.size() != C_.rows())
    throw std::runtime_error("LinearRows: d(t) has " + std::to_string(d.size()) + " entries for " +
                             std::to_string(C_.rows()) + " rows");
  if (!d.allFinite())
    throw std::runtime_error("LinearRows: d(t) is not finite at t = " + std::to_string(t));
  return d;
}

}  // namespace isoflex::joints
