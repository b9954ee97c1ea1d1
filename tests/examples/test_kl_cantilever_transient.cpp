// examples/kl_cantilever_transient (IGA-thesis §6.4.1.5, Fig. 6.15): a cantilever plate under the
// transient corner loads (6.15). Implicit Euler, as in the thesis, damps the swing numerically and
// the plate comes to rest at the static deflection under the final load; the energy–momentum
// scheme keeps energy = work of the corner loads to round-off, through the sine waves and the
// step; tools/transient_error_study.py measures the L² error against a refined solution, smaller
// for the higher degree at the same element size.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "isoflex/integrate/initial_equilibrium.hpp"
#include "isoflex/io/model_reader.hpp"
#include "support/cli.hpp"
#include "support/examples.hpp"
#include "support/files.hpp"
#include "support/geometry.hpp"
#include "support/sanitizers.hpp"
#include "support/trajectory.hpp"

using namespace isoflex;

namespace {

void report(const char* what, double v) {
  std::printf("  [kl-cantilever-transient] %-44s %.6g\n", what, v);
  ::testing::Test::RecordProperty(what, test::sci(v));
}

// The example with probes at the two loaded corners as well.
model::Model cantilever() {
  return io::read_model_string(
      test::replaced(test::example_text("kl_cantilever_transient", "model.yaml"),
                     "  - {name: tip, shell: plate, point: [10, 0.5, 0]}",
                     "  - {name: tip, shell: plate, point: [10, 0.5, 0]}\n"
                     "  - {name: a, shell: plate, point: [10, 0, 0]}\n"
                     "  - {name: b, shell: plate, point: [10, 1, 0]}"),
      "model.yaml");
}

// f(t) of (6.15), per corner.
double corner_load(double t) {
  return t <= 10.0 ? 2.0 * std::sin(test::kPi * t / 5.0) : 2.0;
}

}  // namespace

// Implicit Euler's numerical damping (ζ ≈ ωΔt/2 for the first mode) brings the plate to rest by
// t = 70 at the static equilibrium under 2 + 2 at the corners: a large deflection (tip 6.42 up on
// a length of 10).
TEST(KLCantileverTransient, ImplicitEulerComesToRestAtTheStaticDeflection) {
  ISOFLEX_SKIP_LONG_RUN_UNDER_ASAN();
  const model::Model m = cantilever();
  const test::Trajectory r = test::simulate(m);
  ASSERT_EQ(r.snapshots.size(), 701u);
  EXPECT_EQ(r.unknowns, 108);  // printed by `isoflex check` for the example

  model::Model s = m;
  for (auto& load : s.kl_loads) load.force[2] = "2";
  s.solver.initial_equilibrium = 20;
  const auto sys = system::System::compile(s);
  const Vec3 rest = sys.probe_point(integrate::initial_equilibrium(s).q, sys.probes().front());
  const Vec3 end = r.probe("tip").back();
  EXPECT_GT(rest.z(), 5.0);                         // nonlinear: far beyond the plate's thickness
  EXPECT_LT((end - rest).norm(), 1e-3 * rest.z());  // measured 2.9e-5
  EXPECT_LT(r.snapshots.back().kinetic_energy, 1e-3 * r.snapshots.back().potential_energy);
  report("static tip z under 2 + 2", rest.z());
  report("implicit Euler at t = 70: |tip - static| / z", (end - rest).norm() / rest.z());
}

// The energy–momentum scheme applies the corner loads at t_{n+½} to the midpoint configuration:
// E_{n+1} − E_n = f(t_{n+½}) e_z · (Δx_a + Δx_b) exactly, so E minus the summed work vanishes to
// round-off — through the sine waves and after the step to the constant load at t = 10.
TEST(KLCantileverTransient, EnergyMomentumEnergyIsTheWorkOfTheLoads) {
  model::Model m = cantilever();
  m.solver.integrator = model::Integrator::energy_momentum;
  m.solver.t_end = 14.0;
  const test::Trajectory r = test::simulate(m);
  const auto& s = r.snapshots;
  const std::vector<Vec3> a = r.probe("a"), b = r.probe("b");
  double work = 0.0, worst = 0.0, largest = 0.0;
  for (std::size_t i = 1; i < s.size(); ++i) {
    const double f = corner_load(0.5 * (s[i - 1].t + s[i].t));
    work += f * ((a[i] - a[i - 1]).z() + (b[i] - b[i - 1]).z());
    worst = std::max(worst, std::abs(s[i].total_energy - s[0].total_energy - work));
    largest = std::max(largest, std::abs(s[i].total_energy));
  }
  EXPECT_LT(worst, 1e-10 * largest);
  report("EM: max |E - E0 - W| / max E", worst / largest);
}

// The study script on a small set: p = 2 and 3 at h = 2.5 against p = 4 with 8 elements, two
// integrators, 3 s. The higher degree has the smaller error.
TEST(KLCantileverTransient, ErrorStudyScript) {
  ISOFLEX_SKIP_LONG_RUN_UNDER_ASAN();
  const test::TempDir dir(test::temp_dir("isoflex_", "transient_error"));
  const std::string table = (dir.path() / "table.md").string();
  const auto r = test::run_shell(
      std::string("cd ") + ISOFLEX_SOURCE_DIR +
      " && /usr/bin/python3 tools/transient_error_study.py "
      "examples/kl_cantilever_transient/model.yaml --degrees 2,3 --reference 4,8 --integrators "
      "bdf1,energy_momentum --gauss 8,3,2 --t-end 3 --isoflex " +
      ISOFLEX_BINARY + " --outdir " + dir.path().string() + " --table " + table);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "l2_error.png"));
  EXPECT_EQ(
      test::read_text((dir.path() / "l2_error.csv").string()).rfind("integrator,p,t,l2_error\n", 0),
      0u);
  // | integrator | p | elements | unknowns | max e(t) | e(t_end) | Newton it. | wall (s) |
  std::istringstream in(test::read_text(table));
  std::vector<double> max_error;
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> cell;
    std::istringstream cells(line);
    for (std::string c; std::getline(cells, c, '|');) cell.push_back(c);
    if (cell.size() > 5 && cell[2].find("reference") == std::string::npos &&
        (cell[5].find("e-") != std::string::npos || cell[5].find("e+") != std::string::npos))
      max_error.push_back(std::stod(cell[5]));
  }
  ASSERT_EQ(max_error.size(), 4u) << test::read_text(table);
  EXPECT_LT(max_error[1], max_error[0]);  // bdf1: p = 3 below p = 2
  EXPECT_LT(max_error[3], max_error[2]);  // energy_momentum
  EXPECT_EQ(test::run_shell("/usr/bin/python3 " + std::string(ISOFLEX_SOURCE_DIR) +
                            "/tools/transient_error_study.py " + ISOFLEX_SOURCE_DIR +
                            "/examples/kl_cantilever_transient/model.yaml --degrees 0")
                .code,
            2);
}
