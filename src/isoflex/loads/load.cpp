#include "isoflex/loads/load.hpp"

namespace isoflex::loads {

Load::SpMat Load::tangent_pattern(int size) const {
  return MatX::Ones(size, size).sparseView();
}

}  // namespace isoflex::loads
