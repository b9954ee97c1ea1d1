// examples/viscoelastic_beam_release (IGA-thesis §6.4.3.1): a Kirchhoff–Love strip released from
// the static deflection under a tip load (solver.initial_equilibrium), damped by Kelvin–Voigt
// viscosity (material.eta). The start is the equilibrium of the static analysis; energy +
// dissipated energy stays constant to round-off; the oscillation decays, more slowly while the
// deflection is large, and its damping ratio approaches that of the linear first mode,
// ζ = η ω₁ / 2.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "isoflex/integrate/initial_equilibrium.hpp"
#include "isoflex/integrate/static_equilibrium.hpp"
#include "isoflex/io/model_reader.hpp"
#include "support/cli.hpp"
#include "support/examples.hpp"
#include "support/files.hpp"
#include "support/geometry.hpp"
#include "support/model_errors.hpp"
#include "support/sanitizers.hpp"
#include "support/trajectory.hpp"

using namespace isoflex;

namespace {

void report(const char* what, double v) {
  std::printf("  [viscoelastic-beam] %-44s %.6g\n", what, v);
  ::testing::Test::RecordProperty(what, test::sci(v));
}

model::Model beam(double t_end, double eta) {
  model::Model m = io::read_model_string(
      test::example_text("viscoelastic_beam_release", "model.yaml"), "model.yaml");
  m.solver.t_end = t_end;
  m.kl_shells.front().eta = eta;
  return m;
}

// The tip's z at its maxima (upper turning points), from t > 0.
std::vector<double> peaks(const test::Trajectory& r) {
  const std::vector<Vec3> tip = r.probe("tip");
  std::vector<double> z;
  for (std::size_t i = 1; i + 1 < tip.size(); ++i)
    if (tip[i].z() >= tip[i - 1].z() && tip[i].z() > tip[i + 1].z()) z.push_back(tip[i].z());
  return z;
}

// ζ_k / √(1 − ζ_k²) = ln(z_k / z_{k+1}) / 2π (IGA-thesis §6.4.3.1).
double damping_ratio(double zk, double zk1) {
  const double d = std::log(zk / zk1) / (2.0 * test::kPi);
  return d / std::sqrt(1.0 + d * d);
}

}  // namespace

// The initial equilibrium is one: with the least-squares multipliers of the supports the
// residual ∇V − f_ext(0) + Gᵀλ vanishes to round-off, and the rows hold. It agrees with the static
// analysis of the same load to 10⁻⁴: the static clamp leaves the stretch across the edge free,
// the dynamic one attaches the second row of control points rigidly (system_compile.cpp).
TEST(ViscoelasticBeam, StartsFromTheStaticEquilibrium) {
  const model::Model m = beam(0.02, 0.01);
  const integrate::InitialEquilibrium eq = integrate::initial_equilibrium(m);
  EXPECT_EQ(eq.load_steps, 20);
  const auto dyn = system::System::compile(m);
  const VecX f = dyn.static_force(eq.q, 0.0, nullptr);
  const MatX G(dyn.jacobian(eq.q));
  const VecX lambda = (G * G.transpose()).ldlt().solve(-G * f);
  EXPECT_LT((f + G.transpose() * lambda).norm(), 1e-10 * f.norm());
  EXPECT_LT(dyn.constraints(eq.q, 0.0).norm(), 1e-15);

  model::Model s = io::read_model_string(
      test::replaced(test::example_text("viscoelastic_beam_release", "model.yaml"),
                     "  dt: 0.01\n  t_end: 20\n  initial_equilibrium: 20",
                     "  analysis: static\n  dt: 0.05\n  t_end: 1"),
      "model.yaml");
  s.kl_loads.front().force[2] = "5";
  const auto sys = system::System::compile(s);
  integrate::StaticEquilibrium solver(sys, s.solver);
  const VecX q = solver.solve().x.head(sys.n());
  const Vec3 a = dyn.probe_point(eq.q, dyn.probes().front());
  const Vec3 b = sys.probe_point(q, sys.probes().front());
  EXPECT_LT((a - b).norm(), 3e-4 * b.z());
  EXPECT_NEAR(a.z(), 0.2175, 1e-4);  // a large deflection: L = 0.3
  report("|f + G^T lambda| / |f| at the equilibrium",
         (f + G.transpose() * lambda).norm() / f.norm());
  report("tip z of the initial equilibrium", a.z());
  report("tip z, static analysis (free stretch at the clamp)", b.z());
}

