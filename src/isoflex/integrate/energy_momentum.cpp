#include "isoflex/integrate/energy_momentum.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "isoflex/elements/invariant_spring_damper.hpp"
#include "isoflex/elements/point_spring_damper.hpp"
#include "isoflex/elements/revolute_spring.hpp"
#include "isoflex/integrate/step_subdivision.hpp"
#include "isoflex/loads/line_actuator.hpp"
#include "isoflex/solve/linear_solver.hpp"
#include "isoflex/system/joint_reactions.hpp"

namespace isoflex::integrate {

using system::SpMat;
using F = model::Formulation;

struct EnergyMomentumIntegrator::StepContext {
  const State* s;
  double dt, t_mid;
  // Loop-closing rows: range W and null space U of (G_cut P_tree)ᵀ at q_n (DNSM-III (12)).
  MatX W, U;
  // The Newton matrices of a step's iteration with the mixed tangent (model::Solver::mixed_tangent;
  // residual() keeps the exact derivative).
  bool mixed = false;
};

namespace {
// Entries of P_tree = P_int E (57) as a pattern: the node's coordinates times the ν-entries on its
// path to its root (the τ of every tree joint above it and the root's free velocities).
long long structural_null_space_entries(const system::System& sys) {
  std::vector<int> parent_joint(sys.node_count(), -1), root_width(sys.node_count(), 0);
  for (std::size_t j = 0; j < sys.joints().size(); ++j)
    if (sys.joints()[j].tree) parent_joint[sys.joints()[j].child] = static_cast<int>(j);
  for (std::size_t r = 0; r < sys.roots().size(); ++r)
    root_width[sys.roots()[r]] = sys.root_widths()[r];
  long long entries = 0;
  for (int i = 0; i < sys.node_count(); ++i) {
    long long width = 0;
    int node = i;
    while (node >= 0 && parent_joint[node] >= 0) {
      const auto& joint = sys.joints()[parent_joint[node]];
      width += joint.joint->freedom_count();
      node = joint.parent;
    }
    if (node >= 0) width += root_width[node];
    entries += sys.coordinate_count(i) * width;
  }
  return entries;
}
}  // namespace

EnergyMomentumIntegrator::EnergyMomentumIntegrator(const system::System& sys,
                                                   const model::Solver& settings, ReducedSolve how)
    : sys_(sys), settings_(settings) {
  set_joint_reactions(true);
  for (const auto& J : sys.joints()) drivers_ = drivers_ || J.driver >= 0 || J.rows->rheonomic();
  const double mean_mass = sys.mass().diagonal().sum() / std::max(1, sys.n());
  constraint_scale_ = (2.0 / settings.dt) * (mean_mass > 0.0 ? mean_mass : 1.0);
  if (settings.formulation == F::reparametrized) {
    abs_mass_ = sys.mass();
    for (int k = 0; k < abs_mass_.outerSize(); ++k)
      for (SpMat::InnerIterator it(abs_mass_, k); it; ++it) it.valueRef() = std::abs(it.value());
  }
  const bool possible = settings.formulation != F::constrained && sys.cut_rows().empty();
  if (settings.formulation == F::reparametrized &&
      (how == ReducedSolve::tree || how == ReducedSolve::automatic)) {
    system::TreeNewtonSolver t(sys);
    if (t.applicable()) tree_.emplace(std::move(t));
  }
  if (how == ReducedSolve::tree && !tree_)
    throw std::invalid_argument(
        "the tree recursion needs the reparametrized formulation on a tree whose elements couple "
        "only tree neighbours");
  // 𝖯 has a block per (node, ancestor joint): few entries for shallow trees (a beam's nodes are
  // roots of their own), O(N²) for a chain. The explicit form wins while 𝖯 stays sparse; counted
  // structurally (not at q₀, where aligned bodies leave entries that are zero only there).
  const auto dense_null_space = [&] {
    return sys.k() >= 48 && structural_null_space_entries(sys) > 20LL * sys.n();
  };
  bordered_ =
      !tree_ && possible &&
      (how == ReducedSolve::bordered || (how == ReducedSolve::automatic && dense_null_space()));
  if (settings.formulation == F::reparametrized && !tree_ && !bordered_ &&
      (how == ReducedSolve::blocks || how == ReducedSolve::automatic) &&
      ReducedNewtonMatrix::applicable(sys) && !sys.viscous() &&
      !(settings.numerical_dissipation > 0.0 && sys.strain_dissipation()))
    blocks_.emplace(sys);
  if (how == ReducedSolve::blocks && !blocks_)
    throw std::invalid_argument(
        "the block assembly needs the reparametrized formulation on a forest without "
        "loop-closing rows");
}

int EnergyMomentumIntegrator::unknowns() const {
  switch (settings_.formulation) {
    case F::constrained:
      return sys_.n() + sys_.m_selected();
    case F::nullspace:
      return sys_.n();
    case F::reparametrized:
      return sys_.k();
  }
  return 0;
}

State EnergyMomentumIntegrator::initial_state() const {
  State s;
  s.q = sys_.q0();
  s.v = sys_.v0();
  return s;
}

EnergyMomentumIntegrator::StepContext EnergyMomentumIntegrator::context(const State& s,
                                                                        double dt) const {
  StepContext c{&s, dt, s.t + 0.5 * dt, {}, {}, false};
  if (settings_.formulation != F::constrained && !sys_.cut_rows().empty()) {
    const MatX Gc = MatX(sys_.jacobian_rows(s.q, sys_.cut_rows()) * sys_.tree_null_space(s.q));
    solve::qr_range_and_null_space(Gc, c.W, c.U);
  }
  return c;
}

VecX EnergyMomentumIntegrator::start_unknowns(const State& s, double dt, Predictor p,
                                              const VecX* q0) const {
  const bool have = s.last_unknowns.size() == unknowns();
  const double ratio = s.last_dt > 0.0 ? dt / s.last_dt : 1.0;
  switch (settings_.formulation) {
    case F::constrained: {
      // λ ≈ λₙ in every predictor.
      VecX x = have ? s.last_unknowns : VecX::Zero(unknowns());
      if (q0)
        x.head(sys_.n()) = *q0;
      else
        x.head(sys_.n()).setZero();
      if (have && p == Predictor::extrapolated) {
        x.head(sys_.n()) += dt * s.v;
        secant_directors(s, ratio, q0, x);
      }
      if (have && p == Predictor::secant)
        x.head(sys_.n()) += ratio * s.last_unknowns.head(sys_.n());
      return x;
    }
    case F::nullspace: {
      const VecX x = q0 ? *q0 : VecX::Zero(sys_.n());
      if (have && p == Predictor::extrapolated) {
        VecX q = x + dt * s.v;
        secant_directors(s, ratio, q0, q);
        return q;
      }
      if (have && p == Predictor::secant) return x + ratio * s.last_unknowns;
      return x;
    }
    case F::reparametrized: {
      VecX u = VecX::Zero(sys_.k());
      if (!have || p == Predictor::at_rest) return u;
      u = ratio * s.last_unknowns;
      if (p == Predictor::extrapolated) sys_.extrapolate_increments(s.q, s.v, dt, u);
      return u;
    }
  }
  return {};
}

// The extrapolation moves a director node's position by Δt vₙ and its director as in the last
// step (NodeType::extrapolate, the same in the reparametrized formulation): vₙ of a director
// carries the period-2 oscillation of the unresolved director modes, the secant does not.
void EnergyMomentumIntegrator::secant_directors(const State& s, double ratio, const VecX* q0,
                                                VecX& x) const {
  for (int i = 0; i < sys_.node_count(); ++i)
    if (sys_.node_kind(i) == NodeKind::director) {
      const int d = sys_.q_offset(i) + 3;
      const Vec3 origin = q0 ? Vec3(q0->segment<3>(d)) : Vec3::Zero();
      x.segment<3>(d) = origin + ratio * s.last_unknowns.segment<3>(d);
    }
}

// With `increment`, also q_{n+1} − qₙ for the step's velocities (9) without subtracting rounded
// coordinates, so that the momenta's round-off scales with the increments, not with the
// distance from the origin (docs/theory/schemes.md §7): the constrained and null-space unknowns
// are the increment itself, the reparametrized free nodes' come from u (System::update).
VecX EnergyMomentumIntegrator::configuration(const StepContext& c, const VecX& x,
                                             VecX* increment) const {
  switch (settings_.formulation) {
    case F::constrained:
      if (increment) *increment = x.head(sys_.n());
      return c.s->q + x.head(sys_.n());
    case F::nullspace:
      if (increment) *increment = x;
      return c.s->q + x;
    case F::reparametrized: {
      if (blocks_)
        if (const VecX* q1 = blocks_->configuration(c.s->q, x, increment)) return *q1;
      VecX q;
      std::vector<Mat3> step;
      sys_.update(c.s->q, x, q, step, increment);
      return q;
    }
  }
  return {};
}

namespace {
void append(system::Triplets& t, const SpMat& A, int r0, int c0) {
  for (int k = 0; k < A.outerSize(); ++k)
    for (SpMat::InnerIterator it(A, k); it; ++it)
      t.emplace_back(r0 + it.row(), c0 + it.col(), it.value());
}
}  // namespace

SpMat EnergyMomentumIntegrator::reduced_stiffness(const VecX& qm, const SpMat& Gm, const VecX& r0,
                                                  const SpMat& Kf, double dt) const {
  // λ̂ from r₀ ≈ −Δt 𝖦ᵀλ (least squares) stands in for the derivative of 𝖯 (see the header).
  // Without constraints (a free KL patch) there is no such term.
  if (Gm.rows() == 0) return (2.0 / dt) * sys_.mass() + dt * Kf;
  const VecX lambda = normal_equations_.solve(Gm, -(Gm * r0) / dt);
  return (2.0 / dt) * sys_.mass() + dt * Kf + (0.5 * dt) * sys_.constraint_hessian(qm, lambda);
}

// The trust region of the reparametrized corrections (docs/theory/schemes.md §6): a correction
// that turns a director or a frame by more than max_rotation_correction is shortened to it. The
// update maps (exp on S² (54), Rodrigues (37)) are injective only below π, and on thin shells
// the linearization is trusted much less far: in the intersecting shells no converged step ever
// had a correction above 0.45 rad, and every start that failed had one (1.4–80 rad within two
// iterations, examples/intersecting_shells/README.md).
double EnergyMomentumIntegrator::rotation_trust_factor(const VecX& dx) const {
  const double limit = settings_.max_rotation_correction;
  if (settings_.formulation != F::reparametrized || !(limit > 0.0)) return 1.0;
  double turn = 0.0;
  for (const int i : sys_.rotation_tree_coordinates()) turn = std::max(turn, std::abs(dx(i)));
  return turn > limit ? limit / turn : 1.0;
}

const VecX& EnergyMomentumIntegrator::correction(const NewtonMatrix& J, const VecX& R,
                                                 bool fresh) const {
  if (J.tree) {
    auto du = tree_->solve(J.qm, J.q1, J.u, J.A, -R);
    if (!du) throw std::logic_error("Newton matrix couples nodes that are not tree neighbours");
    correction_ = std::move(*du);
    return correction_;
  }
  if (J.blocks) {
    minus_residual_ = -R;
    return blocks_->solve(J.A, minus_residual_, fresh);
  }
  if (J.row == 0 && J.col == 0 && J.A.rows() == R.size()) {
    correction_ = newton_lu_.solve(J.A, -R);
    return correction_;
  }
  VecX b = VecX::Zero(J.A.rows());
  b.segment(J.row, R.size()) = -R;
  const int size = settings_.formulation == F::nullspace ? sys_.n() : sys_.k();
  correction_ = solve::solve(J.A, b).segment(J.col, size);
  return correction_;
}

const VecX& EnergyMomentumIntegrator::evaluate(const StepContext& c, const VecX& x,
                                               NewtonMatrix* NJ, bool bordered, bool start) const {
  if (blocks_ && !bordered) {
    // Reparametrized, no loop-closing rows: fixed-pattern block assembly of 𝖯ᵀ K̂ F′.
    if (NJ) NJ->blocks = true;
    return blocks_->evaluate(c.s->q, c.s->v, x, c.dt, c.t_mid, normal_equations_,
                             NJ ? &NJ->A : nullptr, start ? &c.s->lambda : nullptr);
  }
  if (start) have_last_iterate_ = false;
  residual_ = evaluate_assembled(c, x, NJ, bordered);
  return residual_;
}

VecX EnergyMomentumIntegrator::evaluate_assembled(const StepContext& c, const VecX& x,
                                                  NewtonMatrix* NJ, bool bordered) const {
  SpMat* J = NJ ? &NJ->A : nullptr;
  const State& s = *c.s;
  const double dt = c.dt;
  const int n = sys_.n();
  VecX increment;
  const VecX q1 = configuration(c, x, &increment);
  const VecX qm = 0.5 * (s.q + q1);
  const VecX v1 = (2.0 / dt) * increment - s.v;
  SpMat Kf;
  // The mixed integration point Newton iteration (docs/theory/schemes.md §6): the geometric part
  // of Kf with the stresses of the strains linearized at the last iterate (qₙ's at a start), and
  // λ̂ of the reduced matrices from the momentum balance at those stresses, r̂₀. Thin shells'
  // membrane strains are quadratic in rotations that a correction gets wrong by a little: their
  // stresses at the new iterate, 12/h² times the bending ones, are far off where the linearized
  // ones are not (intersecting shells: 2 mm plates).
  const bool mixed = c.mixed && J;
  VecX stress_force;
  VecX f = mixed ? sys_.mixed_discrete_force(s.q, q1, have_last_iterate_ ? &last_iterate_ : nullptr,
                                             c.t_mid, &Kf, stress_force)
                 : sys_.discrete_force(s.q, q1, c.t_mid, J ? &Kf : nullptr);

  // Kelvin–Voigt forces at the midpoint, f_v(q_{n+½}, Δq/Δt): their work f_v·Δq is what the step
  // removes from the energy, exactly (State::dissipated).
  if (sys_.viscous())
    f += sys_.viscous_force(qm, (q1 - s.q) / dt, 0.5, 1.0 / dt, J ? &Kf : nullptr);
  if (dissipating(s))
    f += dissipative_force(s, q1, dt, J ? &Kf : nullptr, mixed ? &stress_force : nullptr);
  if (c.mixed) {
    last_iterate_ = q1;
    have_last_iterate_ = true;
  }
  const VecX r0 = sys_.mass() * (v1 - s.v) + dt * f;
  const VecX r0_hat = mixed ? VecX(r0 + dt * stress_force) : r0;
  // 𝖦 = G̃(qₙ, qₙ₊₁), the discrete derivative of the selected rows: G(q_{n+½}) for rows at most
  // quadratic (DNSM-III (9)–(10)).
  const SpMat Gm = sys_.discrete_jacobian(s.q, q1);
  const int m = sys_.m_selected();
  system::Triplets t;

  if (tree_ && bordered) {
    // 𝖯ᵀ r₀ by a leaves-to-root sweep; the Newton matrix stays factored (TreeNewtonSolver).
    const VecX R = sys_.reduce(qm, r0);
    if (NJ) {
      NJ->A = reduced_stiffness(qm, Gm, r0_hat, Kf, dt);
      NJ->tree = true;
      NJ->qm = qm;
      NJ->q1 = q1;
      NJ->u = x;
    }
    return R;
  }

  if (settings_.formulation == F::constrained) {
    const VecX lambda = x.tail(m);
    VecX R(n + m);
    R.head(n) = r0 + dt * (Gm.transpose() * lambda);
    const VecX phi = sys_.constraints(q1, c.s->t + dt);
    for (int i = 0; i < m; ++i) R(n + i) = phi(sys_.selected_rows()[i]);
    if (J) {
      const SpMat K =
          (2.0 / dt) * sys_.mass() + dt * Kf + (0.5 * dt) * sys_.constraint_hessian(qm, lambda);
      append(t, K, 0, 0);
      append(t, SpMat(dt * SpMat(Gm.transpose())), 0, n);
      append(t, sys_.jacobian(q1), n, 0);
      J->resize(n + m, n + m);
      J->setFromTriplets(t.begin(), t.end());
    }
    return R;
  }

  if (bordered) {
    // 𝖯ᵀ r₀ by a leaves-to-root sweep; Newton matrix in bordered form (header, ReducedSolve).
    const bool ns = settings_.formulation == F::nullspace;
    const int N6 = 6 * sys_.node_count(), k = sys_.k();
    const std::vector<int>& rows = ns ? sys_.selected_rows() : sys_.cut_rows();
    const int mc = static_cast<int>(rows.size());
    VecX R(k + mc);
    R.head(k) = sys_.reduce(qm, r0);
    const VecX phi = sys_.constraints(q1, c.s->t + dt);
    for (int i = 0; i < mc; ++i) R(k + i) = constraint_scale_ * phi(rows[i]);
    if (J) {
      const SpMat K = reduced_stiffness(qm, Gm, r0_hat, Kf, dt);
      SpMat Lm, Bm, Pm;
      sys_.tree_factors(qm, Lm, Bm, Pm);
      const SpMat PmT = Pm.transpose(), LmT = Lm.transpose(), BmT = Bm.transpose();
      if (ns) {
        // [−P_intᵀK̂  (I−𝒜)ᵀ; 0  ℬᵀ; G(q_{n+1})  0] [Δq; y] = [0; −R]
        append(t, SpMat(-(PmT * K)), 0, 0);
        append(t, LmT, 0, n);
        append(t, BmT, N6, n);
        append(t, SpMat(constraint_scale_ * sys_.jacobian(q1)), N6 + k, 0);
        J->resize(N6 + n, N6 + n);
        NJ->row = N6;
        NJ->col = 0;
      } else {
        // [−K̃  (I−𝒜ₘ)ᵀ  0; (I−𝒜₁)  0  −ℬ̃; 0  ℬₘᵀ  0] [w; y; Δu] = [0; 0; −R],
        // K̃ = P_int(q_{n+½})ᵀ K̂ P_int(q_{n+1}).
        SpMat L1, B1, P1;
        sys_.tree_factors(q1, L1, B1, P1);
        append(t, SpMat(-(PmT * (K * P1))), 0, 0);
        append(t, LmT, 0, N6);
        append(t, L1, N6, 0);
        append(t, SpMat(-sys_.update_input_map(s.q, q1, x)), N6, 2 * N6);
        append(t, BmT, 2 * N6, N6);
        J->resize(2 * N6 + k, 2 * N6 + k);
        NJ->row = 2 * N6;
        NJ->col = 2 * N6;
      }
      J->setFromTriplets(t.begin(), t.end());
    }
    return R;
  }

  // Discrete null space 𝖯 = P_tree(q_{n+½}) 𝖯_cut.
  SpMat P = sys_.tree_null_space(qm);
  const bool cuts = !sys_.cut_rows().empty();
  if (cuts) {
    const MatX Gc = MatX(sys_.discrete_jacobian_rows(s.q, q1, sys_.cut_rows()) * P);
    // A locked mechanism (no columns in U) has nothing to project; Eigen's LU of an empty
    // block would bind a null reference.
    MatX Pc = c.U;
    if (c.U.cols() > 0) {
      const MatX GW = Gc * c.W;
      Pc -= c.W * GW.partialPivLu().solve(Gc * c.U);  // (13)
    }
    P = (P * Pc).sparseView();
  }
  const int kred = static_cast<int>(P.cols());
  const std::vector<int>& con_rows =
      settings_.formulation == F::nullspace ? sys_.selected_rows() : sys_.cut_rows();
  const int mc = static_cast<int>(con_rows.size());
  VecX R(kred + mc);
  R.head(kred) = P.transpose() * r0;
  const VecX phi = sys_.constraints(q1, c.s->t + dt);
  for (int i = 0; i < mc; ++i) R(kred + i) = constraint_scale_ * phi(con_rows[i]);
  if (J) {
    const SpMat K = reduced_stiffness(qm, Gm, r0_hat, Kf, dt);
    SpMat dq;  // ∂q_{n+1}/∂x
    if (settings_.formulation == F::nullspace) {
      dq.resize(n, n);
      dq.setIdentity();
    } else {
      dq = sys_.update_derivative(s.q, q1, x);
    }
    append(t, SpMat(SpMat(P.transpose()) * (K * dq)), 0, 0);
    append(t, SpMat(constraint_scale_ * (sys_.jacobian_rows(q1, con_rows) * dq)), kred, 0);
    J->resize(kred + mc, static_cast<int>(dq.cols()));
    J->setFromTriplets(t.begin(), t.end());
  }
  return R;
}

double EnergyMomentumIntegrator::start_residual(const StepContext& c, Predictor p,
                                                bool bordered) const {
  return evaluate(c, start_unknowns(*c.s, c.dt, p), nullptr, bordered, true)
      .lpNorm<Eigen::Infinity>();
}

VecX EnergyMomentumIntegrator::start_unknowns(const State& s) const {
  return start_unknowns(s, settings_.dt, Predictor::extrapolated, &s.q);
}

VecX EnergyMomentumIntegrator::residual(const State& s, const VecX& x, MatX* J) const {
  const StepContext c = context(s, settings_.dt);
  NewtonMatrix Js;
  VecX dx = x;
  if (settings_.formulation != F::reparametrized) dx.head(sys_.n()) -= s.q;
  const VecX R = evaluate(c, dx, J ? &Js : nullptr, false);
  if (J) *J = MatX(Js.A);
  return R;
}

StepStats EnergyMomentumIntegrator::step(State& s) const {
  return whole_step(
      s, [&](double dt) { return attempt(s, dt); }, settings_.dt, settings_.max_subdivisions);
}

// Residual scale: the momentum terms that cancel in r₀, (2/Δt) M qₙ and M vₙ, in the equations the
// residual has, so that the tolerance means the same in any units. The reduced equations 𝖯ᵀ(…) of
// the reparametrized formulation get |𝖯|ᵀ |M| b, b the coordinates with every 3-vector replaced
// by its length in all three places (the round-off of qₙ₊₁ − qₙ is ε|qₙ| in every component,
// also where qₙ has a zero). Before, the full terms with a floor of 1 stood for the reduced ones
// too: a heavy top of 1 mm (its reduced moments 10⁻³ of them) stopped after 1.7 iterations per
// step and drifted 3·10⁻⁸ in energy over 10⁴ steps, where the same top of 1 m drifts 2·10⁻¹³
// (issue #19; tests/integrate/test_newton_scale.cpp).
double EnergyMomentumIntegrator::residual_scale(const State& s, double dt, double full) const {
  double ref = full;
  if (settings_.formulation == F::reparametrized && sys_.k() > 0) {
    const auto lengths = [](const VecX& x) {
      VecX b(x.size());
      for (Eigen::Index i = 0; i + 2 < x.size(); i += 3)
        b.segment<3>(i).setConstant(x.segment<3>(i).norm());
      return b;
    };
    const VecX t = abs_mass_ * ((2.0 / dt) * lengths(s.q) + lengths(s.v));
    // Never looser than the full terms: |𝖯|ᵀ bounds the round-off, but a chain far from the origin
    // (lever arms × positions) would get a bound far above it and stop early. |𝖯|ᵀ t by its
    // upper bound from one leaves-to-root sweep, linear in the number of nodes (the exact sums
    // are O(N²) on a chain of N bodies: bench/chain.md).
    ref = std::min(ref, sys_.abs_tree_null_space_transpose_bound(s.q, t).maxCoeff());
  }
  return ref > 0.0 ? ref : 1.0;
}

StepStats EnergyMomentumIntegrator::attempt(State& s, double dt) const {
  StepContext c = context(s, dt);
  // Only director shells have a mixed tangent (Element::mixed_discrete_gradient_in_pattern): other
  // models keep their iteration, starts included.
  c.mixed = settings_.mixed_tangent && !sys_.shells().empty();
  // The momentum terms of the full equations (9); with a floor of 1 the scale of the check of a
  // reduced root below.
  const double full = (2.0 / c.dt) * (sys_.mass() * s.q).lpNorm<Eigen::Infinity>() +
                      (sys_.mass() * s.v).lpNorm<Eigen::Infinity>();
  const double ref = residual_scale(s, c.dt, full), full_ref = std::max(1.0, full);
  const double qscale = std::max(1.0, s.q.lpNorm<Eigen::Infinity>());
  // Kept across steps: the block path's matrix stays in its fixed pattern (one copy of the
  // pattern per run, not per step).
  NewtonMatrix& J = newton_matrix_;
  J.row = J.col = 0;
  J.tree = J.blocks = false;
  const bool fast = bordered_ || tree_.has_value();
  // Newton from the extrapolation qₙ + Δt vₙ and the secant qₙ + (qₙ − qₙ₋₁), the one the last
  // step converged from first, then from qₙ. The step equations are the same, only the start
  // differs: thin shells have small convergence basins (membrane/bending stiffness 12/h²). The
  // extrapolation is the closer start while the motion is smooth; once the unresolved director
  // modes carry their undamped period-2 oscillation in vₙ, the secant (the mean velocity of the
  // last step) is, and it stays so for many steps. Always starting from the extrapolation cost
  // the intersecting shells 259 failed starts in 500 steps (examples/intersecting_shells).
  const bool have = s.last_unknowns.size() == unknowns();
  std::vector<Predictor> starts{Predictor::at_rest};
  if (have) {
    starts = {static_cast<Predictor>(s.last_start)};
    for (const Predictor p : {Predictor::extrapolated, Predictor::secant, Predictor::at_rest})
      if (p != starts.front()) starts.push_back(p);
  }
  // With the mixed tangent, on the assembled path, the predictor with the smaller residual goes
  // first: two residuals against a failed start's up to max_iterations Newton matrices. The
  // intersecting shells' late steps switch between the extrapolation and the secant
  // (examples/intersecting_shells/README.md: 2 failed starts instead of 3 (reparametrized) and 0
  // instead of 1 (the others); with the exact tangent 32 instead of 3 to t = 6).
  if (have && c.mixed && !(blocks_ && !fast)) {
    const bool secant = start_residual(c, Predictor::secant, fast) <
                        start_residual(c, Predictor::extrapolated, fast);
    starts = {secant ? Predictor::secant : Predictor::extrapolated,
              secant ? Predictor::extrapolated : Predictor::secant, Predictor::at_rest};
  }
  NewtonOptions opt;
  opt.max_iterations = settings_.max_iterations;
  opt.residual_tolerance = settings_.residual_tolerance;
  // Chord corrections once a correction has reduced ‖R‖ 1000-fold, where the block path keeps the
  // factorization: on the slider-crank the third and later corrections of a step (−26 %
  // instructions, callgrind, the same iteration counts; free_body_flip 2.28 → 2.53 iterations per
  // step and −5 %). Elsewhere a chord correction would factorize the old matrix again: the
  // intersecting shells took 8 % more iterations.
  opt.chord_contraction = blocks_ && !fast ? 1e-3 : 0.0;
  // No prediction of the last matrix here: at ~4 iterations per step it fails often enough that
  // the re-evaluation costs more than it saves (+2.0 % instructions on the slider-crank, +0.8 %
  // on kl_free_plate, callgrind; the iterates are the same either way).
  VecX x, lambda;
  StepStats st;
  int spent = 0;
  // Only rows between nodes can lose rank at q_{n+½}: a node's own rows (|d| = 1, dᵢ·dⱼ = δᵢⱼ) stay
  // independent, so a model without others (a free beam) skips the check and its least squares.
  const bool check =
      settings_.formulation != F::constrained && sys_.m_selected() > sys_.internal_rows();
  bool fresh = false;  // J evaluated since the last correction
  for (std::size_t k = 0; k < starts.size(); ++k) {
    x = start_unknowns(s, dt, starts[k]);
    // A start whose residual has grown 10⁶-fold is abandoned for the next one; the last start
    // keeps its max_iterations.
    opt.stop_when_diverging = k + 1 < starts.size();
    const NewtonOutcome o = newton_loop(
        opt,
        [&, start = true](bool matrix) mutable -> const VecX& {
          fresh = fresh || matrix;
          const VecX& R = evaluate(c, x, matrix ? &J : nullptr, fast, start);
          start = false;
          return R;
        },
        [&] { return ref; },
        [&](const VecX& R) {
          const VecX& dx = correction(J, R, fresh);
          fresh = false;
          const double a = rotation_trust_factor(dx);
          x += a * dx;
          // Configuration units for every formulation (positions; u moves material points by
          // about |u| times the size of the system).
          const double size =
              a * (settings_.formulation == F::constrained
                       ? dx.head(sys_.n()).lpNorm<Eigen::Infinity>()
                       : dx.lpNorm<Eigen::Infinity>() *
                             (settings_.formulation == F::reparametrized ? qscale : 1.0));
          return size <= settings_.increment_tolerance * qscale;
        });
    std::string refused;
    if (o.converged && check) {
      // 𝖯ᵀr₀ = 0 implies (9), r₀ = −Δt𝖦ᵀλ, only where 𝖦 = G(q_{n+½}) has full row rank. Where it
      // loses rank, null 𝖦 is larger than range 𝖯, the reduced equations have roots that are no
      // steps of the scheme, and their energy balance fails; Newton can converge to one
      // (docs/theory/schemes.md §7: a top with an arm on a universal joint). Such a root is
      // refused like a start that did not converge.
      double mismatch = 0.0;
      VecX dq;
      const VecX q1 = configuration(c, x, &dq);
      lambda = step_multipliers(s, q1, dq, c.dt, c.t_mid, &mismatch);
      if (!(c.dt * mismatch <= std::max(1e3 * o.residual, 1e-8 * full_ref)))
        refused = fmt::format(
            "Newton converged to a root of the reduced equations that is no step of the scheme "
            "(G(q_n+1/2) rank deficient: |r0 + dt G^T lambda| = {:.3e}, scale {:.3e})",
            c.dt * mismatch, full_ref);
    }
    if (o.converged && refused.empty()) {
      if (have) s.last_start = static_cast<int>(starts[k]);
      st.iterations = o.iterations;
      st.residual = o.residual;
      break;
    }
    if (k + 1 == starts.size()) {
      const std::string where = fmt::format("step {} (t = {:.6g})", s.step + 1, s.t + c.dt);
      // Every start of a failed attempt failed.
      const int all = static_cast<int>(starts.size());
      if (refused.empty())
        throw NewtonFailure(where, o, opt.residual_tolerance).spent(spent + o.iterations, all);
      throw NewtonFailure(where + ": " + refused).spent(spent + o.iterations, all);
    }
    spent += o.iterations;
    ++st.failed_starts;
  }
  st.iterations += spent;
  VecX increment;
  const VecX q1 = configuration(c, x, &increment);
  // Prescribed motions (rheonomic rows Φ(q) = d(t), held at t_{n+1}): the constraint forces
  // G̃ᵀλ add −λ·(d(tₙ₊₁) − d(tₙ)) to the energy in the step, exactly (G̃ Δq = ΔΦ; DNSM-III (9)
  // with a right-hand side): the drivers' work, summed wherever the step's λ is recovered (joint
  // drivers, or reactions written).
  // The block path keeps them in any case: λ̂ of the next step's first Newton matrix
  // (ReducedNewtonMatrix::evaluate).
  if (reactions_ || drivers_ || (check && blocks_ && !fast))
    s.lambda = check ? lambda : step_multipliers(s, q1, increment, c.dt, c.t_mid);
  if (sys_.rheonomic() && s.lambda.size() == sys_.m_selected()) {
    const VecX dd = sys_.prescribed(s.t + c.dt) - sys_.prescribed(s.t);
    for (int p = 0; p < sys_.m_selected(); ++p)
      s.driver_work -= s.lambda(p) * dd(sys_.selected_rows()[static_cast<std::size_t>(p)]);
  }
  s.last_unknowns = x;
  if (settings_.formulation == F::reparametrized)
    sys_.transport_increments(s.q, q1, s.last_unknowns);
  const VecX dq = q1 - s.q;
  // The step's own ratio Δt/Δtₙ: before last_dt becomes this step's length.
  if (dissipating(s)) s.dissipated += dissipative_force(s, q1, c.dt, nullptr).dot(dq);
  s.last_dt = dt;
  if (sys_.viscous())
    s.dissipated += sys_.viscous_force(0.5 * (s.q + q1), dq / c.dt, 0, 0, nullptr).dot(dq);
  if (settings_.numerical_dissipation > 0.0) s.q_prev = s.q;
  if (!sys_.loads().empty())
    s.external_work += sys_.external_force(0.5 * (s.q + q1), c.t_mid).dot(dq);
  sys_.accept(q1);
  s.v = (2.0 / c.dt) * increment - s.v;
  s.q = q1;
  s.t += c.dt;
  return st;
}

bool EnergyMomentumIntegrator::dissipating(const State& s) const {
  return settings_.numerical_dissipation > 0.0 && s.q_prev.size() == s.q.size() && s.last_dt > 0.0;
}

VecX EnergyMomentumIntegrator::dissipative_force(const State& s, const VecX& q1, double dt,
                                                 SpMat* K, VecX* stress_force) const {
  // The strains' second difference over steps of other lengths: ΔEₙ₊₁ − (Δt/Δtₙ) ΔEₙ, zero for
  // strains linear in t.
  const double chi = settings_.numerical_dissipation, ratio = dt / s.last_dt;
  if (stress_force)
    return sys_.mixed_strain_dissipation_force(s.q_prev, s.q, q1,
                                               have_last_iterate_ ? &last_iterate_ : nullptr, chi,
                                               ratio, K, *stress_force);
  return sys_.strain_dissipation_force(s.q_prev, s.q, q1, chi, ratio, K);
}

void EnergyMomentumIntegrator::set_joint_reactions(bool on) {
  reactions_ = on && (!sys_.shell_point_joints().empty() || !sys_.joints().empty());
}

VecX EnergyMomentumIntegrator::step_multipliers(const State& s, const VecX& q1, const VecX& dq,
                                                double dt, double t_mid, double* mismatch) const {
  if (blocks_ && sys_.nary_constraints().empty()) {
    // The block path's fixed patterns of 𝖦 and 𝖦𝖦ᵀ with the kept LDLᵀ (the same least squares
    // without assembling 𝖦 and 𝖦𝖦ᵀ through sparse products every step).
    try {
      VecX lambda;
      double e = 0.0;
      if (blocks_->multipliers(s.q, s.v, q1, dq, dt, t_mid, normal_equations_, lambda, e)) {
        if (mismatch) *mismatch = e;
        return lambda;
      }
    } catch (const std::runtime_error&) {
      if (mismatch) *mismatch = std::numeric_limits<double>::infinity();
      return VecX();  // G rank deficient at the step: no reactions for it (the step stands)
    }
  }
  VecX f = sys_.discrete_force(s.q, q1, t_mid, nullptr);
  // (The viscous forces' velocity as in the residual, evaluate_assembled.)
  if (sys_.viscous()) f += sys_.viscous_force(0.5 * (s.q + q1), (q1 - s.q) / dt, 0, 0, nullptr);
  if (dissipating(s)) f += dissipative_force(s, q1, dt, nullptr);
  const VecX v1 = (2.0 / dt) * dq - s.v;
  const VecX r = (1.0 / dt) * (sys_.mass() * (v1 - s.v)) + f;
  const SpMat G = sys_.discrete_jacobian(s.q, q1);
  try {
    VecX lambda = normal_equations_.solve(G, VecX(-(G * r)));
    if (mismatch) *mismatch = (r + G.transpose() * lambda).lpNorm<Eigen::Infinity>();
    return lambda;
  } catch (const std::runtime_error&) {
    if (mismatch) *mismatch = std::numeric_limits<double>::infinity();
    return VecX();  // G rank deficient at the step: no reactions for it (the step stands)
  }
}

Snapshot EnergyMomentumIntegrator::snapshot(const State& s, const StepStats& st,
                                            const std::vector<std::string>& body_names) const {
  return integrate::snapshot(sys_, s, st, body_names);
}

Snapshot snapshot(const system::System& sys_, const State& s, const StepStats& st,
                  const std::vector<std::string>& body_names) {
  Snapshot out;
  out.step = s.step;
  out.t = s.t;
  out.kinetic_energy = 0.5 * s.v.dot(sys_.mass() * s.v);
  out.potential_energy = sys_.potential(s.q);
  out.total_energy = out.kinetic_energy + out.potential_energy;
  out.dissipated_energy = s.dissipated;
  out.external_work = s.external_work;
  out.driver_work = s.driver_work;
  out.linear_momentum = sys_.linear_momentum(s.v);
  out.angular_momentum = sys_.angular_momentum(s.q, s.v);
  out.constraint_violation = sys_.constraints(s.q, s.t).lpNorm<Eigen::Infinity>();
  out.newton_iterations = st.iterations;
  out.residual = st.residual;
  for (int i = 0; i < sys_.node_count(); ++i) {
    const int o = sys_.q_offset(i);
    BodyPose b;
    b.name = i < static_cast<int>(body_names.size()) ? body_names[i] : std::string();
    b.position = s.q.segment<3>(o);
    b.velocity = s.v.segment<3>(o);
    const NodeType& type = sys_.node_type(i);
    const auto q = sys_.node_q(s.q, i), v = sys_.node_q(s.v, i);
    b.directors = type.frame(q);
    b.angular_velocity = type.angular_velocity(q, v);
    out.bodies.push_back(b);
  }
  for (int b = 0; b < static_cast<int>(sys_.beams().size()); ++b) {
    const auto& beam = sys_.beams()[b];
    for (int e = 0; e < static_cast<int>(beam.elements.size()); ++e) {
      const auto r = beam.elements[e]->stress_resultants(sys_.beam_element_q(s.q, b, e));
      out.beam_elements.push_back(
          {beam.name, e, beam.elements[e]->nodes()[0], beam.elements[e]->nodes()[1], r.n, r.m});
    }
  }
  for (const auto& shell : sys_.shells())
    for (int e = 0; e < static_cast<int>(shell.elements.size()); ++e) {
      const auto* el = shell.elements[e];
      const auto r = el->stress_resultants(Vec<24>(sys_.stacked(s.q, el->nodes())));
      ShellElementValue v{shell.name, e, {}, r.frame, r.n, r.m, r.q};
      for (int a = 0; a < 4; ++a) v.nodes[a] = el->nodes()[a];
      out.shell_elements.push_back(v);
    }
  for (const auto& k : sys_.kl_patches())
    out.kl_patches.push_back(
        {k.name, sys_.stacked(s.q, k.nodes), k.element->shared_patch(), k.element->kinematics()});
  for (const auto& p : sys_.probes()) {
    ProbeValue pv;
    pv.name = p.name;
    pv.position = sys_.probe_point(s.q, p);
    pv.displacement = pv.position - sys_.probe_point(sys_.q0(), p);
    pv.velocity = sys_.probe_point(s.v, p);  // material points are linear in q
    out.probes.push_back(pv);
  }
  if (s.lambda.size() == sys_.m_selected() && sys_.m_selected() > 0)
    for (const auto& r : system::joint_reactions(sys_, s.q, s.lambda))
      out.reactions.push_back(
          {r.joint, r.point, r.force, r.moment, r.force_local, r.moment_local, r.driver});
  for (const auto& sp : sys_.springs()) {
    const auto& e = dynamic_cast<const elements::PointSpringDamper&>(
        *sys_.elements()[static_cast<std::size_t>(sp.element_index)]);
    const VecX q = sys_.stacked(s.q, e.nodes()), v = sys_.stacked(s.v, e.nodes());
    const double z = e.length(q);
    double force = e.force(q, v);
    if (sp.actuator_load >= 0)
      force += dynamic_cast<const loads::LineActuator&>(
                   *sys_.loads()[static_cast<std::size_t>(sp.actuator_load)])
                   .force(s.t);
    out.springs.push_back({sp.name, z, z - e.law().free_length, e.rate(q, v), force});
  }
  // Springs between frames: a joint spring's angle or slide (length: its value, elongation: from
  // the free value), a bushing's six strains as rows NAME.u1 … NAME.theta3; force: the moment or
  // force along each (K e + C ė).
  for (const auto& fs : sys_.frame_springs()) {
    const auto& el = *sys_.elements()[static_cast<std::size_t>(fs.element_index)];
    const VecX q = sys_.stacked(s.q, el.nodes()), v = sys_.stacked(s.v, el.nodes());
    using K = system::FrameSpringInstance::Kind;
    if (fs.kind == K::revolute) {
      const auto& r = dynamic_cast<const elements::RevoluteSpring&>(el);
      const double theta = r.angle(q);
      out.springs.push_back({fs.name, theta, theta - r.free_angle(), r.rate(q, v), r.moment(q, v)});
      continue;
    }
    const auto& b = dynamic_cast<const elements::InvariantSpringDamper&>(el);
    const VecX e = b.strains(q), rate = b.strain_rates(q, v), f = b.forces(q, v);
    if (fs.kind == K::prismatic) {
      out.springs.push_back({fs.name, e(0) + fs.free_value, e(0), rate(0), f(0)});
      continue;
    }
    static constexpr const char* kStrain[6] = {"u1", "u2", "u3", "theta1", "theta2", "theta3"};
    for (int i = 0; i < 6; ++i)
      out.springs.push_back({fs.name + "." + kStrain[i], e(i), e(i), rate(i), f(i)});
  }
  return out;
}

}  // namespace isoflex::integrate
