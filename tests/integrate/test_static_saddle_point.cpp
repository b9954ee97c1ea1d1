// Static Newton with multiplier rows solved by the augmented Lagrangian (solve/saddle_point.hpp,
// StaticSettings::saddle_point) instead of the sparse LU: AF-BS rows (IGA-thesis (5.5)) on a
// nonlinear 3 × 3-patch plate, and KL supports as multiplier rows with AF-BS together. The
// equilibria are the LU's to the Newton tolerance, in the same iterations, with no fallback.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "isoflex/integrate/static_equilibrium.hpp"
#include "isoflex/io/model_reader.hpp"
#include "isoflex/system/system.hpp"
#include "support/kl_plate_grid.hpp"

using namespace isoflex;

namespace {

struct Solved {
  VecX q;
  int newton_iterations = 0, krylov_iterations = 0, fallbacks = 0;
};

Solved solve(const std::string& yaml) {
  const model::Model m = io::read_model_string(yaml, "m.yaml");
  const auto sys = system::System::compile(m);
  integrate::StaticEquilibrium eq(sys, m.solver);
  const integrate::StaticResult res = eq.solve();
  Solved out{res.x.head(sys.n()), 0, 0, 0};
  for (const auto& st : res.steps) {
    out.newton_iterations += st.iterations;
    out.krylov_iterations += st.krylov_iterations;
    out.fallbacks += st.saddle_point_fallbacks;
  }
  return out;
}

std::string plate(const std::string& saddle_point, int steps,
                  const std::string& support = "fixed: all", int grid = 3) {
  test::PlateGrid g;
  g.pu = g.pv = grid;
  g.support = support;
  g.coupling = "strip_constraints";
  g.solver = "{analysis: static, dt: " + std::to_string(1.0 / steps) +
             ", t_end: 1, saddle_point_solver: " + saddle_point + "}";
  return test::plate_grid_yaml(g);
}

double relative_difference(const VecX& a, const VecX& b, const VecX& reference) {
  return (a - b).lpNorm<Eigen::Infinity>() / (b - reference).lpNorm<Eigen::Infinity>();
}

}  // namespace

// Clamped edges add the slope rows of the supports (multiplier rows of the LinearConstraints,
// IGA-thesis (4.27)) to AF-BS's rows. (The 3 × 3 clamped plate failed in the sparse LU too before
// the rank threshold of system::select_group_rows was taken before the projection: 9
// "independent" rows on interfaces of 4 triples, a singular Newton matrix.)
TEST(StaticSaddlePoint, AugmentedLagrangianGivesTheLuEquilibriumOfStripConstraints) {
  struct Case {
    int steps;
    std::string support;
    int grid;
  };
  for (const Case& c : {Case{1, "fixed: all", 3}, Case{2, "fixed: all", 3},
                        Case{1, "clamped: all", 2}, Case{1, "clamped: all", 3}}) {
    const Solved lu = solve(plate("lu", c.steps, c.support, c.grid));
    const Solved al = solve(plate("augmented_lagrangian", c.steps, c.support, c.grid));
    const model::Model m = io::read_model_string(plate("lu", c.steps, c.support, c.grid), "m.yaml");
    const VecX q0 = system::System::compile(m).q0();
    const double d = relative_difference(al.q, lu.q, q0);
    std::printf(
        "  [saddle point] %d x %d, %s, %d load steps: Newton %d (LU %d), GMRES %d, "
        "|q_AL - q_LU| %.2e\n",
        c.grid, c.grid, c.support.c_str(), c.steps, al.newton_iterations, lu.newton_iterations,
        al.krylov_iterations, d);
    EXPECT_LT(d, 1e-9);
    EXPECT_EQ(al.newton_iterations, lu.newton_iterations);
    EXPECT_GT(al.krylov_iterations, 0);  // the augmented Lagrangian did solve
    EXPECT_EQ(al.fallbacks, 0);
    EXPECT_EQ(lu.krylov_iterations, 0);
  }
}

TEST(StaticSaddlePoint, AutomaticChoiceKeepsTheLuForSmallSystems) {
  const Solved automatic = solve(plate("auto", 1));
  const Solved lu = solve(plate("lu", 1));
  EXPECT_EQ(automatic.krylov_iterations, 0);
  EXPECT_EQ(automatic.q, lu.q);  // the very same solves, to the last digit
}
