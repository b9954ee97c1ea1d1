#include "isoflex/joints/linear_rows.hpp"

#include <stdexcept>
#include <utility>

namespace isoflex::joints {

LinearRows::LinearRows(std::vector<int> nodes, MatX C, VecX Q)
    : nodes_(std::move(nodes)), C_(std::move(C)), Q_(std::move(Q)) {
  if (C_.cols() != Q_.size())
    throw std::invalid_argument("LinearRows: C has " + std::to_string(C_.cols()) + " columns for " +
                                std::to_string(Q_.size()) + " coordinates");
  if (!C_.allFinite() || !Q_.allFinite())
    throw std::invalid_argument("LinearRows: C or Q is not finite");
}

}  // namespace isoflex::joints
