// Static solves with the PETSc solvers (integrate/static_newton.hpp LinearSolverMethod,
// docs/theory/solvers.md §3–4) against the direct solver, on the whole Scordelis–Lo roof as one
// Kirchhoff–Love patch (bench/large_shells/scordelis_lo_whole.yaml, smaller): the same
// displacements to the solver and Newton tolerances, linear and nonlinear (an inexact Newton),
// and the solver's own iterations counted.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
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

namespace {

// A model file of the repository with its solver, its knots per span (the "[40, 40]" or
// "[3, 1]" of the file replaced) and linear or 5× the self-weight in two load steps.
std::string repository_model(const std::string& path, const std::string& solver,
                             const std::string& knots_from, const std::string& knots_to) {
  std::ifstream in(std::string(ISOFLEX_SOURCE_DIR) + "/" + path);
  std::stringstream text;
  text << in.rdbuf();
  std::string s = text.str();
  const auto replace_all = [&](const std::string& from, const std::string& to) {
    for (auto p = s.find(from); p != std::string::npos; p = s.find(from, p + to.size()))
      s.replace(p, from.size(), to);
  };
  replace_all("knots_per_span: " + knots_from, "knots_per_span: " + knots_to);
  replace_all("linear_solver: cg_multigrid", "linear_solver: " + solver);
  replace_all("linear: true}", "linear: true, linear_solver: " + solver + "}");
  return s;
}

struct SolvedModel {
  VecX q;
  int krylov_iterations = 0, fallbacks = 0, unknowns = 0;
  std::string solver;
};

SolvedModel solve_model(const std::string& text) {
  const model::Model m = io::read_model_string(text, "model.yaml");
  const system::System sys = system::System::compile(m);
  integrate::StaticEquilibrium eq(sys, m.solver);
  SolvedModel out;
  out.unknowns = eq.unknowns();
  out.solver = eq.linear_solver();
  eq.solve([&](const integrate::LoadStepStats& st, const VecX& x) {
    out.q = x.head(sys.n());
    out.krylov_iterations += st.krylov_iterations;
    out.fallbacks += st.linear_solver_fallbacks;
  });
  return out;
}

// The model with `solver.support_rows: multipliers`: the symmetry rows as multiplier rows, the
// saddle-point path of the PETSc solvers (docs/theory/solvers.md §5) instead of the ties (§7).
std::string with_support_rows_as_multipliers(std::string text) {
  if (const auto block = text.find("solver:\n"); block != std::string::npos)
    text.insert(block + 8, "  support_rows: multipliers\n");
  else  // solver: {…}
    text.insert(text.find("solver: {") + 9, "support_rows: multipliers, ");
  return text;
}

// max |q − q_direct| relative to max |q − X|, the size of the displacements.
double relative_difference(const SolvedModel& s, const SolvedModel& direct, const VecX& X) {
  return (s.q - direct.q).cwiseAbs().maxCoeff() / (direct.q - X).cwiseAbs().maxCoeff();
}

}  // namespace

// The quarter roof with its symmetry supports imposed weakly (multiplier rows; without them
// nothing holds it along z, so the stiffness of the free coordinates alone is singular): the
// PETSc solvers take its saddle point (docs/theory/solvers.md §5, FGMRES with the block
// preconditioner on the augmented Lagrangian) and agree with the direct solver (the sparse LU of
// the whole matrix at this size) to 10⁻⁸ of the displacements, without a fallback.
TEST(StaticPetsc, SaddlePointWithSymmetryRowsAgreesWithTheDirectSolver) {
  ISOFLEX_REQUIRE_PETSC();
  const auto text = [](const std::string& solver) {
    return with_support_rows_as_multipliers(repository_model(
        "bench/large_shells/scordelis_lo_quarter.yaml", solver, "[40, 40]", "[24, 24]"));
  };
  const SolvedModel direct = solve_model(text("direct"));
  const model::Model m = io::read_model_string(text("direct"), "model.yaml");
  const VecX X = system::System::compile(m).q0();
  EXPECT_EQ(direct.krylov_iterations, 0);
  for (const char* method : {"cg_multigrid", "mumps", "cg_gamg"}) {
    const SolvedModel s = solve_model(text(method));
    const double diff = relative_difference(s, direct, X);
    std::printf("%-12s %4d iterations, relative difference %.2e\n", method, s.krylov_iterations,
                diff);
    EXPECT_EQ(s.solver, method);
    EXPECT_LT(diff, 1e-8) << method;
    EXPECT_EQ(s.fallbacks, 0) << method;
    EXPECT_GT(s.krylov_iterations, 0) << method;
  }
}

