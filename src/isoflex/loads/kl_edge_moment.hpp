#pragma once
// A bending moment per unit reference length m about a fixed axis e, acting on an edge of a
// Kirchhoff–Love shell patch (elements::KLShellPatch layout, x ∈ R^{3·ncp}). A Kirchhoff–Love
// shell has no rotational unknowns, so the moment does work on the rotation of the edge's
// cross-section: with t = ∂x/∂ζ the tangent across the edge (ζ = ξ on u0/u1, η on v0/v1) and
// t⊥ = t − (t·e) e its part normal to e, the cross-section turns about e by θ with
//
//   dθ = (e × t⊥) · dt / |t⊥|²,     W_ext = m ∫_Γ θ dS      (dS: reference length),
//
// so the load is conservative, with the generalized forces and the (symmetric) tangent
//
//   f_A = m ∫_Γ R_A,ζ g(t) dS,   g(t) = (e × t⊥) / |t⊥|²,
//   ∂f_A/∂x_B = m ∫_Γ R_A,ζ R_B,ζ ∂g/∂t dS,   ∂g/∂t = ([e]× P − 2 (e × t⊥) t⊥ᵀ) / |t⊥|²,
//
// P = I − e eᵀ. The moment vector m e keeps its direction (a "dead-axis" moment), which is the
// pure end moment of the rolled-up plate (IGA-thesis §6.4.1.1, (6.14)): the plate curls in the
// plane normal to e and the bending moment is m everywhere. docs/theory/kl-static.md.
#include "isoflex/loads/kl_patch_loads.hpp"

namespace isoflex::loads {

class EdgeMoment : public PatchLoad {
 public:
  // n_points: Gauss points per knot span along the edge, ≤ 0 = degree + 1. Throws
  // std::invalid_argument for a zero axis or a non-finite moment.
  EdgeMoment(const geometry::NurbsSurface& s, PatchEdge edge, const Vec3& axis, double m,
             TimeFunction factor = TimeFunction(std::string("t")), int n_points = 0);
  VecX force(const VecX& x) const override;
  bool follower() const override { return true; }  // depends on x (its tangent is symmetric)
  void add_tangent(const VecX& x, double scale, SpMat& K) const override;

 private:
  struct Point {
    double ds = 0.0;         // Gauss weight × reference length element
    std::vector<int> cp;     // control points with a non-zero R_A,ζ
    std::vector<double> dR;  // R_A,ζ
  };
  Vec3 t_across(const Point& p, const VecX& x) const;

  int ncp_ = 0;
  Vec3 e_ = Vec3::Zero();
  double m_ = 0.0;
  std::vector<Point> points_;
};

}  // namespace isoflex::loads
