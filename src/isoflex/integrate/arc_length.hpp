#pragma once
// The corrector of the arc-length method (Crisfield, "A fast incremental/iterative solution
// procedure that handles snap-through", Comput. Struct. 13 (1981)): in a step from (u_n, λ_n)
// the iterate has the increment (Δu, Δλ); the bordered Newton correction is
// δu = δu_R + δλ δu_λ (static_newton.hpp), and δλ is chosen so that the new increment keeps the
// arc length Δl,
//     ‖Δu + δu_R + δλ δu_λ‖² + w (Δλ + δλ)² = Δl²,   w = ψ² s,
// a quadratic a δλ² + b δλ + c = 0. Of its two roots the one whose increment makes the smaller
// angle with (Δu, Δλ) — the larger w-weighted inner product — keeps the path from turning back.
#include <cmath>
#include <stdexcept>
#include <string>

#include "isoflex/math/types.hpp"

namespace isoflex::integrate {

// Throws std::runtime_error when the quadratic has no real root (the corrector left the
// sphere's reach: the step is retried with a shorter arc).
inline double arc_length_correction(const VecX& du, double dlam, const VecX& du_R, const VecX& du_l,
                                    double w, double dl) {
  const VecX v = du + du_R;
  const double a = du_l.squaredNorm() + w;
  const double b = 2.0 * (du_l.dot(v) + w * dlam);
  const double c = v.squaredNorm() + w * dlam * dlam - dl * dl;
  const double disc = b * b - 4.0 * a * c;
  if (!(a > 0.0) || !(disc >= 0.0))
    throw std::runtime_error("arc length: the corrector has no real root (discriminant " +
                             std::to_string(disc) + ")");
  // Roots without cancellation: q = −(b + sign(b)√disc)/2, r₁ = q/a, r₂ = c/q.
  const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
  const double r1 = q / a;
  const double r2 = q != 0.0 ? c / q : r1;
  const double base = v.dot(du) + w * dlam * dlam;
  const double slope = du_l.dot(du) + w * dlam;
  return base + r1 * slope >= base + r2 * slope ? r1 : r2;
}

}  // namespace isoflex::integrate
