// Static solves with the PETSc solvers (integrate/static_newton.hpp LinearSolverMethod,
// docs/theory/solvers.md §3–4) against the direct solver, on the whole Scordelis–Lo roof as one
// Kirchhoff–Love patch (bench/large_shells/scordelis_lo_whole.yaml, smaller): the same
// displacements to the solver and Newton tolerances, linear and nonlinear (an inexact Newton),
// and the solver's own iterations counted.
#include <gtest/gtest.h>

#include <string>

#include "isoflex/integrate/static_equilibrium.hpp"
#include "isoflex/io/model_reader.hpp"
#include "isoflex/solve/krylov_solver.hpp"
#include "isoflex/system/system.hpp"
#include "support/petsc.hpp"

using namespace isoflex;

namespace {

std::string roof(const std::string& solver, bool linear, int knots) {
  return R"(
solver:
  analysis: static
  dt: )" +
         std::string(linear ? "1" : "0.5") +
         R"(
  t_end: 1
  linear: )" +
         (linear ? "true" : "false") +
         R"(
  linear_solver: )" +
         solver + R"(
surfaces:
  - name: roof
    builtin: {type: cylinder_sector, radius: 25, length: 50, angle: 80}
    refine: {elevate: [1, 2], knots_per_span: [)" +
         std::to_string(knots) + ", " + std::to_string(knots) + R"(]}
kl_shells:
  - {name: roof, surface: roof, material: {E: 4.32e8, nu: 0, thickness: 0.25}}
kl_supports:
  - {shell: roof, edge: v0, fixed: [x, y]}
  - {shell: roof, edge: v1, fixed: [x, y]}
  - {shell: roof, control_points: [0], fixed: [z]}
kl_loads:
  - {name: self_weight, shell: roof, area_force: [0, "-450*t", 0]}
)";
}

struct Solved {
  VecX q;
  int krylov_iterations = 0, fallbacks = 0, newton_iterations = 0;
};

Solved solve_roof(const std::string& solver, bool linear, int knots = 30) {
  const model::Model m = io::read_model_string(roof(solver, linear, knots), "roof.yaml");
  const system::System sys = system::System::compile(m);
  integrate::StaticEquilibrium eq(sys, m.solver);
  Solved out;
  eq.solve([&](const integrate::LoadStepStats& st, const VecX& x) {
    out.q = x.head(sys.n());
    out.krylov_iterations += st.krylov_iterations;
    out.fallbacks += st.linear_solver_fallbacks;
    out.newton_iterations += st.iterations;
  });
  return out;
}

}  // namespace

// Linear: one solve, to a tenth of the Newton tolerance (10⁻¹¹ of the load): the displacements
// agree with CHOLMOD's to 10⁻⁸ of their size, which the roof's condition number allows.
TEST(StaticPetsc, LinearSolvesAgreeWithTheDirectSolver) {
  ISOFLEX_REQUIRE_PETSC();
  const Solved direct = solve_roof("direct", true);
  EXPECT_EQ(direct.krylov_iterations, 0);
  const double size = (direct.q - solve_roof("direct", true, 30).q).norm();  // 0: deterministic
  EXPECT_EQ(size, 0.0);
  for (const char* method : {"cg_gamg", "cg_multigrid", "mumps"}) {
    const Solved s = solve_roof(method, true);
    const double diff = (s.q - direct.q).cwiseAbs().maxCoeff();
    const double u = 1.0;  // |u| of the roof under 5× its self-weight is O(1)
    std::printf("%-12s %4d iterations, max |q - q_direct| = %.2e\n", method, s.krylov_iterations,
                diff);
    EXPECT_LT(diff, 1e-8 * u) << method;
    EXPECT_EQ(s.fallbacks, 0) << method;
    if (std::string(method) == "mumps")
      EXPECT_EQ(s.krylov_iterations, 0);
    else
      EXPECT_GT(s.krylov_iterations, 0) << method;
  }
}