TEST(ViscoelasticBeam, EnergyPlusDissipationIsConservedAndTheSwingDecays) {
  ISOFLEX_SKIP_LONG_RUN_UNDER_ASAN();
  const test::Trajectory r = test::simulate(beam(6.0, 0.01), model::Formulation::reparametrized);
  const auto& s = r.snapshots;
  double worst = 0.0;
  for (const auto& x : s)
    worst = std::max(worst, std::abs(x.total_energy + x.dissipated_energy - s[0].total_energy) /
                                s[0].total_energy);
  EXPECT_LT(worst, 1e-12);
  EXPECT_EQ(s[0].kinetic_energy, 0.0);  // at rest
  const std::vector<double> z = peaks(r);
  ASSERT_GE(z.size(), 3u);
  for (std::size_t k = 1; k < z.size(); ++k) EXPECT_LT(z[k], z[k - 1]);
  // The damping grows as the deflection falls (less damping in the nonlinear regime).
  EXPECT_LT(damping_ratio(z[0], z[1]), damping_ratio(z[1], z[2]));
  report("|E + D - E0| / E0", worst);
  report("zeta_1", damping_ratio(z[0], z[1]));
}

// Without damping the swing keeps its amplitude (the energy–momentum scheme conserves energy);
// with η the late, small oscillations decay at the damping ratio of the first bending mode,
// ζ = η ω₁/2 with ω₁ = 2π / period of the undamped run.
TEST(ViscoelasticBeam, LinearRegimeDampingRatioIsEtaOmegaOverTwo) {
  ISOFLEX_SKIP_LONG_RUN_UNDER_ASAN();
  const test::Trajectory free = test::simulate(beam(6.0, 0.0), model::Formulation::reparametrized);
  const std::vector<double> z0 = peaks(free);
  ASSERT_GE(z0.size(), 3u);
  EXPECT_LT(std::abs(z0[2] - z0[0]), 1e-2 * z0[0]);  // 0.26 %: energy shared with other modes
  EXPECT_EQ(free.snapshots.back().dissipated_energy, 0.0);

  model::Model m = beam(12.0, 0.01);
  m.kl_loads.front().force[2] = "0.5*(t<=0)";  // F₀/10: the linear regime
  const test::Trajectory r = test::simulate(m, model::Formulation::reparametrized);
  const std::vector<Vec3> tip = r.probe("tip");
  std::vector<double> up;  // times of the maxima
  for (std::size_t i = 1; i + 1 < tip.size(); ++i)
    if (tip[i].z() >= tip[i - 1].z() && tip[i].z() > tip[i + 1].z()) up.push_back(r.snapshots[i].t);
  const std::vector<double> z = peaks(r);
  ASSERT_GE(z.size(), 6u);
  const double period = (up.back() - up.front()) / static_cast<double>(up.size() - 1);
  const double omega = 2.0 * test::kPi / period;
  const double zeta = damping_ratio(z[z.size() - 2], z.back()), linear = 0.01 * omega / 2.0;
  EXPECT_NEAR(zeta / linear, 1.0, 0.05);
  report("omega_1 (rad/s)", omega);
  report("zeta, small amplitude", zeta);
  report("eta omega_1 / 2", linear);
}

// Through the CLI: the equilibrium is announced, summary.json records it and the dissipated
// energy, history.csv has the dissipated_energy column.
TEST(ViscoelasticBeam, CliReportsTheStartAndTheDissipation) {
  const test::TempDir dir(test::temp_dir("isoflex_", "viscoelastic_cli"));
  const std::string model = (dir.path() / "m.yaml").string();
  test::write_text(model,
                   test::replaced(test::example_text("viscoelastic_beam_release", "model.yaml"),
                                  "t_end: 20", "t_end: 0.1"));
  const auto r = test::run_isoflex("run " + model + " -o " + (dir.path() / "out").string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("initial equilibrium: 20 load steps"), std::string::npos) << r.out;
  const std::string summary = test::read_text((dir.path() / "out" / "summary.json").string());
  EXPECT_NE(summary.find("\"initial_equilibrium_load_steps\": 20"), std::string::npos);
  EXPECT_NE(summary.find("\"dissipated_energy\": "), std::string::npos);
  const std::string history = test::read_text((dir.path() / "out" / "history.csv").string());
  EXPECT_EQ(history.rfind("t,kinetic_energy", 0), 0u);
  EXPECT_NE(history.find(",residual,dissipated_energy,external_work\n"), std::string::npos);
}

// solver.initial_equilibrium is for dynamic runs; a count, at most 10 000.
TEST(ViscoelasticBeam, InitialEquilibriumKeyErrors) {
  const auto error = [](const std::string& solver) {
    return test::error_of("name: m\nsolver:\n" + solver + "\n");
  };
  EXPECT_EQ(error("  analysis: static\n  initial_equilibrium: 5"),
            "m.yaml:4: solver.initial_equilibrium: the start from a static equilibrium is for a "
            "dynamic analysis (a static analysis finds the equilibrium itself)");
  EXPECT_EQ(error("  initial_equilibrium: 20000"),
            "m.yaml:3: solver.initial_equilibrium: at most 10000 load steps");
  EXPECT_EQ(error("  initial_equilibrium: -1"),
            "m.yaml:3: solver.initial_equilibrium: must be >= 0, got -1");
}

