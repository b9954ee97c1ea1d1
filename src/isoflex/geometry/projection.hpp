#pragma once
// Point projection onto a NURBS surface (IGA-thesis §4.1.5): the parameters (ξ*, η*) of the
// surface point closest to a given point Q, by Newton's method on the orthogonality conditions
//
//     r(ξ, η) = S(ξ, η) − Q                                       IGA-thesis (4.14)
//     f = r · S_ξ = 0,   g = r · S_η = 0                           IGA-thesis (4.15)
//
// with the Jacobian J = [S_ξ·S_ξ + r·S_ξξ, S_ξ·S_η + r·S_ξη; sym., S_η·S_η + r·S_ηη] and the
// thesis' three stopping criteria: point coincidence |r| ≤ ε₁, zero cosine
// |S_j · r| / (|S_j| |r|) ≤ ε₂ (j = ξ, η), and negligible parameter change
// |Δξ S_ξ + Δη S_η| ≤ ε₁. The parameters are kept in the domain (the thesis' "parameters stay in
// the corresponding range of the knot values") by clamping, with a bound held fixed while the
// distance would decrease beyond it, so points beyond the boundary project onto the boundary
// curve; on a closed surface (first and last rows of control points equal) such a bound is a
// seam and the parameter continues from the other side. Newton starts from the best point of a
// coarse sampling of every element (skipping collapsed edges such as a sphere's pole, where ξ is
// arbitrary); where the full Newton Hessian is not positive definite (far from the surface,
// saddle regions) the step falls back to Gauss–Newton, and a step that increases the distance
// beyond round-off is halved (at most 30 times). Details: docs/theory/nurbs-tools.md §3.
#include "isoflex/geometry/nurbs_surface.hpp"
#include "isoflex/math/types.hpp"

namespace isoflex::geometry {

struct ProjectionOptions {
  // ε₁ (a length). ≤ 0: 1e-13 × the diagonal of the control points' bounding box.
  double eps1 = 0.0;
  double eps2 = 1e-14;  // ε₂ (a cosine)
  int max_iterations = 50;
  // Start search: samples per element and direction (at the element's ends and evenly between).
  // ≤ 0: p + 2 along ξ and q + 2 along η.
  int samples_per_span = 0;
};

enum class ProjectionStop {
  point_coincidence,  // |S − Q| ≤ ε₁
  zero_cosine,        // S − Q orthogonal to both tangents (or a bound holds the parameter)
  parameter_change,   // |Δξ S_ξ + Δη S_η| ≤ ε₁
  max_iterations,     // none of the above within max_iterations
};

struct ProjectionResult {
  double xi = 0.0, eta = 0.0;  // the closest point's parameters, inside the domain
  Vec3 point = Vec3::Zero();   // S(ξ, η)
  double distance = 0.0;       // |S(ξ, η) − Q|
  int iterations = 0;          // Newton iterations (updates of the parameters)
  bool on_surface = false;     // distance ≤ ε₁
  double eps1 = 0.0;           // the ε₁ that was used
  ProjectionStop stop = ProjectionStop::max_iterations;
  bool converged() const { return stop != ProjectionStop::max_iterations; }
};

// Closest point of `s` to `q`, started from the coarse sampling.
ProjectionResult project_point(const NurbsSurface& s, const Vec3& q,
                               const ProjectionOptions& options = {});

// Closest point started from given parameters (clamped to the domain), e.g. the previous
// result when the point moves a little.
ProjectionResult project_point(const NurbsSurface& s, const Vec3& q, double xi0, double eta0,
                               const ProjectionOptions& options = {});

}  // namespace isoflex::geometry