// Nonlinear (5× the self-weight in two load steps): the inexact Newton with the saddle-point
// solve reaches the direct solver's equilibrium.
TEST(StaticPetsc, SaddlePointInexactNewtonReachesTheSameEquilibrium) {
  ISOFLEX_REQUIRE_PETSC();
  const auto text = [](const std::string& solver) {
    std::string s = repository_model("bench/large_shells/scordelis_lo_quarter.yaml", solver,
                                     "[40, 40]", "[16, 16]");
    s.replace(s.find("  linear: true"), 14, "  linear: false");
    s.replace(s.find("  dt: 1\n"), 8, "  dt: 0.5\n");
    s.replace(s.find("-90*t"), 5, "-450*t");
    return s;
  };
  const SolvedModel direct = solve_model(text("direct"));
  const model::Model m = io::read_model_string(text("direct"), "model.yaml");
  const VecX X = system::System::compile(m).q0();
  // The saddle point (rows as multipliers), and the rows tied (the default).
  for (const bool multipliers : {true, false}) {
    const SolvedModel s =
        solve_model(multipliers ? with_support_rows_as_multipliers(text("cg_multigrid"))
                                : text("cg_multigrid"));
    const double diff = relative_difference(s, direct, X);
    std::printf("cg_multigrid, rows %s: %4d iterations, relative difference %.2e\n",
                multipliers ? "as multipliers" : "tied", s.krylov_iterations, diff);
    EXPECT_LT(diff, 1e-8);
    EXPECT_EQ(s.fallbacks, 0);
    EXPECT_GT(s.krylov_iterations, 0);
  }
}

// Two patches coupled by AF-D (examples/kl_scordelis_lo_two_patch, `coupling: angle`: the G¹
// rows tie coordinates, and the symmetry rows that the tied rows imply are kept with the
// equation μᵢ = 0): the saddle point with tied coordinates, symmetry rows and implied rows
// (`support_rows: multipliers`), and the symmetry rows tied as well (the default), by the PETSc
// solvers against the direct solver, to 10⁻⁸ of the displacements.
TEST(StaticPetsc, SaddlePointOfAMultipatchCouplingAgreesWithTheDirectSolver) {
  ISOFLEX_REQUIRE_PETSC();
  const auto text = [](const std::string& solver) {
    return repository_model("examples/kl_scordelis_lo_two_patch/model.yaml", solver, "[3, 1]",
                            "[6, 3]");
  };
  const SolvedModel direct = solve_model(text("direct"));
  const model::Model m = io::read_model_string(text("direct"), "model.yaml");
  const VecX X = system::System::compile(m).q0();
  for (const bool multipliers : {true, false})
    for (const char* method : {"mumps", "cg_gamg", "cg_multigrid"}) {
      const SolvedModel s =
          solve_model(multipliers ? with_support_rows_as_multipliers(text(method)) : text(method));
      const double diff = relative_difference(s, direct, X);
      std::printf("%-12s rows %s: %4d iterations, relative difference %.2e\n", method,
                  multipliers ? "as multipliers" : "tied", s.krylov_iterations, diff);
      EXPECT_LT(diff, 1e-8) << method;
      EXPECT_EQ(s.fallbacks, 0) << method;
      if (multipliers || std::string(method) != "mumps") {
        EXPECT_GT(s.krylov_iterations, 0) << method;
      }
    }
}