// examples/viscoelastic_beam_periodic (IGA-thesis §6.4.3.2) at η = 0.08 s: after ten decay times
// 2/(η ω₁²) of the transient the tip oscillates at the load's Ω with the amplitude and phase lag of
// the linear one-mode Kelvin–Voigt oscillator (README.md there): X = X₀/√((1 − r²)² + (ηΩ)²),
// tan φ = ηΩ/(1 − r²), r = Ω/ω₁.
TEST(ViscoelasticBeam, SteadyStateUnderAHarmonicLoad) {
  ISOFLEX_SKIP_LONG_RUN_UNDER_ASAN();
  model::Model m = io::read_model_string(
      test::example_text("viscoelastic_beam_periodic", "model.yaml"), "model.yaml");
  const double eta = 0.08, Omega = 3.39, omega1 = 3.583, X0 = 5.193e-3;
  m.kl_shells.front().eta = eta;
  m.solver.t_end = 20.0;
  const test::Trajectory r = test::simulate(m, model::Formulation::reparametrized);
  // Least squares over the last four periods: u_z = a sin Ωt + b cos Ωt + c.
  const double t0 = m.solver.t_end - 4 * 2 * test::kPi / Omega;
  const std::vector<Vec3> tip = r.probe("tip");
  const Vec3 X_ref = tip.front();
  Eigen::MatrixXd A(0, 3);
  VecX z(0);
  for (std::size_t i = 0; i < tip.size(); ++i) {
    const double t = r.snapshots[i].t;
    if (t < t0) continue;
    A.conservativeResize(A.rows() + 1, 3);
    z.conservativeResize(z.size() + 1);
    A.row(A.rows() - 1) << std::sin(Omega * t), std::cos(Omega * t), 1.0;
    z(z.size() - 1) = tip[i].z() - X_ref.z();
  }
  const Vec3 abc = A.colPivHouseholderQr().solve(z);
  const double X = std::hypot(abc(0), abc(1)), phi = std::atan2(-abc(1), abc(0));
  const double rr = Omega / omega1;
  const double X_sdof = X0 / std::hypot(1 - rr * rr, eta * Omega);
  const double phi_sdof = std::atan2(eta * Omega, 1 - rr * rr);
  EXPECT_NEAR(X / X_sdof, 1.0, 0.02);
  EXPECT_NEAR((phi - phi_sdof) * 180 / test::kPi, 0.0, 1.0);
  for (std::size_t i = 1; i < r.snapshots.size(); ++i)
    EXPECT_GT(r.snapshots[i].dissipated_energy, r.snapshots[i - 1].dissipated_energy) << i;
  report("steady amplitude / one-mode oscillator", X / X_sdof);
  report("phase lag - one-mode oscillator (deg)", (phi - phi_sdof) * 180 / test::kPi);
}

// tools/damping_study.py runs the model per η and writes the two figures and the table.
TEST(ViscoelasticBeam, DampingStudyScript) {
  ISOFLEX_SKIP_LONG_RUN_UNDER_ASAN();
  const test::TempDir dir(test::temp_dir("isoflex_", "damping_study"));
  const std::string table = (dir.path() / "table.md").string();
  const auto r = test::run_shell(
      std::string("cd ") + ISOFLEX_SOURCE_DIR + " && /usr/bin/python3 tools/damping_study.py " +
      "examples/viscoelastic_beam_release/model.yaml --etas 0,0.02 --t-end 4 --isoflex " +
      ISOFLEX_BINARY + " --outdir " + dir.path().string() + " --table " + table);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "amplitude.png"));
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "damping_ratio.png"));
  const std::string t = test::read_text(table);
  EXPECT_NE(t.find("| 0 | "), std::string::npos) << t;
  EXPECT_NE(t.find("| 0.02 | "), std::string::npos) << t;
  // The steady state under a harmonic load, with the one-mode oscillator beside it.
  const auto h = test::run_shell(
      std::string("cd ") + ISOFLEX_SOURCE_DIR + " && /usr/bin/python3 tools/damping_study.py " +
      "examples/viscoelastic_beam_periodic/model.yaml --etas 0.08 --t-end 8 --forcing 3.39 " +
      "--periods 2 --sdof 3.583,5.193e-3 --isoflex " + ISOFLEX_BINARY + " --outdir " +
      dir.path().string() + " --table " + table);
  ASSERT_EQ(h.code, 0) << h.out;
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "steady_state.png"));
  EXPECT_NE(test::read_text(table).find("| 0.08 | "), std::string::npos);
  EXPECT_EQ(test::run_shell("/usr/bin/python3 " + std::string(ISOFLEX_SOURCE_DIR) +
                            "/tools/damping_study.py /no/such.yaml --etas 0")
                .code,
            2);
}
