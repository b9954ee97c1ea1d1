#pragma once
// Central finite differences for tangent checks: step ∛ε·max(1, |x|), truncation error O(h²).
#include <cmath>
#include <functional>
#include <limits>
#include <random>

#include "isoflex/math/types.hpp"

namespace isoflex::test {

inline double fd_step(double x) {
  return std::cbrt(std::numeric_limits<double>::epsilon()) * std::max(1.0, std::abs(x));
}

// J(:, j) ≈ (f(x + h eⱼ) − f(x − h eⱼ)) / 2h.
inline MatX central_jacobian(const std::function<VecX(const VecX&)>& f, const VecX& x) {
  const VecX f0 = f(x);
  MatX J(f0.size(), x.size());
  for (int j = 0; j < x.size(); ++j) {
    const double h = fd_step(x(j));
    VecX xp = x, xm = x;
    xp(j) += h;
    xm(j) -= h;
    J.col(j) = (f(xp) - f(xm)) / (2.0 * h);
  }
  return J;
}

// Relative difference ‖A − B‖ / max(‖B‖, floor).
inline double rel_diff(const MatX& A, const MatX& B, double floor = 1.0) {
  return (A - B).norm() / std::max(B.norm(), floor);
}

inline VecX random_vector(std::mt19937& g, int n, double scale = 1.0) {
  std::uniform_real_distribution<double> u(-scale, scale);
  VecX v(n);
  for (int i = 0; i < n; ++i) v(i) = u(g);
  return v;
}

inline Mat3 random_rotation(std::mt19937& g);

}  // namespace isoflex::test

#include "isoflex/math/rotation.hpp"
inline isoflex::Mat3 isoflex::test::random_rotation(std::mt19937& g) {
  return rodrigues(random_vector(g, 3, 3.0));
}