// The symmetry rows tied (solver.support_rows: auto, a PETSc solver; docs/theory/solvers.md §7):
// the Newton matrix Tᵀ K T has no multiplier rows, CG (or MUMPS's Cholesky) solves it, and the
// displacements are the direct saddle-point solver's (the LU at this size) to 10⁻⁸.
TEST(StaticPetsc, TiedSymmetryRowsAgreeWithTheDirectSaddlePoint) {
  ISOFLEX_REQUIRE_PETSC();
  const auto text = [](const std::string& solver) {
    return repository_model("bench/large_shells/scordelis_lo_quarter.yaml", solver, "[40, 40]",
                            "[24, 24]");
  };
  const SolvedModel direct = solve_model(text("direct"));
  const model::Model m = io::read_model_string(text("direct"), "model.yaml");
  const system::System sys = system::System::compile(m);
  const VecX X = sys.q0();
  const int rows = sys.linear_constraints().multipliers();
  ASSERT_GT(rows, 0);
  EXPECT_EQ(integrate::StaticEquilibrium(sys, m.solver).multipliers(), rows);  // direct: kept
  for (const char* method : {"cg_multigrid", "mumps", "cg_gamg"}) {
    const model::Model mm = io::read_model_string(text(method), "model.yaml");
    const integrate::StaticEquilibrium eq(sys, mm.solver);
    EXPECT_EQ(eq.multipliers(), 0) << method;
    EXPECT_EQ(eq.tied_rows(), rows) << method;
    EXPECT_EQ(eq.unknowns(), direct.unknowns - 2 * rows) << method;  // a slave and a multiplier
    const SolvedModel s = solve_model(text(method));
    const double diff = relative_difference(s, direct, X);
    std::printf("%-12s %4d iterations, relative difference %.2e\n", method, s.krylov_iterations,
                diff);
    EXPECT_EQ(s.solver, method);
    EXPECT_LT(diff, 1e-8) << method;
    EXPECT_EQ(s.fallbacks, 0) << method;
  }
}

// The one-eighth pinched cylinder (bench/large_shells/pinched_cylinder.yaml, 1.2·10⁴ unknowns,
// three levels): with the symmetry rows tied, the multigrid's interpolations follow the ties
// (P̂ = S P T_c), and CG takes about as many iterations as on a model without rows (16); with
// the rows as multipliers FGMRES on the saddle point takes 32. Both agree with the direct
// solver (here to the resolution of the coordinates: a displacement of 1.8·10⁻⁵ on coordinates
// of 300 is resolved to 3·10⁻⁹ of itself).
TEST(StaticPetsc, MultigridWithTiedSymmetryRowsConvergesInFewIterations) {
  ISOFLEX_REQUIRE_PETSC();
  const auto text = [](const std::string& solver) {
    return repository_model("bench/large_shells/pinched_cylinder.yaml", solver, "[40, 40]",
                            "[60, 60]");
  };
  const SolvedModel direct = solve_model(text("direct"));
  const model::Model m = io::read_model_string(text("direct"), "model.yaml");
  const VecX X = system::System::compile(m).q0();
  const SolvedModel tied = solve_model(text("cg_multigrid"));
  const SolvedModel saddle = solve_model(with_support_rows_as_multipliers(text("cg_multigrid")));
  std::printf(
      "tied: %s, %d unknowns, %d CG iterations, %.2e; multipliers: %s, %d unknowns, %d "
      "FGMRES iterations, %.2e (direct: %d unknowns, |u| %.3e)\n",
      tied.solver.c_str(), tied.unknowns, tied.krylov_iterations,
      relative_difference(tied, direct, X), saddle.solver.c_str(), saddle.unknowns,
      saddle.krylov_iterations, relative_difference(saddle, direct, X), direct.unknowns,
      (direct.q - X).cwiseAbs().maxCoeff());
  EXPECT_LT(relative_difference(tied, direct, X), 1e-8);
  EXPECT_LT(relative_difference(saddle, direct, X), 1e-8);
  EXPECT_EQ(tied.fallbacks, 0);
  EXPECT_GT(tied.krylov_iterations, 0);
  EXPECT_LE(tied.krylov_iterations, 20);  // 16 measured; 32 FGMRES iterations with multipliers
}

