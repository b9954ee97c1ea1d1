// Director nodes in the system (DNSM-III §4, Ex. 5.3): sizes, the tree null space of shells joined
// to each other, to bodies and to the ground, the update map, and a load-free shell system that
// conserves energy and momenta in every formulation.
#include <gtest/gtest.h>

#include "isoflex/integrate/energy_momentum.hpp"
#include "isoflex/io/model_reader.hpp"
#include "isoflex/system/system.hpp"
#include "support/finite_difference.hpp"

using namespace isoflex;

namespace {
// A body "hub" holding edge u0 of plate p, plate q joined to edge u1 of p at 126.9°, and
// optionally supports: p[0] pinned (so the hub hangs from a shell node: FrameOnDirector) and
// edge v1 of q on the symmetry plane y = 0.5.
std::string shells_yaml(bool supports, const std::string& formulation = "reparametrized") {
  std::string y = R"yaml(
name: shells
solver: {formulation: )yaml" +
                  formulation +
                  R"yaml(, dt: 0.01, t_end: 0.3, increment_tolerance: 1.0e-13}
bodies:
  - {name: hub, mass: 2, inertia: [0.1, 0.2, 0.3], position: [-0.1, 0.25, 0]}
shells:
  - name: p
    plate: {corners: [[0, 0, 0], [1, 0, 0], [1, 0.5, 0], [0, 0.5, 0]], elements: [3, 2]}
    material: {E: 1.0e5, nu: 0.3, thickness: 0.05, density: 100}
  - name: q
    plate: {corners: [[1, 0, 0], [1.6, 0, 0.8], [1.6, 0.5, 0.8], [1, 0.5, 0]], elements: [2, 2]}
    material: {E: 1.0e5, nu: 0.3, thickness: 0.05, density: 100}
shell_connections:
  - {shell: p, edge: u0, attach_to: hub}
  - {shell: p, edge: u1, join: {shell: q, edge: u0}}
shell_loads:
  - {shell: q, pressure: "50*(t<0.1)"}
  - {shell: p, nodes: [5], force: ["0", "3*(t<0.1)", "0"], moment: ["0.2*(t<0.1)", "0", "0"]}
)yaml";
  if (supports)
    y += R"yaml(shell_supports:
  - {shell: p, nodes: [0], translation: all}
  - {shell: q, edge: v1, translation: [y], director: [0, 1, 0]}
)yaml";
  return y;
}

system::System compile(bool supports) {
  return system::System::compile(io::read_model_string(shells_yaml(supports), "shells.yaml"));
}

// A configuration near q₀ but off the constraint manifold.
VecX perturbed(const system::System& sys, std::mt19937& g, double scale) {
  return sys.q0() + test::random_vector(g, sys.n(), scale);
}
}  // namespace

TEST(ShellSystem, CountsNodesConstraintsAndTreeCoordinates) {
  const auto free = compile(false);
  // hub + 12 + 9 director nodes; n = 12 + 21·6, m = 6 + 21 internal + 3·5 attached + 3·4 joined.
  EXPECT_EQ(free.node_count(), 22);
  EXPECT_EQ(free.node_count(isoflex::NodeKind::director), 21);
  EXPECT_EQ(free.n(), 138);
  EXPECT_EQ(free.m_selected(), 27 + 15 + 12);
  EXPECT_EQ(free.k(), free.n() - free.m_selected());
  EXPECT_LT(free.constraints(free.q0(), 0.0).lpNorm<Eigen::Infinity>(), 1e-15);
  const auto held = compile(true);
  // + pinned p[0] (3 rows) and three nodes on the symmetry plane (y and d·n: 2 rows each).
  EXPECT_EQ(held.m_selected(), free.m_selected() + 3 + 6);
  EXPECT_EQ(held.k(), held.n() - held.m_selected());
  EXPECT_TRUE(held.cut_rows().empty());
}

// G(q) P_tree(q) = 0 on all of Rⁿ, so P_tree(q_{n+½}) is a discrete null space (DNSM-III (10)).
TEST(ShellSystem, TreeNullSpaceAnnihilatesJacobianEverywhere) {
  std::mt19937 g(3);
  for (bool supports : {false, true}) {
    const auto sys = compile(supports);
    for (int k = 0; k < 3; ++k) {
      const VecX q = perturbed(sys, g, 0.2);
      const MatX G = MatX(sys.jacobian(q)), P = MatX(sys.tree_null_space(q));
      EXPECT_LT((G * P).norm(), 1e-13 * G.norm() * P.norm());
      Eigen::FullPivLU<MatX> lu(P);
      EXPECT_EQ(lu.rank(), sys.k());
    }
  }
}

// The update keeps every constraint, and ∂F/∂u (from the twist blocks ℬ̃) is its derivative.
TEST(ShellSystem, UpdateKeepsConstraintsWithExactDerivative) {
  std::mt19937 g(4);
  const auto sys = compile(true);
  VecX q = sys.q0();
  for (int step = 0; step < 3; ++step) {
    const VecX u = test::random_vector(g, sys.k(), 0.3);
    const VecX q1 = sys.update(q, u);
    EXPECT_LT(sys.constraints(q1, 0.0).lpNorm<Eigen::Infinity>(), 1e-14);
    auto f = [&](const VecX& x) -> VecX { return sys.update(q, x); };
    EXPECT_LT(test::rel_diff(MatX(sys.update_derivative(q, q1, u)), test::central_jacobian(f, u)),
              1e-7);
    q = q1;
  }
}

// After the loads end: energy, linear and angular momentum constant to round-off in every
// formulation, and the three formulations on the same trajectory (DNSM-III Sect. 2).
TEST(ShellSystem, FreeShellsConserveEnergyAndMomentaInEveryFormulation) {
  std::vector<VecX> finals;
  for (const char* f : {"constrained", "nullspace", "reparametrized"}) {
    const auto m = io::read_model_string(shells_yaml(false, f), "shells.yaml");
    const auto sys = system::System::compile(m);
    integrate::EnergyMomentumIntegrator integ(sys, m.solver);
    auto s = integ.initial_state();
    std::vector<integrate::Snapshot> after;
    for (int i = 0; i < 30; ++i) {
      const auto st = integ.step(s);
      if (s.t > 0.1 + 1e-9) after.push_back(integ.snapshot(s, st, {}));
      EXPECT_LT(sys.constraints(s.q, s.t).lpNorm<Eigen::Infinity>(), 1e-13) << f;
    }
    ASSERT_GT(after.size(), 10u);
    const auto& a = after.front();
    EXPECT_GT(a.kinetic_energy, 0.1) << f;
    for (const auto& b : after) {
      EXPECT_LT(std::abs(b.total_energy - a.total_energy), 1e-12 * a.total_energy) << f;
      EXPECT_LT((b.linear_momentum - a.linear_momentum).norm(), 1e-12) << f;
      EXPECT_LT((b.angular_momentum - a.angular_momentum).norm(), 1e-12) << f;
    }
    finals.push_back(s.q);
  }
  EXPECT_LT((finals[0] - finals[2]).lpNorm<Eigen::Infinity>(), 1e-9);
  EXPECT_LT((finals[1] - finals[2]).lpNorm<Eigen::Infinity>(), 1e-9);
}