// Nonlinear, 5× the self-weight in two load steps: the inexact Newton (forcing term
// min(10⁻², ‖R‖/scale)) reaches the same equilibrium as Newton with the direct solver, in at
// most two more iterations per step.
TEST(StaticPetsc, InexactNewtonReachesTheSameEquilibrium) {
  ISOFLEX_REQUIRE_PETSC();
  const Solved direct = solve_roof("direct", false);
  for (const char* method : {"cg_gamg", "cg_multigrid"}) {
    const Solved s = solve_roof(method, false);
    const double diff = (s.q - direct.q).cwiseAbs().maxCoeff();
    std::printf("%-12s Newton %d (direct %d), CG %d, max |q - q_direct| = %.2e\n", method,
                s.newton_iterations, direct.newton_iterations, s.krylov_iterations, diff);
    EXPECT_LT(diff, 1e-8) << method;
    EXPECT_LE(s.newton_iterations, direct.newton_iterations + 4) << method;
    EXPECT_EQ(s.fallbacks, 0) << method;
  }
}

// A patch too small to coarsen (no more unknowns than the coarsest level takes) is solved by
// the coarsest level's Cholesky factorization alone: one CG iteration, and a second where the
// round-off of the first is above the tolerance (a tenth of the Newton tolerance).
TEST(StaticPetsc, MultigridOnASmallPatchIsItsCoarsestLevel) {
  ISOFLEX_REQUIRE_PETSC();
  const Solved direct = solve_roof("direct", true, 8);
  const Solved s = solve_roof("cg_multigrid", true, 8);
  EXPECT_LT((s.q - direct.q).cwiseAbs().maxCoeff(), 1e-10);
  EXPECT_GE(s.krylov_iterations, 1);
  EXPECT_LE(s.krylov_iterations, 2);
  EXPECT_EQ(s.fallbacks, 0);
}

// `auto` (integrate::kAutomaticMultigridUnknowns): geometric multigrid for patches without rows
// from 50 000 unknowns on, the direct solver below and wherever the matrix has multiplier rows.
TEST(StaticPetsc, AutomaticChoosesMultigridBySize) {
  ISOFLEX_REQUIRE_PETSC();
  const auto chosen = [](int knots, const std::string& extra_support) {
    std::string text = roof("auto", true, knots);
    text.replace(text.find("kl_loads:"), 0, extra_support);
    const model::Model m = io::read_model_string(text, "roof.yaml");
    const system::System sys = system::System::compile(m);
    const integrate::StaticEquilibrium eq(sys, m.solver);
    return std::make_pair(eq.unknowns(), std::string(eq.linear_solver()));
  };
  const auto [small, small_solver] = chosen(120, "");
  EXPECT_LT(small, integrate::kAutomaticMultigridUnknowns);
  EXPECT_EQ(small_solver, "direct");
  const auto [large, large_solver] = chosen(127, "");
  EXPECT_GE(large, integrate::kAutomaticMultigridUnknowns);
  EXPECT_EQ(large_solver, "cg_multigrid");
  const auto [rows, rows_solver] =
      chosen(127, "  - {shell: roof, edge: u0, symmetry: [1, 0, 0]}\n");
  EXPECT_GE(rows, integrate::kAutomaticMultigridUnknowns);
  EXPECT_EQ(rows_solver, "direct");
}

// A static run keeps no copy of a linear patch's constant tangent (System::keep_linear_tangent,
// set by `isoflex run`): the tangent is evaluated instead of copied, with the same values, so the
// solution is the same to the last bit, over several load steps.
TEST(StaticPetsc, NoKeptLinearTangentGivesTheSameSolution) {
  std::string text = roof("direct", true, 12);
  text.replace(text.find("dt: 1"), 5, "dt: 0.25");
  const model::Model m = io::read_model_string(text, "roof.yaml");
  const auto solve_with = [&](bool keep) {
    system::System sys = system::System::compile(m);
    sys.keep_linear_tangent(keep);
    integrate::StaticEquilibrium eq(sys, m.solver);
    std::vector<VecX> steps;
    eq.solve([&](const integrate::LoadStepStats&, const VecX& x) { steps.push_back(x); });
    return steps;
  };
  const std::vector<VecX> kept = solve_with(true), not_kept = solve_with(false);
  ASSERT_EQ(kept.size(), 4u);
  ASSERT_EQ(not_kept.size(), kept.size());
  for (std::size_t k = 0; k < kept.size(); ++k)
    EXPECT_EQ((kept[k] - not_kept[k]).cwiseAbs().maxCoeff(), 0.0) << "load step " << k + 1;
  EXPECT_GT((kept.back() - kept.front()).cwiseAbs().maxCoeff(), 1e-3);  // the roof moved
}