// The two-patch AF-D roof of bench/large_shells/scordelis_lo_two_patch.yaml at k = 100 (6.3·10⁴
// unknowns, four levels): the coarse control points on the interface are one (kl_multigrid.hpp)
// and only the supports' ties are carried to the coarse levels, not AF-D's, so CG takes about as
// many iterations as on the quarter roof of one patch (20): 20 measured since the smoothers'
// blocks end off the interface's band (solve/row_cuts.hpp, cuts heavier than 3 × the median), 26
// with blocks moved only off cuts above 10 ×; 45 when the shared points' rows were summed over
// both patches and all ties carried down, 47 with the points merged and all ties carried. The
// Newton iteration checks the solve's residual.
TEST(StaticPetsc, MultigridAcrossAPatchInterfaceConvergesInFewIterations) {
  ISOFLEX_REQUIRE_PETSC();
  const SolvedModel afd = solve_model(repository_model(
      "bench/large_shells/scordelis_lo_two_patch.yaml", "cg_multigrid", "[40, 40]", "[100, 100]"));
  std::printf("AF-D two-patch roof: %d unknowns, %d CG iterations\n", afd.unknowns,
              afd.krylov_iterations);
  EXPECT_EQ(afd.solver, "cg_multigrid");
  EXPECT_EQ(afd.fallbacks, 0);
  EXPECT_GT(afd.krylov_iterations, 0);
  EXPECT_LE(afd.krylov_iterations, 23);
}

// The two-patch roof coupled by a bending strip
// (bench/large_shells/scordelis_lo_bending_strip.yaml) at k = 24, 4 320 unknowns: the strip (1000 ×
// E) spans five rows of control points, and an equal block of the finest smoother ended inside it;
// the smoothers' blocks now end off the strip (solve/row_cuts.hpp). 18 CG iterations
// measured, 73 with equal blocks; the value the direct solver's to 1.7·10⁻⁹.
TEST(StaticPetsc, MultigridOnABendingStripConvergesInFewIterations) {
  ISOFLEX_REQUIRE_PETSC();
  const auto text = [](const std::string& solver) {
    return repository_model("bench/large_shells/scordelis_lo_bending_strip.yaml", solver,
                            "[40, 40]", "[24, 24]");
  };
  const SolvedModel strip = solve_model(text("cg_multigrid"));
  const SolvedModel direct = solve_model(text("direct"));
  const model::Model m = io::read_model_string(text("direct"), "model.yaml");
  const VecX X = system::System::compile(m).q0();
  std::printf("bending strip: %d unknowns, %d CG iterations, %.2e from the direct solver\n",
              strip.unknowns, strip.krylov_iterations, relative_difference(strip, direct, X));
  EXPECT_EQ(strip.solver, "cg_multigrid");
  EXPECT_EQ(strip.fallbacks, 0);
  EXPECT_GT(strip.krylov_iterations, 0);
  EXPECT_LE(strip.krylov_iterations, 30);
  EXPECT_LT(relative_difference(strip, direct, X), 1e-8);
}

// p-multigrid (`multigrid_coarsening: degree`, system/kl_multigrid.hpp): the quarter roof at
// k = 60 (11 781 unknowns; the symmetry rows tied, the diaphragm's x and y held), its first coarse
// level of degree 2 on the fine knots, then two of fewer knots. The same value as the direct
// solver, in about as many CG iterations as with the knots alone (17 and 19 measured). A coarse
// control point on the held diaphragm is held too (StaticProblem::first_transfer_not_nested):
// kept free, its interpolation restricted to the free rows made P̂ rank-deficient, the level's
// block Cholesky indefinite, and CG failed (DIVERGED_INDEFINITE_PC, the direct solver's fallback).
TEST(StaticPetsc, DegreeCoarseningAgreesWithTheDirectSolver) {
  ISOFLEX_REQUIRE_PETSC();
  const auto text = [](const std::string& solver) {
    return repository_model("bench/large_shells/scordelis_lo_quarter.yaml", solver, "[40, 40]",
                            "[60, 60]");
  };
  std::string degree = text("cg_multigrid");
  degree.insert(degree.find("linear_solver: cg_multigrid"), "multigrid_coarsening: degree\n  ");
  const SolvedModel p = solve_model(degree);
  const SolvedModel h = solve_model(text("cg_multigrid"));
  const SolvedModel direct = solve_model(text("direct"));
  const model::Model m = io::read_model_string(text("direct"), "model.yaml");
  const VecX X = system::System::compile(m).q0();
  std::printf("degree: %d CG iterations, %.2e from the direct solver; knots: %d, %.2e\n",
              p.krylov_iterations, relative_difference(p, direct, X), h.krylov_iterations,
              relative_difference(h, direct, X));
  EXPECT_EQ(p.solver, "cg_multigrid");
  EXPECT_EQ(p.fallbacks, 0);
  EXPECT_GT(p.krylov_iterations, 0);
  EXPECT_LE(p.krylov_iterations, h.krylov_iterations + 2);
  EXPECT_LT(relative_difference(p, direct, X), 1e-8);
  EXPECT_LT(relative_difference(h, direct, X), 1e-8);
}

