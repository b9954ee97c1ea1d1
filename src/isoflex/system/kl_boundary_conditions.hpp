#pragma once
// Dirichlet boundary conditions of a Kirchhoff–Love shell patch whose unknowns are the control
// point positions x ∈ R^{3·ncp} (elements::KLShellPatch), turned into LinearConstraints for the
// static Newton solver (static_newton.hpp). docs/theory/kl-static.md §2.
//
// • Homogeneous conditions (IGA-thesis §4.2.3) eliminate control-point components: x_{A,k} =
// X_{A,k}.
//   With open knot vectors the boundary curve depends only on row 0 of the edge, so fixing row 0
//   fixes the edge (pinned / simply supported in those components); fixing rows 0 and 1 also
//   fixes the tangent across the edge, ∂_n c = Σ R_A,n x_A: a clamped edge.
// • A symmetry plane through an edge with unit normal n: the surface continues by reflection, so
//   the displacement component along n is odd and the two components in the plane are even
//   across the edge: n·(x_A − X_A) = 0 on row 0, and the in-plane components of the slope across
//   the edge vanish, t·(u_B − u_A) = 0 for t ⊥ n and each pair (A on row 0, B on row 1 next to
//   it) — with open knot vectors (and weights that are a product of a ξ- and an η-factor, as for
//   surfaces of revolution) the slope across the edge is a positive multiple of u_B − u_A. This
//   keeps the normal displacement and the rotation about the edge fixed, as symmetry demands,
//   and leaves the stretch across the edge free. The row-0 condition eliminates a component if n
//   is a coordinate axis, otherwise it is a multiplier row; the slope conditions are multiplier
//   rows (they link two control points). Rows that act only on eliminated components are
//   dropped, and so are rows that depend on others (where two symmetry edges meet at a corner,
//   the twist ∂²u/∂ξ∂η is fixed twice): an independent subset is selected by full-pivot LU
//   (solve::independent_rows_lu) on the columns the rows touch.
// • A prescribed displacement ū(t, X) of an edge (a moving boundary) is imposed weakly by
//   Lagrange multipliers on the edge (IGA-thesis (3.37)–(3.40), (4.25)–(4.27)):
//       ∫_Γ Φ_j · (u_h − ū) |∂_θ c₀| dθ = 0,   u_h = Σ_A R_A (x_A − X_A),
//   with the multiplier basis Φ_j = R_j|_Γ e_k, j the control points of row 0 (the trace of the
//   displacement space on the edge, the univariate NURBS space of (4.26)). Then G restricted to
//   the edge dofs is the Gram (mass) matrix of that trace basis, symmetric positive definite: the
//   rows are independent, [K Gᵀ; G 0] is non-singular whenever K is positive definite on ker G,
//   and the constraint makes u_h|_Γ the L²(Γ) projection of ū onto the trace space (exact for ū
//   in it). Multipliers in the trace space itself are the stable choice for boundary-fitted
//   constraints; a richer space would have more multipliers than edge dofs (LBB violated). As in
//   (4.26), functions whose control-point component is eliminated, or already
//   owned by an earlier prescribed edge (a shared corner), are dropped, so the rows stay
//   independent.
#include <functional>
#include <string>
#include <vector>

#include "isoflex/geometry/nurbs_surface.hpp"
#include "isoflex/loads/patch_edge.hpp"
#include "isoflex/math/types.hpp"
#include "isoflex/system/linear_constraints.hpp"

namespace isoflex::system {

using loads::PatchEdge;

// Components as a bit mask.
enum Component : unsigned { kCompX = 1u, kCompY = 2u, kCompZ = 4u, kCompXYZ = 7u };

class KLBoundaryConditions {
 public:
  // Throws std::invalid_argument for an invalid surface.
  explicit KLBoundaryConditions(geometry::NurbsSurface reference);

  // Homogeneous: x_{A,k} = X_{A,k} for the components in the mask.
  KLBoundaryConditions& fix_control_point(int cp, unsigned components = kCompXYZ);
  // Rows 0 … rows−1 of the edge (rows = 1: the edge itself).
  KLBoundaryConditions& fix_edge(PatchEdge e, unsigned components = kCompXYZ, int rows = 1);
  // Clamped. All components: the edge (row 0) held and the slope across it keeps its direction,
  // t·(u_B − u_A) = 0 for t ⊥ X_B − X_A (rows 0 and 1 pairwise), its stretch free; fixing rows 0
  // and 1 entirely would also hold the membrane strain across the edge at zero (a first-order
  // error in nonlinear bending). Some components: those components of rows 0 and 1.
  KLBoundaryConditions& clamp_edge(PatchEdge e, unsigned components = kCompXYZ);
  // Symmetry plane with normal n (normalized here) containing the edge. Throws for |n| = 0.
  KLBoundaryConditions& symmetry_edge(PatchEdge e, const Vec3& n);
  // Eliminated, inhomogeneous: x_{A,k} = X_{A,k} + u(t) (k = 0, 1, 2).
  KLBoundaryConditions& prescribe_control_point(int cp, int component,
                                                std::function<double(double)> u);
  // Weak (multiplier) prescribed displacement of an edge, u(t, X) with X the reference point of
  // the edge; only the components in the mask. n_points: Gauss points per knot span, ≤ 0: p + 2.
  KLBoundaryConditions& prescribe_edge(PatchEdge e, std::function<Vec3(double, const Vec3&)> u,
                                       unsigned components = kCompXYZ, int n_points = 0);

  // The eliminated dofs and the multiplier rows.
  LinearConstraints constraints() const;
  const geometry::NurbsSurface& reference() const { return s_; }
  int dofs() const { return 3 * static_cast<int>(s_.points.size()); }

 private:
  struct Fixed {
    int dof;
    std::function<double(double)> value;
  };
  // A homogeneous row Σ c_i (x_i − X_i) = 0 over full dofs i.
  struct LinkRow {
    std::vector<std::pair<int, double>> entries;
    std::string label;
  };
  struct WeakEdge {
    PatchEdge edge;
    std::function<Vec3(double, const Vec3&)> u;
    unsigned components;
    int n_points;
  };
  // Rows t·(u_b − u_a) = 0 for t = t1, t2.
  void add_slope_rows(int a, int b, const Vec3& t1, const Vec3& t2, const std::string& label);

  geometry::NurbsSurface s_;
  std::vector<Fixed> fixed_;
  std::vector<LinkRow> link_rows_;
  std::vector<WeakEdge> weak_;
};

}  // namespace isoflex::system
