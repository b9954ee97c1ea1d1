#include "isoflex/elements/force_law.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "isoflex/geometry/quadrature.hpp"

namespace isoflex::elements {

namespace {

constexpr double kCloseIncrement = 1e-5;  // |Δx| ≤ this × max|x|: the midpoint force

}  // namespace

ForceLaw::ForceLaw(double k) : k_(k) {}

ForceLaw::ForceLaw(const std::string& expression, const std::string& variable)
    : expression_(loads::TimeFunction(expression, variable)) {
  const geometry::GaussRule g = geometry::gauss_legendre(kPoints);  // on [0, 1]:
  for (int i = 0; i < kPoints; ++i) {
    s_[i] = 0.5 * (g.nodes[i] + 1.0);
    w_[i] = 0.5 * g.weights[i];
  }
}

double ForceLaw::force(double x) const {
  return expression_ ? (*expression_)(x) : k_ * x;
}

// Five-point central difference, h = ε^{1/5} max(1, |x|): truncation O(h⁴ N⁽⁵⁾) (exact for
// polynomials up to degree 4), round-off ~ ε |N| / h.
double ForceLaw::derivative(double x) const {
  if (!expression_) return k_;
  const double h = 7e-4 * std::max(1.0, std::abs(x));
  const auto& N = *expression_;
  return (8.0 * (N(x + h) - N(x - h)) - (N(x + 2 * h) - N(x - 2 * h))) / (12.0 * h);
}

double ForceLaw::energy(double x) const {
  if (!expression_) return 0.5 * k_ * x * x;
  double sum = 0.0;
  for (int i = 0; i < kPoints; ++i) sum += w_[i] * (*expression_)(s_[i] * x);
  return x * sum;
}

double ForceLaw::mean(double x0, double x1, double* d_dx1) const {
  if (!expression_) {
    if (d_dx1) *d_dx1 = 0.5 * k_;
    return 0.5 * k_ * (x0 + x1);
  }
  const double dx = x1 - x0;
  if (std::abs(dx) <= kCloseIncrement * std::max(std::abs(x0), std::abs(x1))) {
    const double xm = 0.5 * (x0 + x1);
    if (d_dx1) *d_dx1 = 0.5 * derivative(xm);
    return force(xm);
  }
  const double m = (energy(x1) - energy(x0)) / dx;
  if (d_dx1) *d_dx1 = (force(x1) - m) / dx;
  return m;
}

}  // namespace isoflex::elements