// `auto` with tied coordinates of the model's own (AF-D), on a synthetic problem of that size
// (a model of 4·10⁵ unknowns takes half a minute to compile): the direct solver below
// kAutomaticTiedMultigridUnknowns free dofs, geometric multigrid from there on, and the direct
// solver while multiplier rows remain.
TEST(StaticPetsc, AutomaticTakesMultigridForTiedCoordinatesFromTheirThreshold) {
  ISOFLEX_REQUIRE_PETSC();
  const auto chosen = [](int free, bool rows) {
    integrate::StaticProblem pb;
    const int n = free + 1;  // one slave
    pb.reference = VecX::Zero(n);
    pb.evaluate = [](const VecX&, double, bool, integrate::ResidualEvaluation&) {};
    pb.transfer_operators = [] { return std::vector<Eigen::SparseMatrix<double>>{}; };
    system::LinearConstraints c;
    c.tied.push_back({{0, 1.0}, {1, -1.0}});
    c.C.resize(rows ? 1 : 0, n);
    if (rows) c.C.insert(0, 2) = 1.0;
    const integrate::StaticNewtonSolver solver(std::move(pb), std::move(c), {});
    EXPECT_EQ(solver.dofs().n_free(), free);
    return std::string(solver.linear_solver());
  };
  EXPECT_EQ(chosen(integrate::kAutomaticTiedMultigridUnknowns - 1, false), "direct");
  EXPECT_EQ(chosen(integrate::kAutomaticTiedMultigridUnknowns, false), "cg_multigrid");
  EXPECT_EQ(chosen(integrate::kAutomaticTiedMultigridUnknowns, true), "direct");
}

// `auto` (integrate::kAutomaticMultigridUnknowns): geometric multigrid for patches without rows
// from 50 000 unknowns on, the direct solver below; with weak supports' multiplier rows from
// 100 000 free dofs on (kAutomaticSaddlePointMultigridUnknowns).
TEST(StaticPetsc, AutomaticChoosesMultigridBySize) {
  ISOFLEX_REQUIRE_PETSC();
  const auto chosen = [](int knots, const std::string& extra_support, bool multipliers = false) {
    std::string text = roof("auto", true, knots);
    text.replace(text.find("kl_loads:"), 0, extra_support);
    if (multipliers) text = with_support_rows_as_multipliers(text);
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
  // Symmetry rows: tied where a PETSc solver takes the matrix (§7), so the threshold of a model
  // without rows; as multipliers (solver.support_rows), the saddle point's threshold.
  const std::string symmetry = "  - {shell: roof, edge: u0, symmetry: [1, 0, 0]}\n";
  EXPECT_EQ(chosen(120, symmetry).second, "direct");
  const auto [rows, rows_solver] = chosen(127, symmetry);
  EXPECT_GE(rows, integrate::kAutomaticMultigridUnknowns);
  EXPECT_EQ(rows_solver, "cg_multigrid");
  const auto [saddle, saddle_solver] = chosen(127, symmetry, true);
  EXPECT_LT(saddle, integrate::kAutomaticSaddlePointMultigridUnknowns);
  EXPECT_EQ(saddle_solver, "direct");
  const auto [many_rows, many_rows_solver] = chosen(180, symmetry, true);
  EXPECT_GE(many_rows, integrate::kAutomaticSaddlePointMultigridUnknowns);
  EXPECT_EQ(many_rows_solver, "cg_multigrid");
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
