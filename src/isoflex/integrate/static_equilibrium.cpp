#include "isoflex/integrate/static_equilibrium.hpp"

#include <fmt/format.h>

#include <cmath>

#include "isoflex/integrate/newton_loop.hpp"
#include "isoflex/solve/linear_solver.hpp"

namespace isoflex::integrate {

using system::SpMat;

StaticEquilibrium::StaticEquilibrium(const system::System& sys, const model::Solver& settings)
    : sys_(sys), settings_(settings) {}

State StaticEquilibrium::initial_state() const {
  State s;
  s.q = sys_.q0();
  s.v = VecX::Zero(sys_.n());
  return s;
}

VecX StaticEquilibrium::evaluate(double t, const VecX& x, SpMat* J) const {
  const int n = sys_.n(), m = sys_.m_selected();
  const VecX q = x.head(n), lambda = x.tail(m);
  SpMat K;
  // DV(q, q) − f_ext(q, t) = ∇V(q) − f_ext(q, t); K = ½ (∇²V − ∂f_ext/∂q) (see the header).
  const VecX f = sys_.discrete_force(q, q, t, J ? &K : nullptr);
  const SpMat G = sys_.jacobian(q);
  VecX R(n + m);
  R.head(n) = f + G.transpose() * lambda;  // DNSM-III (9) without M, at q instead of q_{n+½}
  const VecX phi = sys_.constraints(q);
  for (int i = 0; i < m; ++i) R(n + i) = phi(sys_.selected_rows()[i]);
  if (J) {
    const SpMat A = 2.0 * K + sys_.constraint_hessian(lambda);
    system::Triplets tr;
    tr.reserve(A.nonZeros() + 2 * G.nonZeros());
    for (int c = 0; c < A.outerSize(); ++c)
      for (SpMat::InnerIterator it(A, c); it; ++it) tr.emplace_back(it.row(), it.col(), it.value());
    for (int c = 0; c < G.outerSize(); ++c)
      for (SpMat::InnerIterator it(G, c); it; ++it) {
        tr.emplace_back(n + it.row(), it.col(), it.value());
        tr.emplace_back(it.col(), n + it.row(), it.value());
      }
    J->resize(n + m, n + m);
    J->setFromTriplets(tr.begin(), tr.end());
  }
  return R;
}

VecX StaticEquilibrium::residual(double t, const VecX& x, MatX* J) const {
  SpMat Js;
  const VecX R = evaluate(t, x, J ? &Js : nullptr);
  if (J) *J = MatX(Js);
  return R;
}

// A load increment whose Newton iteration fails is retried as two halves from the last
// equilibrium, at most max_subdivisions deep; only the end of the nominal increment is reported.
StepStats StaticEquilibrium::step(State& s) const {
  return whole_step(
      s, [&](double dt) { return attempt(s, dt); }, settings_.dt, settings_.max_subdivisions);
}

StepStats StaticEquilibrium::attempt(State& s, double dt) const {
  const int n = sys_.n(), m = sys_.m_selected();
  const double t = s.t + dt;
  if (settings_.linear) {
    // Geometrically linear: one Newton correction from the unloaded reference (q₀, λ = 0), whose
    // tangent is the small-displacement stiffness; the load enters linearly.
    VecX x = VecX::Zero(n + m);
    x.head(n) = sys_.q0();
    SpMat J;
    const VecX R = evaluate(t, x, &J);
    x -= solve::solve(J, R);
    s.q = x.head(n);
    s.last_unknowns = x.tail(m);
    s.t = t;
    return {1, evaluate(t, x, nullptr).lpNorm<Eigen::Infinity>(), 1};
  }
  VecX x(n + m);
  x.head(n) = s.q;
  x.tail(m) = s.last_unknowns.size() == m ? s.last_unknowns : VecX::Zero(m);
  const double qscale = std::max(1.0, s.q.lpNorm<Eigen::Infinity>());
  SpMat J;
  solve::FixedPatternLU lu;
  // Residual scale: the forces that balance, ‖Gᵀλ‖∞.
  const StepStats st = newton_loop(
      x, settings_, qscale, fmt::format("load step {} (t = {:.6g})", s.step + 1, t),
      [&](const VecX& y, bool matrix) { return evaluate(t, y, matrix ? &J : nullptr); },
      [&](const VecX& R) { return lu.solve(J, -R); },
      [&](const VecX& y) {
        return std::max(
            1.0, (sys_.jacobian(y.head(n)).transpose() * y.tail(m)).lpNorm<Eigen::Infinity>());
      },
      [&](const VecX& dx) { return dx.head(n).lpNorm<Eigen::Infinity>(); });
  s.q = x.head(n);
  s.last_unknowns = x.tail(m);
  s.t = t;
  return st;
}

}  // namespace isoflex::integrate
