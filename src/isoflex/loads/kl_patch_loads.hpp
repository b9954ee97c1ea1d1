#pragma once
// External loads on one NURBS shell patch whose control points are point nodes (the layout of
// elements::KLShellPatch: x ∈ R^{3·ncp}, control point A at x[3A, 3A+3)). Each load is the
// generalized force f_A = ∂W_ext/∂x_A of its external work (IGA-thesis (3.25)–(3.29), discretized
// with the NURBS basis R_A as in (4.18)–(4.22): b_A = ∫ R_A p dA), integrated by Gauss–Legendre
// points per knot span (geometry/quadrature.hpp), and scaled by a load factor λ(t) (a
// TimeFunction of the load parameter t; the default "t" is proportional loading, t ∈ [0, 1]):
//
//   dead pressure       f_A = p ∫ R_A A₁×A₂ dξ dη              (reference normal and area)
//   follower pressure   f_A(x) = p ∫ R_A a₁×a₂ dξ dη,  a_α = Σ_B R_B,α x_B   (current normal
//                       a₃ |a₁×a₂|), tangent ∂f_A/∂x_B = p ∫ R_A (R_B,η [a₁]× − R_B,ξ [a₂]×)
//   area force          f_A = ∫ R_A q |A₁×A₂| dξ dη            (3.25)–(3.26), q per unit
//                       reference area; self-weight q = ρ t g
//   line load           f_A = ∫_edge R_A q |∂_θ S| dθ          (3.27), q per unit reference length
//   point load          f_A = R_A(ξ*, η*) F                     (3.28) with (ξ*, η*) the projection
//                       of the point onto the surface (Rem. 3.7, §4.1.5)
//
// p > 0 pushes along +A₃ = A₁×A₂/|A₁×A₂| (resp. +a₃). All loads but the follower pressure are
// dead: their force is computed once, at construction. The follower tangent is not symmetric in
// general (its skew part is a boundary term that cancels only for closed or fixed boundaries).
#include <Eigen/SparseCore>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "isoflex/geometry/nurbs_surface.hpp"
#include "isoflex/geometry/quadrature.hpp"
#include "isoflex/loads/patch_edge.hpp"
#include "isoflex/loads/time_function.hpp"
#include "isoflex/math/types.hpp"

namespace isoflex::loads {

using SpMat = Eigen::SparseMatrix<double>;

class PatchLoad {
 public:
  explicit PatchLoad(TimeFunction factor) : factor_(std::move(factor)) {}
  virtual ~PatchLoad() = default;
  PatchLoad(const PatchLoad&) = default;
  PatchLoad& operator=(const PatchLoad&) = default;

  // λ(t).
  double factor(double t) const { return factor_(t); }
  // The load at λ = 1 as generalized forces on the control points (3·ncp) at the configuration x.
  virtual VecX force(const VecX& x) const = 0;
  // Whether force() depends on x (then add_tangent is non-trivial and not symmetric).
  virtual bool follower() const { return false; }
  // K += scale · ∂force/∂x at x. K (3ncp × 3ncp) should already hold the entries of every pair of
  // control points sharing an element (KLShellPatch::pattern()); missing entries are inserted.
  virtual void add_tangent(const VecX& x, double scale, SpMat& K) const;

 private:
  TimeFunction factor_;
};

// The loads of one patch.
using PatchLoads = std::vector<std::shared_ptr<const PatchLoad>>;

// Basis data at the Gauss points of a patch, evaluated once (the loads share nothing else).
struct PatchQuadrature {
  struct Point {
    double weight = 0.0;  // Gauss weight × parameter Jacobian (no surface Jacobian)
    std::vector<int> cp;  // global control points of the non-zero functions
    MatX R;               // 3 × cp.size(): R, R_ξ, R_η
  };
  std::vector<Point> points;
  // Gauss points per knot span and direction; ≤ 0 = p + 1 (q + 1).
  static PatchQuadrature build(const geometry::NurbsSurface& s, geometry::QuadratureOrder order);
};

// Uniform pressure p on the reference normal and area (dead).
class DeadPressure : public PatchLoad {
 public:
  DeadPressure(const geometry::NurbsSurface& s, double p,
               TimeFunction factor = TimeFunction(std::string("t")),
               geometry::QuadratureOrder order = {});
  VecX force(const VecX& x) const override;

 private:
  VecX f_;
};

// Uniform pressure p on the current normal and area (follower).
class FollowerPressure : public PatchLoad {
 public:
  FollowerPressure(const geometry::NurbsSurface& s, double p,
                   TimeFunction factor = TimeFunction(std::string("t")),
                   geometry::QuadratureOrder order = {});
  VecX force(const VecX& x) const override;
  bool follower() const override { return true; }
  void add_tangent(const VecX& x, double scale, SpMat& K) const override;

 private:
  int ncp_ = 0;
  double p_ = 0.0;
  PatchQuadrature quad_;
};

// A constant force per unit reference area q (body load (3.25)–(3.26)).
class AreaForce : public PatchLoad {
 public:
  AreaForce(const geometry::NurbsSurface& s, const Vec3& q,
            TimeFunction factor = TimeFunction(std::string("t")),
            geometry::QuadratureOrder order = {});
  VecX force(const VecX& x) const override;

 private:
  VecX f_;
};

// Self-weight: the area force ρ t g. Throws std::invalid_argument for density or thickness < 0.
AreaForce self_weight(const geometry::NurbsSurface& s, double density, double thickness,
                      const Vec3& g, TimeFunction factor = TimeFunction(std::string("t")));

// A constant force per unit reference length q along a patch edge (3.27). n_points: Gauss points
// per knot span along the edge, ≤ 0 = degree + 1.
class LineLoad : public PatchLoad {
 public:
  LineLoad(const geometry::NurbsSurface& s, PatchEdge edge, const Vec3& q,
           TimeFunction factor = TimeFunction(std::string("t")), int n_points = 0);
  VecX force(const VecX& x) const override;
  // ∫_edge |∂_θ S| dθ, the reference length of the edge, by the same rule.
  double edge_length() const { return length_; }

 private:
  VecX f_;
  double length_ = 0.0;
};

// A force F at a physical point of the reference surface (3.28). tolerance: the largest accepted
// distance between the point and the surface; ≤ 0 = 1e-8 × the diagonal of the control points'
// bounding box. Throws std::invalid_argument (with the distance and the tolerance) if the point is
// farther than that from the surface.
class PointLoad : public PatchLoad {
 public:
  PointLoad(const geometry::NurbsSurface& s, const Vec3& point, const Vec3& F,
            TimeFunction factor = TimeFunction(std::string("t")), double tolerance = 0.0);
  // The same at known parameters (ξ*, η*) of the surface (a point projected already).
  PointLoad(const geometry::NurbsSurface& s, double xi, double eta, const Vec3& F,
            TimeFunction factor = TimeFunction(std::string("t")));
  VecX force(const VecX& x) const override;
  double xi() const { return xi_; }
  double eta() const { return eta_; }

 private:
  void distribute(const geometry::NurbsSurface& s, double xi, double eta, const Vec3& F);

  VecX f_;
  double xi_ = 0.0, eta_ = 0.0;
};

}  // namespace isoflex::loads
