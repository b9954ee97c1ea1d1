#include <gtest/gtest.h>

#include "isoflex/integrate/energy_momentum.hpp"
#include "isoflex/integrate/step_subdivision.hpp"
#include "isoflex/io/model_reader.hpp"
#include "support/finite_difference.hpp"
#include "support/models.hpp"

using namespace isoflex;
using F = model::Formulation;
using integrate::EnergyMomentumIntegrator;

namespace {
const F kAll[] = {F::constrained, F::nullspace, F::reparametrized};

struct Run {
  std::vector<integrate::Snapshot> snaps;
  VecX q;
  int iterations = 0;
};

Run run(const model::Model& m, int steps) {
  const auto sys = system::System::compile(m);
  EnergyMomentumIntegrator integ(sys, m.solver);
  auto s = integ.initial_state();
  Run r;
  r.snaps.push_back(integ.snapshot(s, {}, {}));
  for (int i = 0; i < steps; ++i) {
    const auto st = integ.step(s);
    r.iterations += st.iterations;
    r.snaps.push_back(integ.snapshot(s, st, {}));
  }
  r.q = s.q;
  return r;
}
}  // namespace

TEST(EnergyMomentum, SystemSizes) {
  const auto top = system::System::compile(test::heavy_top());
  EXPECT_EQ(top.n(), 12);
  EXPECT_EQ(top.m_selected(), 9);
  EXPECT_EQ(top.k(), 3);
  const auto fb = system::System::compile(test::four_bar());
  EXPECT_EQ(fb.n(), 36);
  EXPECT_EQ(fb.redundant_rows().size(), 3u);
  EXPECT_EQ(fb.cut_rank(), 2);
  EXPECT_EQ(fb.cut_rank_qr(), 2);
  EXPECT_EQ(fb.dof(), 1);
  EXPECT_EQ(fb.k(), 3);
  for (F f : kAll) {
    auto m = test::heavy_top(f);
    EnergyMomentumIntegrator integ(top, m.solver);
    EXPECT_EQ(integ.unknowns(), f == F::constrained ? 21 : f == F::nullspace ? 12 : 3);
  }
}

TEST(EnergyMomentum, InitialVelocitiesAreAdmissible) {
  for (auto m : {test::heavy_top(), test::four_bar(), test::free_body_flip()}) {
    const auto sys = system::System::compile(m);
    EXPECT_LT((sys.jacobian(sys.q0()) * sys.v0()).norm(), 1e-12) << m.name;
  }
  EXPECT_LT(system::System::compile(test::heavy_top()).initial_velocity_projection_error(), 1e-13);
}

// Conservative load-free (or gravity-only) runs: energy and the momentum maps of the symmetry
// to round-off over 1000 steps.
TEST(EnergyMomentum, HeavyTopConservesEnergyAndVerticalAngularMomentum) {
  for (F f : kAll) {
    const auto r = run(test::heavy_top(f), 1000);
    const auto& a = r.snaps.front();
    double dE = 0, dLz = 0, phi = 0;
    for (const auto& s : r.snaps) {
      dE = std::max(dE, std::abs(s.total_energy - a.total_energy) / std::abs(a.total_energy));
      dLz = std::max(dLz, std::abs(s.angular_momentum.z() - a.angular_momentum.z()) /
                              a.angular_momentum.norm());
      phi = std::max(phi, s.constraint_violation);
    }
    EXPECT_LT(dE, 1e-10) << model::to_string(f);
    EXPECT_LT(dLz, 1e-10) << model::to_string(f);
    EXPECT_LT(phi, 1e-10) << model::to_string(f);
  }
}

TEST(EnergyMomentum, FreeBodyConservesEnergyAndAllMomenta) {
  for (F f : kAll) {
    const auto r = run(test::free_body_flip(f), 1000);
    const auto& a = r.snaps.front();
    for (const auto& s : r.snaps) {
      ASSERT_LT(std::abs(s.total_energy - a.total_energy) / a.total_energy, 1e-10);
      ASSERT_LT((s.angular_momentum - a.angular_momentum).norm() / a.angular_momentum.norm(),
                1e-10);
      ASSERT_LT((s.linear_momentum - a.linear_momentum).norm() / a.linear_momentum.norm(), 1e-10);
    }
  }
}

