#pragma once
// AF-D, the continuity constraints across a Kirchhoff–Love patch interface (IGA-thesis §5.2), as
// a Constraint over the stacked triples of control points (x_a, x_s, x_b): x_s on the common
// edge, x_a and x_b its neighbours across it in the two patches; legs a = x_s − x_a,
// b = x_b − x_s. Per triple, from the reference:
// - straight (the patches continue smoothly, a ∥ b): G¹ by (5.36), a = c b with c = |A|/|B|,
//   three linear rows;
// - kinked: the angle (5.37), a·b = |a||b| cos θ₀, one row. It is not quadratic in q, so it is
//   written in the quadratic invariants π₁ = a·b, π₂ = a·a, π₃ = b·b as
//   Φ = π₁ − cos θ₀ √π₂ √π₃, and its discrete derivative is the chain rule over the invariants
//   with the exact difference quotients Δ√π = Δπ/(√π_a + √π_b) and Δ(uv) = v̄ Δu + ū Δv:
//     G̃ = ∇π₁(q_{½}) − cos θ₀ [ s̄₃/(s₂ₐ + s₂ᵦ) ∇π₂(q_{½}) + s̄₂/(s₃ₐ + s₃ᵦ) ∇π₃(q_{½}) ],
//   sₖ = √πₖ, s̄ the mean over q_a, q_b. Then G̃ Δq = ΔΦ exactly (∇πₖ(q_{½}) Δq = Δπₖ, πₖ being
//   quadratic), and the forces G̃ᵀλ are combinations of invariant gradients, so they neither
//   push nor turn the pair (Gonzalez's construction, as for the joints of DNSM-III).
// Every row is multiplied by `scale` (the row scaling of (4.42)/(5.5), chosen by the caller) and
// is 0 exactly at the reference. The remaining length of the legs is free (Remark 5.8: the
// bending strip's rows preserve it as well, AF-D does not).
#include <array>
#include <optional>
#include <vector>

#include "isoflex/joints/constraint.hpp"

namespace isoflex::joints {

class TripleContinuityRows final : public Constraint {
 public:
  // nodes: three per triple (x_a, x_s, x_b); X: their stacked reference positions. Throws
  // std::invalid_argument for a size mismatch or a leg of zero length.
  TripleContinuityRows(std::vector<int> nodes, const VecX& X, double scale = 1.0);

  const std::vector<int>& nodes() const override { return nodes_; }
  int constraint_count() const override { return rows_; }
  VecX constraints(CRef q_c) const override;
  MatX jacobian(CRef q_c) const override;
  void add_constraint_hessian(CRef q_c, CRef lambda, MatX& H) const override;
  MatX discrete_jacobian(CRef q_a, CRef q_b) const override;

  int kinks() const { return kinks_; }
  // A straight triple's coefficients (−1, 1 + c, −c) of its rows (5.36) on (x_a, x_s, x_b), the
  // same for each component; none for a kinked one.
  static std::optional<std::array<double, 3>> straight_rows(const Vec3& xa, const Vec3& xs,
                                                            const Vec3& xb);
  // A triple is straight when the angle between its legs is below this (radians, as a sine).
  static constexpr double straight_tolerance = 1e-8;

 private:
  struct Triple {
    bool straight;
    double c;     // |A|/|B| (straight) or cos θ₀ (kinked)
    double phi0;  // the kinked row's value at the reference (round-off), subtracted
    int row;      // first row
    Vec3 X[3];    // reference positions (straight rows: C (x − X))
  };
  std::vector<int> nodes_;
  std::vector<Triple> triples_;
  double scale_;
  int rows_ = 0, kinks_ = 0;
};

}  // namespace isoflex::joints
