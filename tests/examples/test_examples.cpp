// Every example model, read from its file and integrated: conservation to round-off, constraint
// satisfaction, system sizes, and agreement of the three formulations.
#include <gtest/gtest.h>

#include "isoflex/integrate/energy_momentum.hpp"
#include "isoflex/io/model_reader.hpp"

using namespace isoflex;
using F = model::Formulation;

namespace {
model::Model example(const std::string& name, F f) {
  auto m = io::read_model(std::string(ISOFLEX_SOURCE_DIR) + "/examples/" + name + "/model.yaml");
  m.solver.formulation = f;
  return m;
}

struct Drift {
  double energy = 0, Lz = 0, L = 0, p = 0, phi = 0;
  VecX q;
};

// Relative drifts over `steps` steps; energy relative to the largest of |E₀|, T and |V| seen,
// angular momentum relative to the largest Σ |q_k| |(M v)_k| seen (its round-off scale).
Drift run(const model::Model& m, int steps) {
  const auto sys = system::System::compile(m);
  integrate::EnergyMomentumIntegrator integ(sys, m.solver);
  auto s = integ.initial_state();
  const auto a = integ.snapshot(s, {}, {});
  std::vector<integrate::Snapshot> snaps{a};
  double scale = std::abs(a.total_energy), Ls = a.angular_momentum.norm(),
         ps = a.linear_momentum.norm();
  for (int i = 0; i < steps; ++i) {
    const auto st = integ.step(s);
    snaps.push_back(integ.snapshot(s, st, {}));
    scale = std::max({scale, snaps.back().kinetic_energy, std::abs(snaps.back().potential_energy)});
    // Round-off scale of the angular momentum: Σ |q_k| |(M v)_k| over the 3-vector blocks.
    const VecX p = sys.mass() * s.v;
    double l = 0;
    for (int k = 0; k < p.size() / 3; ++k)
      l += s.q.segment<3>(3 * k).norm() * p.segment<3>(3 * k).norm();
    Ls = std::max(Ls, l);
  }
  Drift d;
  for (const auto& b : snaps) {
    d.energy = std::max(d.energy, std::abs(b.total_energy - a.total_energy) / scale);
    d.Lz = std::max(
        d.Lz, std::abs(b.angular_momentum.z() - a.angular_momentum.z()) / std::max(Ls, 1e-300));
    d.L = std::max(d.L, (b.angular_momentum - a.angular_momentum).norm() / std::max(Ls, 1e-300));
    d.p = std::max(d.p, (b.linear_momentum - a.linear_momentum).norm() / std::max(ps, 1e-300));
    d.phi = std::max(d.phi, b.constraint_violation);
  }
  d.q = s.q;
  return d;
}

const F kAll[] = {F::constrained, F::nullspace, F::reparametrized};
}  // namespace

TEST(Examples, HeavyTopConservesEnergyAndVerticalAngularMomentum) {
  for (F f : kAll) {
    const auto d = run(example("heavy_top", f), 1000);
    EXPECT_LT(d.energy, 1e-10) << model::to_string(f);
    EXPECT_LT(d.Lz, 1e-10) << model::to_string(f);
    EXPECT_LT(d.phi, 1e-12);
  }
}

TEST(Examples, FreeBodyFlipConservesEnergyAndAllMomenta) {
  for (F f : kAll) {
    const auto d = run(example("free_body_flip", f), 1000);
    EXPECT_LT(d.energy, 1e-10) << model::to_string(f);
    EXPECT_LT(d.L, 1e-10) << model::to_string(f);
    EXPECT_LT(d.p, 1e-10) << model::to_string(f);
  }
}

TEST(Examples, DoublePendulumConservesEnergyAndVerticalAngularMomentum) {
  const auto d = run(example("double_pendulum_3d", F::reparametrized), 1000);
  EXPECT_LT(d.energy, 1e-10);
  EXPECT_LT(d.Lz, 1e-10);
}

TEST(Examples, ClosedLoopsConserveEnergyAndKeepConstraints) {
  for (const char* name : {"four_bar", "slider_crank_rigid"}) {
    for (F f : kAll) {
      const auto d = run(example(name, f), 1000);
      EXPECT_LT(d.energy, 1e-10) << name << " " << model::to_string(f);
      EXPECT_LT(d.phi, 1e-10) << name << " " << model::to_string(f);
    }
  }
}

TEST(Examples, FormulationsAgreeOnHeavyTopAndFourBar) {
  for (const char* name : {"heavy_top", "four_bar"}) {
    const VecX ref = run(example(name, F::constrained), 300).q;
    for (F f : {F::nullspace, F::reparametrized})
      EXPECT_LT((run(example(name, f), 300).q - ref).lpNorm<Eigen::Infinity>(), 1e-8)
          << name << " " << model::to_string(f);
  }
}

// For open trees the reparametrized system has exactly as many unknowns as degrees of freedom.
TEST(Examples, ReparametrizedSizeEqualsDegreesOfFreedom) {
  for (const char* name : {"heavy_top", "free_body_flip", "double_pendulum_3d"}) {
    const auto m = example(name, F::reparametrized);
    const auto sys = system::System::compile(m);
    EXPECT_EQ(integrate::EnergyMomentumIntegrator(sys, m.solver).unknowns(),
              sys.n() - sys.m_selected())
        << name;
  }
  const auto sys = system::System::compile(example("four_bar", F::reparametrized));
  EXPECT_EQ(sys.dof(), 1);
  EXPECT_EQ(sys.n() - sys.m_selected(), 1);
}