TEST(EnergyMomentum, FormulationsAgreeOnHeavyTopAndFourBar) {
  for (auto make : {&test::heavy_top, &test::four_bar}) {
    const VecX ref = run(make(F::constrained), 200).q;
    for (F f : {F::nullspace, F::reparametrized}) {
      const VecX q = run(make(f), 200).q;
      EXPECT_LT((q - ref).lpNorm<Eigen::Infinity>(), 1e-8)
          << make(f).name << " " << model::to_string(f);
    }
  }
}

TEST(EnergyMomentum, FourBarConservesEnergyWithRedundantLoop) {
  for (F f : kAll) {
    const auto r = run(test::four_bar(f), 1000);
    const auto& a = r.snaps.front();
    for (const auto& s : r.snaps) {
      ASSERT_LT(std::abs(s.total_energy - a.total_energy) / std::abs(a.total_energy), 1e-10)
          << model::to_string(f) << " t = " << s.t;
      ASSERT_LT(s.constraint_violation, 1e-10);
    }
  }
}

// The Newton matrix equals the central-difference Jacobian of the residual at the solution of a
// step, for every formulation (the λ-based term in the reduced schemes is exact there).
TEST(EnergyMomentum, NewtonMatrixMatchesFiniteDifferencesAtSolution) {
  for (auto make : {&test::heavy_top, &test::four_bar}) {
    for (F f : kAll) {
      const auto m = make(f);
      const auto sys = system::System::compile(m);
      EnergyMomentumIntegrator integ(sys, m.solver);
      auto s0 = integ.initial_state();
      auto s1 = s0;
      integ.step(s1);
      // Recover the unknowns of the converged step by Newton from the start value.
      VecX x = integ.start_unknowns(s0);
      MatX J;
      for (int it = 0; it < 30; ++it)
        x -= [&] {
          const VecX R = integ.residual(s0, x, &J);
          return VecX(J.fullPivLu().solve(R));
        }();
      const VecX R = integ.residual(s0, x, &J);
      EXPECT_LT(R.lpNorm<Eigen::Infinity>(), 1e-9);
      auto res = [&](const VecX& y) -> VecX { return integ.residual(s0, y, nullptr); };
      const MatX Jfd = test::central_jacobian(res, x);
      EXPECT_LT(test::rel_diff(J, Jfd), 1e-6) << m.name << " " << model::to_string(f);
    }
  }
}

// Second order in Δt: errors against a fine reference shrink by ≈ 4 when Δt halves.
TEST(EnergyMomentum, SecondOrderConvergence) {
  auto at = [](double dt) {
    auto m = test::heavy_top(F::reparametrized);
    m.bodies[0].angular_velocity /= 10.0;
    m.bodies[0].velocity /= 10.0;
    m.solver.dt = dt;
    return run(m, static_cast<int>(std::lround(0.4 / dt))).q;
  };
  const VecX ref = at(0.4 / 1280);
  const double e1 = (at(0.4 / 40) - ref).norm(), e2 = (at(0.4 / 80) - ref).norm(),
               e3 = (at(0.4 / 160) - ref).norm();
  EXPECT_NEAR(std::log2(e1 / e2), 2.0, 0.1);
  EXPECT_NEAR(std::log2(e2 / e3), 2.0, 0.1);
}

// Quadratic convergence of Newton with the analytic tangent (including, in the reduced schemes,
// the λ-term that stands for the derivative of the discrete null space): once the residual is
// small, each iteration roughly squares it (relative to the residual scale).
TEST(EnergyMomentum, NewtonConvergesQuadratically) {
  int checked_total = 0;
  for (auto make : {&test::heavy_top, &test::four_bar}) {
    for (F f : kAll) {
      const auto m = make(f);
      const auto sys = system::System::compile(m);
      EnergyMomentumIntegrator integ(sys, m.solver);
      const auto s0 = integ.initial_state();
      VecX x = integ.start_unknowns(s0);
      MatX J;
      std::vector<double> r;
      for (int it = 0; it < 8; ++it) {
        const VecX R = integ.residual(s0, x, &J);
        r.push_back(R.lpNorm<Eigen::Infinity>());
        x -= J.fullPivLu().solve(R);
      }
      const double scale = r.front();
      int checked = 0;
      for (std::size_t k = 0; k + 1 < r.size(); ++k) {
        const double a = r[k] / scale, b = r[k + 1] / scale;
        if (a < 1e-2 && b > 1e-13) {
          EXPECT_LT(b, 100.0 * a * a) << m.name << " " << model::to_string(f) << " iteration " << k;
          ++checked;
        }
      }
      EXPECT_LT(r.back() / scale, 1e-13) << m.name << " " << model::to_string(f);
      checked_total += checked;
    }
  }
  // Pairs in the window, measured: 5 (e.g. the heavy top's scaled null-space residuals 1, 0.50,
  // 0.026, 9.0e-5, 1.1e-9 give one; its reparametrized ones 1, 0.020, 9.3e-7, 2.1e-14 none).
  EXPECT_GE(checked_total, 5);
}

