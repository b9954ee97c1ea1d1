#include "isoflex/integrate/dae_integrator.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "isoflex/integrate/step_subdivision.hpp"

namespace isoflex::integrate {

using system::SpMat;
using I = model::Integrator;

namespace {

// ‖A‖∞, the largest absolute row sum.
double infinity_norm(const SpMat& A) {
  VecX rows = VecX::Zero(A.rows());
  for (int c = 0; c < A.outerSize(); ++c)
    for (SpMat::InnerIterator it(A, c); it; ++it) rows(it.row()) += std::abs(it.value());
  return rows.size() ? rows.maxCoeff() : 0.0;
}

VecX selected(const VecX& all, const std::vector<int>& rows) {
  VecX out(static_cast<Eigen::Index>(rows.size()));
  for (std::size_t i = 0; i < rows.size(); ++i) out(static_cast<Eigen::Index>(i)) = all(rows[i]);
  return out;
}

void append(system::Triplets& t, const SpMat& A, int r0, int c0, double f) {
  for (int c = 0; c < A.outerSize(); ++c)
    for (SpMat::InnerIterator it(A, c); it; ++it)
      t.emplace_back(r0 + it.row(), c0 + it.col(), f * it.value());
}

}  // namespace

DaeIntegrator::AlphaParameters DaeIntegrator::alpha_parameters(double rho) {
  if (!(rho >= 0.0 && rho <= 1.0))
    throw std::invalid_argument(fmt::format("generalized-α: ρ∞ = {} is outside [0, 1]", rho));
  AlphaParameters p{};
  p.alpha_m = (2.0 * rho - 1.0) / (rho + 1.0);
  p.alpha_f = rho / (rho + 1.0);
  p.gamma = 0.5 - p.alpha_m + p.alpha_f;
  p.beta = 0.25 * (p.gamma + 0.5) * (p.gamma + 0.5);
  return p;
}

DaeIntegrator::DaeIntegrator(const system::System& sys, const model::Solver& settings)
    : sys_(sys), settings_(settings) {
  if (settings.integrator == I::energy_momentum)
    throw std::invalid_argument("DaeIntegrator: energy_momentum is not a DAE scheme");
  alpha_ = alpha_parameters(settings.rho_infinity);
}

State DaeIntegrator::initial_state() const {
  State s;
  s.q = sys_.q0();
  s.v = sys_.v0();
  consistent_start(s);
  return s;
}

void DaeIntegrator::consistent_start(State& s) const {
  const int n = sys_.n(), m = sys_.m_selected();
  const std::vector<int>& rows = sys_.selected_rows();
  VecX f = sys_.static_force(s.q, s.t, nullptr);
  if (sys_.viscous()) f += sys_.viscous_force(s.q, s.v, 0, 0, nullptr);
  const SpMat G = sys_.jacobian(s.q);
  // G q̈ = d̈ − (vᵀ∇²Φᵢ v)ᵢ (exact for the rows at most quadratic and a driven angle alike).
  VecX rhs_c = -sys_.constraint_curvature(s.q, s.v);
  if (sys_.rheonomic()) {
    // d̈(t) = −∂²/∂t² [Φ(q) − d(t)], one-sided and second order (t ≥ 0 only).
    const double h = 1e-2 * settings_.dt;
    const VecX c0 = sys_.constraints(s.q, s.t), c1 = sys_.constraints(s.q, s.t + h),
               c2 = sys_.constraints(s.q, s.t + 2 * h), c3 = sys_.constraints(s.q, s.t + 3 * h);
    rhs_c -= selected((2.0 * c0 - 5.0 * c1 + 4.0 * c2 - c3) / (h * h), rows);
  }
  system::Triplets t;
  append(t, sys_.mass(), 0, 0, 1.0);
  append(t, SpMat(G.transpose()), 0, n, 1.0);
  append(t, G, n, 0, 1.0);
  SpMat A(n + m, n + m);
  A.setFromTriplets(t.begin(), t.end());
  VecX b(n + m);
  b << -f, rhs_c;
  const VecX x = solve::solve(A, b);
  s.a = x.head(n);
  s.aux = s.a;  // a₀ = q̈₀ (2.23)
  s.lambda = x.tail(m);
  s.q_prev.resize(0);
  s.v_prev.resize(0);
}

DaeIntegrator::Prediction DaeIntegrator::predict(const State& s, double h) const {
  Prediction p;
  switch (settings_.integrator) {
    case I::generalized_alpha: {  // Alg. 2.1, lines 1–7
      const AlphaParameters& a = alpha_;
      p.aux = (a.alpha_f * s.a - a.alpha_m * s.aux) / (1.0 - a.alpha_m);
      p.q = s.q + h * s.v + h * h * (0.5 - a.beta) * s.aux + h * h * a.beta * p.aux;
      p.v = s.v + h * (1.0 - a.gamma) * s.aux + h * a.gamma * p.aux;
      p.a = VecX::Zero(s.q.size());
      p.beta_p = (1.0 - a.alpha_m) / (h * h * a.beta * (1.0 - a.alpha_f));  // (2.26)
      p.gamma_p = a.gamma / (h * a.beta);
      return p;
    }
    case I::bdf2:
      if (s.q_prev.size() == s.q.size() && s.last_dt > 0.0) {
        // (2.21) on a variable grid, ω = h/hₙ₋₁ (the halves of a subdivided step):
        // ẋ ≈ [(1 + 2ω)/(1 + ω) xₙ₊₁ − (1 + ω) xₙ + ω²/(1 + ω) xₙ₋₁] / h; ω = 1 gives 3/2, −2, 1/2.
        const double w = h / s.last_dt;
        const double c0 = (1.0 + 2.0 * w) / (1.0 + w), c1 = -(1.0 + w), c2 = w * w / (1.0 + w);
        p.q = s.q + h * s.v;
        p.v = (c0 * p.q + c1 * s.q + c2 * s.q_prev) / h;
        p.a = (c0 * p.v + c1 * s.v + c2 * s.v_prev) / h;
        p.gamma_p = c0 / h;
        p.beta_p = c0 * c0 / (h * h);
        return p;
      }
      [[fallthrough]];
    case I::bdf1:
      p.q = s.q + h * s.v;  // (2.20): v = (q − qₙ)/h, q̈ = (v − vₙ)/h
      p.v = s.v;
      p.a = VecX::Zero(s.q.size());
      p.gamma_p = 1.0 / h;
      p.beta_p = 1.0 / (h * h);
      return p;
    case I::energy_momentum:
      break;
  }
  throw std::logic_error("DaeIntegrator: not a DAE scheme");
}

VecX DaeIntegrator::residual(const Prediction& p, const VecX& q, const VecX& lambda_hat, double t,
                             double c, double sigma, SpMat* S, double* load_norm) const {
  const int n = sys_.n(), m = sys_.m_selected();
  const VecX acc = p.a + p.beta_p * (q - p.q);
  SpMat K;
  VecX f = sys_.static_force(q, t, S ? &K : nullptr, load_norm);
  // Kelvin–Voigt forces f_v(q, q̇) with q̇ = v(q) of the scheme: K_t += ∂f_v/∂q, C_t = ∂f_v/∂q̇
  // times γ′ = ∂q̇/∂q (IGA-thesis (2.27)).
  if (sys_.viscous())
    f += sys_.viscous_force(q, p.v + p.gamma_p * (q - p.q), 1.0, p.gamma_p, S ? &K : nullptr);
  const SpMat G = sys_.jacobian(q);
  VecX R(n + m);
  R.head(n) = c * (sys_.mass() * acc + f) + sigma * (G.transpose() * lambda_hat);
  R.tail(m) = sigma * selected(sys_.constraints(q, t), sys_.selected_rows());
  if (S) {
    system::Triplets tr;
    append(tr, sys_.mass(), 0, 0, c * p.beta_p);
    append(tr, K, 0, 0, c);
    append(tr, sys_.constraint_hessian(q, lambda_hat), 0, 0, sigma);
    append(tr, SpMat(G.transpose()), 0, n, sigma);
    append(tr, G, n, 0, sigma);
    S->resize(n + m, n + m);
    S->setFromTriplets(tr.begin(), tr.end());
    S->makeCompressed();
  }
  return R;
}

void DaeIntegrator::scaling_factors(const Prediction& p, double t, double h, double& c,
                                    double& sigma) const {
  c = 1.0;
  sigma = 1.0;
  if (!settings_.scaling) return;
  // (2.56)–(2.58): force rows × h², constraint rows × σ = ‖M‖∞ + h²‖K_t‖∞ (at q*, D = 0).
  SpMat K;
  sys_.static_force(p.q, t, &K);
  c = h * h;
  sigma = std::max(infinity_norm(sys_.mass()) + h * h * infinity_norm(K), 1e-300);
}

StepStats DaeIntegrator::step(State& s) const {
  if (s.a.size() != s.q.size()) consistent_start(s);
  return whole_step(
      s, [&](double h) { return attempt(s, h); }, settings_.dt, settings_.max_subdivisions);
}

StepStats DaeIntegrator::attempt(State& s, double h) const {
  const int n = sys_.n();
  const Prediction p = predict(s, h);
  const double t1 = s.t + h;
  double c = 1.0, sigma = 1.0;
  scaling_factors(p, t1, h, c, sigma);
  VecX q = p.q;
  VecX lambda_hat = s.lambda * (c / sigma);  // λ = σ λ̂ / c
  // Residual scale: the inertia terms that cancel in the force rows, whose round-off they set.
  const double ref =
      c * std::max(1.0, p.beta_p * (sys_.mass() * s.q).lpNorm<Eigen::Infinity>() +
                            p.gamma_p * (sys_.mass() * s.v).lpNorm<Eigen::Infinity>());
  const double qscale = std::max(1.0, s.q.lpNorm<Eigen::Infinity>());
  double load_norm = 0.0;
  SpMat S;
  NewtonOptions opt;
  opt.max_iterations = settings_.max_iterations;
  opt.residual_tolerance = settings_.residual_tolerance;
  const NewtonOutcome o = newton_loop(
      opt,
      [&](bool matrix) {
        return residual(p, q, lambda_hat, t1, c, sigma, matrix ? &S : nullptr, &load_norm);
      },
      [&] { return std::max(ref, c * load_norm); },
      [&](const VecX& R) {
        const VecX dx = lu_.solve(S, -R);
        q += dx.head(n);
        lambda_hat += dx.tail(dx.size() - n);
        return dx.head(n).lpNorm<Eigen::Infinity>() <= settings_.increment_tolerance * qscale;
      });
  if (!o.converged)
    throw NewtonFailure(fmt::format("step {} (t = {:.6g})", s.step + 1, t1), o,
                        opt.residual_tolerance)
        .spent(o.iterations, 0);
  const VecX acc = p.a + p.beta_p * (q - p.q);
  const VecX v1 = p.v + p.gamma_p * (q - p.q);
  if (sys_.viscous()) {  // the trapezoidal rule of the viscous power f_v·q̇
    const double power0 = sys_.viscous_force(s.q, s.v, 0, 0, nullptr).dot(s.v);
    const double power1 = sys_.viscous_force(q, v1, 0, 0, nullptr).dot(v1);
    s.dissipated += 0.5 * h * (power0 + power1);
  }
  if (!sys_.loads().empty()) {  // the trapezoidal rule of the external power f_ext·q̇
    const double power0 = sys_.external_force(s.q, s.t).dot(s.v);
    const double power1 = sys_.external_force(q, t1).dot(v1);
    s.external_work += 0.5 * h * (power0 + power1);
  }
  if (sys_.rheonomic() && s.lambda.size() == sys_.m_selected()) {
    // The trapezoidal rule of the prescribed motions' power −λ·ḋ, with ḋ·h ≈ d(tₙ₊₁) − d(tₙ).
    const VecX dd = sys_.prescribed(t1) - sys_.prescribed(s.t);
    const VecX lambda1 = lambda_hat * (sigma / c);
    for (int p = 0; p < sys_.m_selected(); ++p)
      s.driver_work -=
          0.5 * (s.lambda(p) + lambda1(p)) * dd(sys_.selected_rows()[static_cast<std::size_t>(p)]);
  }
  sys_.accept(q);
  if (settings_.integrator == I::generalized_alpha)
    s.aux = p.aux + (1.0 - alpha_.alpha_f) / (1.0 - alpha_.alpha_m) * acc;  // Alg. 2.1, line 19
  s.q_prev = s.q;
  s.v_prev = s.v;
  s.v = v1;
  s.q = q;
  s.a = acc;
  s.lambda = lambda_hat * (sigma / c);
  s.t = t1;
  s.last_dt = h;
  return {o.iterations, o.residual, 1};
}

SpMat DaeIntegrator::iteration_matrix(const State& start) const {
  State s = start;
  if (s.a.size() != s.q.size()) consistent_start(s);
  const double h = settings_.dt;
  const Prediction p = predict(s, h);
  double c = 1.0, sigma = 1.0;
  scaling_factors(p, s.t + h, h, c, sigma);
  SpMat S;
  residual(p, p.q, s.lambda * (c / sigma), s.t + h, c, sigma, &S, nullptr);
  return S;
}

}  // namespace isoflex::integrate
