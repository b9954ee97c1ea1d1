#include "isoflex/geometry/projection.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "isoflex/geometry/quadrature.hpp"

namespace isoflex::geometry {

namespace {

using Mat2 = Mat<2, 2>;
using Vec2 = Vec<2>;

double effective_eps1(const NurbsSurface& s, const ProjectionOptions& o) {
  if (o.eps1 > 0.0) return o.eps1;
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = -lo;
  for (const Vec3& p : s.points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double diag = s.points.empty() ? 0.0 : (hi - lo).norm();
  return 1e-13 * (diag > 0.0 ? diag : 1.0);
}

// Whether the edges ξ = front and ξ = back (along_u) — or η = front and η = back — are the same
// curve: the first and last rows of control points and weights coincide (open knot vectors
// interpolate them), as on the seam of a full cylinder or sphere.
bool closed(const NurbsSurface& s, bool along_u, double tol) {
  const KnotVector& kv = along_u ? s.u : s.v;
  if (!kv.is_open()) return false;
  const int n = along_u ? s.n_u() : s.n_v(), m = along_u ? s.n_v() : s.n_u();
  for (int j = 0; j < m; ++j) {
    const int a = along_u ? s.index(0, j) : s.index(j, 0);
    const int b = along_u ? s.index(n - 1, j) : s.index(j, n - 1);
    if (!((s.points[a] - s.points[b]).norm() <= tol) ||
        !(std::abs(s.weights[a] - s.weights[b]) <= 1e-14 * s.weights[a]))
      return false;
  }
  return true;
}

bool positive_definite(const Mat2& A) {
  const double det = A(0, 0) * A(1, 1) - A(0, 1) * A(1, 0);
  return A(0, 0) > 0.0 && A(1, 1) > 0.0 && det > 1e-14 * std::abs(A(0, 0) * A(1, 1));
}

// Newton step J δ = κ (IGA-thesis, Newton on (4.15)) for the free parameters; a parameter held
// by a bound keeps δ = 0. Where J is not positive definite the step would not decrease the
// distance (it heads for a saddle or a farthest point), so the Gauss–Newton matrix
// [S_i · S_j] (J without the curvature terms r · S_ij) is used instead, and where that is
// singular too (degenerate tangents) a scaled gradient step.
Vec2 newton_step(const Mat2& J, const Mat2& JGN, const Vec2& kappa, bool fix_u, bool fix_v) {
  Vec2 d = Vec2::Zero();
  if (fix_u && fix_v) return d;
  if (fix_u || fix_v) {
    const int a = fix_u ? 1 : 0;
    const double h = J(a, a) > 0.0 ? J(a, a) : JGN(a, a);
    if (h > 0.0) d(a) = kappa(a) / h;
    return d;
  }
  if (positive_definite(J)) return J.inverse() * kappa;
  if (positive_definite(JGN)) return JGN.inverse() * kappa;
  const double tr = JGN.trace();
  return tr > 0.0 ? Vec2(kappa / tr) : d;
}

ProjectionResult newton(const NurbsSurface& s, const Vec3& q, double xi, double eta,
                        const ProjectionOptions& o) {
  const double eps1 = effective_eps1(s, o);
  const double u_lo = s.u.front(), u_hi = s.u.back();
  const double v_lo = s.v.front(), v_hi = s.v.back();
  xi = std::clamp(xi, u_lo, u_hi);
  eta = std::clamp(eta, v_lo, v_hi);

  // On a closed surface a bound is a seam, not an edge: a parameter held there continues from
  // the other side (a few times at most, so that a non-smooth seam cannot make it oscillate).
  const bool closed_u = closed(s, true, eps1), closed_v = closed(s, false, eps1);
  int wraps = 0;

  SurfacePoint S = evaluate(s, xi, eta);
  Vec3 r = S.x - q;  // IGA-thesis (4.14)
  double d = r.norm();
  ProjectionResult res;
  int it = 0;
  for (;;) {
    // Criterion 1: the points coincide.
    if (d <= eps1) {
      res.stop = ProjectionStop::point_coincidence;
      break;
    }
    const double f = r.dot(S.xu), g = r.dot(S.xv);  // IGA-thesis (4.15)
    // A parameter on a bound is held there while the distance would still decrease beyond it
    // (−f is the descent direction of ½|r|² in ξ).
    const bool fix_u = (xi <= u_lo && f > 0.0) || (xi >= u_hi && f < 0.0);
    const bool fix_v = (eta <= v_lo && g > 0.0) || (eta >= v_hi && g < 0.0);
    if ((fix_u && closed_u) || (fix_v && closed_v)) {
      if (wraps < 4) {
        ++wraps;
        if (fix_u && closed_u) xi = xi <= u_lo ? u_hi : u_lo;
        if (fix_v && closed_v) eta = eta <= v_lo ? v_hi : v_lo;
        S = evaluate(s, xi, eta);
        r = S.x - q;
        d = r.norm();
        continue;
      }
    }
    // Criterion 2: zero cosine between r and each free tangent. A vanishing tangent (a
    // degenerate edge such as a pole) gives no condition.
    const auto orthogonal = [&](const Vec3& t, double h) {
      return std::abs(h) <= o.eps2 * t.norm() * d;
    };
    if ((fix_u || orthogonal(S.xu, f)) && (fix_v || orthogonal(S.xv, g))) {
      res.stop = ProjectionStop::zero_cosine;
      break;
    }
    if (it >= o.max_iterations) {
      res.stop = ProjectionStop::max_iterations;
      break;
    }
    Mat2 JGN;
    JGN << S.xu.squaredNorm(), S.xu.dot(S.xv), S.xu.dot(S.xv), S.xv.squaredNorm();
    Mat2 J = JGN;
    J(0, 0) += r.dot(S.xuu);
    J(0, 1) += r.dot(S.xuv);
    J(1, 0) += r.dot(S.xuv);
    J(1, 1) += r.dot(S.xvv);
    const Vec2 delta = newton_step(J, JGN, Vec2(-f, -g), fix_u, fix_v);

    // Clamp into the domain; halve a step that increases the distance.
    // The comparison allows for round-off in |r|: near the solution the distance changes only at
    // second order in the parameter error, below its own round-off, and refusing such steps
    // would stop Newton at a parameter error of ~√ε.
    const double noise = 1e-14 * (q.norm() + d);
    double scale = 1.0;
    double xi_new = xi, eta_new = eta;
    SurfacePoint S_new;
    Vec3 r_new;
    double d_new = d;
    bool decreased = false;
    for (int ls = 0; ls <= 30; ++ls, scale *= 0.5) {
      xi_new = std::clamp(xi + scale * delta(0), u_lo, u_hi);
      eta_new = std::clamp(eta + scale * delta(1), v_lo, v_hi);
      S_new = evaluate(s, xi_new, eta_new);
      r_new = S_new.x - q;
      d_new = r_new.norm();
      if (d_new <= d + noise) {
        decreased = true;
        break;
      }
    }
    ++it;
    if (!decreased) {
      // No step along δ reduces the distance: we are at the minimum to round-off.
      res.stop = ProjectionStop::parameter_change;
      break;
    }
    // Criterion 3 uses the tangents at the old parameters, as in the thesis.
    const double change = ((xi_new - xi) * S.xu + (eta_new - eta) * S.xv).norm();
    xi = xi_new;
    eta = eta_new;
    S = S_new;
    r = r_new;
    d = d_new;
    if (change <= eps1) {
      res.stop = ProjectionStop::parameter_change;
      break;
    }
  }
  res.xi = xi;
  res.eta = eta;
  res.point = S.x;
  res.distance = d;
  res.iterations = it;
  res.eps1 = eps1;
  res.on_surface = d <= eps1;
  return res;
}

}  // namespace

ProjectionResult project_point(const NurbsSurface& s, const Vec3& q, double xi0, double eta0,
                               const ProjectionOptions& options) {
  return newton(s, q, xi0, eta0, options);
}

ProjectionResult project_point(const NurbsSurface& s, const Vec3& q,
                               const ProjectionOptions& options) {
  // Start: the closest of a k_u × k_v grid in every element (ends included, so a closest point
  // on the boundary or at a kink between elements is sampled too). Samples where a tangent
  // vanishes — a collapsed edge such as the pole of a sphere — are used only if no regular sample
  // exists: there every ξ gives the same point, the arbitrary ξ of the sample has nothing to do
  // with Q, and the zero-cosine test is void in that direction; from a regular sample Newton
  // still reaches the pole when it is the answer.
  const int ku = options.samples_per_span > 0 ? options.samples_per_span : s.u.degree() + 2;
  const int kv = options.samples_per_span > 0 ? options.samples_per_span : s.v.degree() + 2;
  double best = std::numeric_limits<double>::infinity(), best_degenerate = best;
  double xi0 = s.u.front(), eta0 = s.v.front(), xi_d = xi0, eta_d = eta0;
  for (const SurfaceElement& e : surface_elements(s)) {
    for (int j = 0; j < kv; ++j) {
      const double tv = kv > 1 ? static_cast<double>(j) / (kv - 1) : 0.5;
      const double eta = e.v0 + tv * (e.v1 - e.v0);
      for (int i = 0; i < ku; ++i) {
        const double tu = ku > 1 ? static_cast<double>(i) / (ku - 1) : 0.5;
        const double xi = e.u0 + tu * (e.u1 - e.u0);
        const SurfacePoint sp = evaluate(s, xi, eta);
        const double dist = (sp.x - q).squaredNorm();
        const double nu = sp.xu.norm(), nv = sp.xv.norm();
        const bool degenerate = !(std::min(nu, nv) > 1e-10 * (nu + nv));
        if (degenerate) {
          if (dist < best_degenerate) {
            best_degenerate = dist;
            xi_d = xi;
            eta_d = eta;
          }
        } else if (dist < best) {
          best = dist;
          xi0 = xi;
          eta0 = eta;
        }
      }
    }
  }
  if (best == std::numeric_limits<double>::infinity()) {
    xi0 = xi_d;
    eta0 = eta_d;
  }
  return newton(s, q, xi0, eta0, options);
}

}  // namespace isoflex::geometry