// The sparse bordered solve of the reduced systems gives the same Newton corrections, hence the
// same trajectory, as the explicit discrete null space.
TEST(EnergyMomentum, BorderedReducedSolveEqualsExplicitNullSpace) {
  for (F f : {F::nullspace, F::reparametrized}) {
    const auto m = test::chain(6, f);
    const auto sys = system::System::compile(m);
    EnergyMomentumIntegrator a(sys, m.solver, integrate::ReducedSolve::explicit_null_space);
    EnergyMomentumIntegrator b(sys, m.solver, integrate::ReducedSolve::bordered);
    EXPECT_FALSE(a.bordered());
    EXPECT_TRUE(b.bordered());
    auto sa = a.initial_state(), sb = b.initial_state();
    for (int i = 0; i < 100; ++i) {
      const auto ia = a.step(sa), ib = b.step(sb);
      ASSERT_LE(std::abs(ia.iterations - ib.iterations), 1) << model::to_string(f) << " step " << i;
    }
    EXPECT_LT((sa.q - sb.q).lpNorm<Eigen::Infinity>(), 1e-11) << model::to_string(f);
    EXPECT_LT((sa.v - sb.v).lpNorm<Eigen::Infinity>(), 1e-9) << model::to_string(f);
    const auto e0 = b.snapshot(b.initial_state(), {}, {}), e1 = b.snapshot(sb, {}, {});
    EXPECT_LT(std::abs(e1.total_energy - e0.total_energy) /
                  std::max(std::abs(e1.kinetic_energy), std::abs(e1.potential_energy)),
              1e-12);
  }
}

// A step whose Newton iteration fails is retried in halves (solver.max_subdivisions): the run
// goes on with the nominal step count and times, and every part conserves energy.
TEST(EnergyMomentum, FailingStepsAreSubdividedWhenAllowed) {
  auto m = test::heavy_top(F::reparametrized);
  m.solver.dt = 0.05;
  m.solver.max_iterations = 3;    // too few for a full step of the fast top
  m.solver.max_subdivisions = 0;  // (the default halves it: 6)
  {
    const auto sys = system::System::compile(m);
    EnergyMomentumIntegrator integ(sys, m.solver);
    auto s = integ.initial_state();
    EXPECT_THROW(integ.step(s), integrate::NewtonFailure);
    EXPECT_EQ(s.step, 0);  // left at the last completed step
    EXPECT_EQ(s.t, 0.0);
  }
  m.solver.max_subdivisions = 6;
  const auto sys = system::System::compile(m);
  EnergyMomentumIntegrator integ(sys, m.solver);
  auto s = integ.initial_state();
  const double E0 = integ.snapshot(s, {}, {}).total_energy;
  int substeps = 0;
  for (int i = 0; i < 4; ++i) substeps += integ.step(s).substeps;
  EXPECT_EQ(s.step, 4);
  EXPECT_NEAR(s.t, 0.2, 1e-15);
  EXPECT_GT(substeps, 4);
  EXPECT_LT(std::abs(integ.snapshot(s, {}, {}).total_energy - E0), 1e-12 * std::abs(E0));
}

// The work of an attempt that failed counts in the step that was then taken in halves: its
// iterations and its abandoned starts (NewtonFailure::spent, step_subdivision.hpp).
TEST(EnergyMomentum, ASubdividedStepCountsTheWorkOfItsFailedAttempt) {
  int calls = 0;
  const auto attempt = [&](double dt) {
    ++calls;
    if (dt > 0.6) throw integrate::NewtonFailure("step 1").spent(7, 3);
    integrate::StepStats st;
    st.iterations = 4;
    st.failed_starts = 1;
    return st;
  };
  const integrate::StepStats st = integrate::subdivided(attempt, 1.0, 2);
  EXPECT_EQ(calls, 3);
  EXPECT_EQ(st.iterations, 7 + 4 + 4);
  EXPECT_EQ(st.failed_starts, 3 + 1 + 1);
  EXPECT_EQ(st.substeps, 2);
}

