#include "isoflex/elements/element.hpp"

#include <algorithm>

namespace isoflex::elements {

SpMat Element::pattern() const {
  // The size from the mass matrix: the element's stacked coordinates.
  const MatX M = mass();
  return MatX::Ones(M.rows(), M.cols()).sparseView();
}

VecX Element::discrete_gradient_in_pattern(const VecX& qn, const VecX& qn1, double* values) const {
  if (!values) return discrete_gradient(qn, qn1, nullptr);
  MatX K;
  const VecX dv = discrete_gradient(qn, qn1, &K);
  std::copy(K.data(), K.data() + K.size(), values);  // column-major: the dense pattern's order
  return dv;
}

VecX Element::mixed_discrete_gradient_in_pattern(const VecX& qn, const VecX& qn1, const VecX*,
                                                 double* values, VecX* stress_force) const {
  if (stress_force) stress_force->setZero(qn.size());
  return discrete_gradient_in_pattern(qn, qn1, values);
}

VecX Element::gradient_in_pattern(const VecX& q, double* values) const {
  const VecX g = discrete_gradient_in_pattern(q, q, values);
  if (values)
    for (int k = 0, nnz = static_cast<int>(pattern().nonZeros()); k < nnz; ++k) values[k] *= 2.0;
  return g;
}

VecX Element::viscous_force_in_pattern(const VecX& q, const VecX&, double, double, double*) const {
  return VecX::Zero(q.size());
}

VecX Element::strain_dissipation_force_in_pattern(const VecX&, const VecX& qn, const VecX&, double,
                                                  double, double*) const {
  return VecX::Zero(qn.size());
}

VecX Element::mixed_strain_dissipation_force_in_pattern(const VecX& q_prev, const VecX& qn,
                                                        const VecX& qn1, const VecX*, double chi,
                                                        double ratio, double* values,
                                                        VecX* stress_force) const {
  if (stress_force) stress_force->setZero(qn.size());
  return strain_dissipation_force_in_pattern(q_prev, qn, qn1, chi, ratio, values);
}

SpMat Element::sparse_mass() const {
  return mass().sparseView(0.0, 0.0);
}

}  // namespace isoflex::elements