// The time of step n is n Δt, not a sum of n increments (which drifted to 9.999000000000267
// after 3333 steps of 0.003), with subdivided steps too; the DAE schemes share the step wrapper
// (integrate/step_subdivision.hpp).
TEST(EnergyMomentum, TimeOfStepNIsNTimesDt) {
  auto m = test::free_body_flip(F::reparametrized);
  m.solver.dt = 0.003;
  const auto sys = system::System::compile(m);
  EnergyMomentumIntegrator integ(sys, m.solver);
  auto s = integ.initial_state();
  double sum = 0.0;
  for (int i = 1; i <= 3333; ++i) {
    integ.step(s);
    sum += m.solver.dt;
    ASSERT_EQ(s.t, i * 0.003) << "step " << i;
  }
  EXPECT_NE(sum, s.t);  // what accumulating gave
  auto top = test::heavy_top(F::reparametrized);
  top.solver.dt = 0.05;
  top.solver.max_iterations = 3;  // subdivided steps (FailingStepsAreSubdividedWhenAllowed)
  top.solver.max_subdivisions = 6;
  const auto top_sys = system::System::compile(top);
  EnergyMomentumIntegrator top_integ(top_sys, top.solver);
  auto t = top_integ.initial_state();
  for (int i = 1; i <= 7; ++i) {
    EXPECT_GT(top_integ.step(t).substeps, 1);
    ASSERT_EQ(t.t, i * 0.05);
  }
}

// A reduced step (null space, reparametrized) solves (9) only where 𝖦 = G(q_{n+½}) has full row
// rank. The heavy top with an arm on a universal joint, the arm at rest at t = 0 (its velocities
// projected), Δt = 0.01: at t = 1.27 the null-space Newton converged (residual 8e-15) to a root
// where the arm turned 94° in the step and 𝖦 was singular (smallest singular value 1.5e-17
// against 0.47 elsewhere), and the energy jumped by −0.49 (to 646 at t = 10). Such a root is
// refused now and the step is solved from another start or in halves.
TEST(EnergyMomentum, ReducedRootsWhereTheDiscreteJacobianIsSingularAreRefused) {
  const std::string yaml = R"yaml(
name: top_and_arm
gravity: [0, 0, -9.81]
solver: {dt: 0.01, t_end: 1.4, residual_tolerance: 1e-16, increment_tolerance: 1e-11}
bodies:
  - name: top
    mass: 1.0
    inertia: [0.625, 0.625, 0.25]
    position: [0, 0.5, 0.8660254037844386]
    orientation: [[1, 0, 0], [0, 0.8660254037844386, -0.5], [0, 0.5, 0.8660254037844386]]
    angular_velocity: [0, 25, 43.30127018922193]
  - name: arm
    mass: 0.2
    inertia: [0.004, 0.004, 0.0004]
    position: [0, 0.5, 0.3660254037844386]
joints:
  - {name: tip, type: spherical, body_a: ground, body_b: top, point: [0, 0, 0]}
  - {name: hinge, type: universal, body_a: top, body_b: arm, point_b: [0, 0, 0.25],
     axis: [1, 0, 0], axis2: [0, 1, 0]}
loads:
  - {name: push, body: top, force: ["2*sin(pi*t)*(t<=1)", 0, 0], point_local: [0, 0.5, 0]}
)yaml";
  for (F f : {F::nullspace, F::reparametrized}) {
    auto m = io::read_model_string(yaml, "top_and_arm.yaml");
    m.solver.formulation = f;
    const auto sys = system::System::compile(m);
    EnergyMomentumIntegrator integ(sys, m.solver);
    auto s = integ.initial_state();
    const double E0 = integ.snapshot(s, {}, {}).total_energy;
    for (int i = 0; i < 140; ++i) {
      integ.step(s);
      const double E = integ.snapshot(s, {}, {}).total_energy;
      ASSERT_LT(std::abs(E - E0 - s.external_work), 1e-10 * E0)
          << model::to_string(f) << " t = " << s.t;
    }
  }
}
