// Kirchhoff–Love patches in the ParaView series of a dynamic run (io::VtkSeriesWriter): a patch
// file vtk/<shell>_NNNNNN.vtu per written step, listed in results.pvd as part 1 of the step's
// time, with the tessellated deformed patch of io::kl_shell_vtu; and kl_shell_vtu itself.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <regex>
#include <string>
#include <vector>

#include "isoflex/geometry/quadrature.hpp"
#include "isoflex/integrate/energy_momentum.hpp"
#include "isoflex/io/kl_shell_vtk.hpp"
#include "isoflex/io/model_reader.hpp"
#include "isoflex/io/vtk_writer.hpp"
#include "isoflex/system/kl_model.hpp"
#include "support/cli.hpp"
#include "support/files.hpp"
#include "support/vtu.hpp"

namespace fs = std::filesystem;
using namespace isoflex;
using test::data_array;
using test::read_text;
using test::xml_error;

namespace {

// A free 1 × 0.5 plate, bicubic, 2 × 1 elements, pushed up by a growing area force (the probe's
// displacement grows as t³/3 · 2 m/s³, 4·10⁻⁵ at t = 0.05).
constexpr const char* kPlate = R"(solver: {dt: 0.01, t_end: 0.05}
output: {vtk_every: 1}
surfaces:
  - name: sheet
    builtin: {type: rectangle, size: [1, 0.5]}
    refine: {elevate: [2, 2], knots_per_span: [1, 0]}
kl_shells:
  - {name: plate, surface: sheet, material: {E: 1.0e4, nu: 0.3, thickness: 0.05, density: 1000}}
kl_loads:
  - {shell: plate, area_force: [0, 0, "100*t"]}
probes:
  - {name: corner, shell: plate, point: [1, 0.5, 0]}
)";

class TempDir : public test::TempDir {
 public:
  TempDir() : test::TempDir(fs::temp_directory_path() / ("isoflex_" + current_test())) {}

 private:
  static std::string current_test() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    return std::string(info->test_suite_name()) + "_" + info->name();
  }
};

model::Model plate_model() {
  return io::read_model_string(kPlate, "m.yaml");
}

// The snapshots of the initial state and the five steps of the plate.
const std::vector<integrate::Snapshot>& plate_run() {
  static const std::vector<integrate::Snapshot> run = [] {
    const model::Model m = plate_model();
    const auto sys = system::System::compile(m);
    const integrate::EnergyMomentumIntegrator integ(sys, m.solver);
    auto s = integ.initial_state();
    std::vector<integrate::Snapshot> out;
    for (int i = 0; i <= 5; ++i) {
      const auto st = i == 0 ? integrate::StepStats{} : integ.step(s);
      out.push_back(integ.snapshot(s, st, {}));
    }
    return out;
  }();
  return run;
}

// The plate's snapshots fed to a writer with `every`, then on_finish.
void write_series(const fs::path& dir, int every, int per_span = io::kKLShellQuadsPerSpan,
                  model::VtkFormat format = model::VtkFormat::binary) {
  io::VtkSeriesWriter w(dir, plate_model(), every, format, per_span);
  for (const auto& s : plate_run()) w.on_snapshot(s);
  w.on_finish();
}

struct PvdEntry {
  double t;
  int part;
  std::string file;
};

std::vector<PvdEntry> pvd_entries(const std::string& pvd) {
  const std::regex ds(R"re(<DataSet timestep="([^"]*)" group="" part="(\d+)" file="([^"]*)"/>)re");
  std::vector<PvdEntry> out;
  for (std::sregex_iterator it(pvd.begin(), pvd.end(), ds), end; it != end; ++it)
    out.push_back({std::stod((*it)[1]), std::stoi((*it)[2]), (*it)[3]});
  return out;
}

// The integer attribute `name` of the file's <Piece>.
long piece_attribute(const std::string& xml, const std::string& name) {
  const auto at = xml.find(name + "=\"", xml.find("<Piece"));
  if (at == std::string::npos) return -1;
  return std::stol(xml.substr(at + name.size() + 2));
}

std::vector<Vec3> vec3_array(const std::string& xml, const std::string& name) {
  const std::vector<double> v = data_array(xml, name);
  std::vector<Vec3> out;
  for (std::size_t k = 0; k + 2 < v.size(); k += 3) out.emplace_back(v[k], v[k + 1], v[k + 2]);
  return out;
}

geometry::NurbsSurface with_points(geometry::NurbsSurface s, const VecX& x) {
  for (std::size_t k = 0; k < s.points.size(); ++k)
    s.points[k] = x.segment<3>(3 * static_cast<int>(k));
  return s;
}

}  // namespace

// every = 2 over steps 0…5: patch files at steps 0, 2, 4 and the last one (5), each right after
// its step file in files() and in results.pvd as part 1 with the step's time.
TEST(KLSeries, PatchFilesOfTheWrittenStepsArePart1OfTheCollection) {
  TempDir dir;
  const auto& run = plate_run();
  ASSERT_EQ(run.size(), 6u);
  ASSERT_EQ(run.back().kl_patches.size(), 1u);
  std::vector<std::string> files;
  {
    io::VtkSeriesWriter w(dir.path(), plate_model(), 2, model::VtkFormat::binary);
    for (const auto& s : run) w.on_snapshot(s);
    w.on_finish();
    files = w.files();
  }
  const std::vector<std::string> expected = {
      "vtk/step_000000.vtu", "vtk/plate_000000.vtu", "vtk/step_000002.vtu", "vtk/plate_000002.vtu",
      "vtk/step_000004.vtu", "vtk/plate_000004.vtu", "vtk/step_000005.vtu", "vtk/plate_000005.vtu"};
  EXPECT_EQ(files, expected);
  for (const auto& f : expected) {
    SCOPED_TRACE(f);
    EXPECT_TRUE(fs::is_regular_file(dir.path() / f));
    EXPECT_EQ(xml_error(read_text(dir.path() / f)), "");
  }
  for (const char* f : {"vtk/plate_000001.vtu", "vtk/plate_000003.vtu"})
    EXPECT_FALSE(fs::exists(dir.path() / f)) << f;

  const std::string pvd = read_text(dir.path() / "results.pvd");
  EXPECT_EQ(xml_error(pvd), "");
  const auto entries = pvd_entries(pvd);
  ASSERT_EQ(entries.size(), expected.size());
  const int steps[] = {0, 2, 4, 5};
  for (std::size_t k = 0; k < entries.size(); ++k) {
    SCOPED_TRACE(entries[k].file);
    EXPECT_EQ(entries[k].file, expected[k]);
    EXPECT_EQ(entries[k].part, static_cast<int>(k % 2));
    // {:.17g} reads back exactly.
    EXPECT_EQ(entries[k].t, run[steps[k / 2]].t);
  }
  EXPECT_GT(entries.back().t, 0.0);
}

// At step 0 the displacement is exactly zero; at every written step the points are the deformed
// surface at their parameters, the displacement that point minus the reference one, and at the
// probe's material point (the corner) the probe's displacement and position, to round-off.
TEST(KLSeries, DisplacementIsTheSurfaceMinusTheReferenceAndTheProbes) {
  TempDir dir;
  write_series(dir.path(), 1);
  const auto& run = plate_run();
  const model::Model m = plate_model();
  const geometry::NurbsSurface& ref = system::kl_surface(m, m.kl_shells.front());

  const std::string first = read_text(dir.path() / "vtk/plate_000000.vtu");
  const auto u0 = data_array(first, "displacement");
  ASSERT_FALSE(u0.empty());
  for (const double u : u0) EXPECT_EQ(u, 0.0);
  // The corner's point: the sample nearest to the probe's reference point.
  const std::vector<Vec3> reference = vec3_array(first, "Points");
  std::size_t corner = 0;
  for (std::size_t i = 0; i < reference.size(); ++i)
    if ((reference[i] - Vec3(1, 0.5, 0)).norm() < (reference[corner] - Vec3(1, 0.5, 0)).norm())
      corner = i;
  ASSERT_LT((reference[corner] - Vec3(1, 0.5, 0)).norm(), 1e-14);

  for (const auto& s : run) {
    SCOPED_TRACE(s.step);
    const std::string xml = read_text(dir.path() / fmt::format("vtk/plate_{:06d}.vtu", s.step));
    const auto points = vec3_array(xml, "Points");
    const auto u = vec3_array(xml, "displacement");
    const auto par = data_array(xml, "parameters");
    ASSERT_EQ(u.size(), points.size());
    ASSERT_EQ(par.size(), 2 * points.size());
    const geometry::NurbsSurface deformed = with_points(ref, s.kl_patches.front().x);
    for (std::size_t i = 0; i < points.size(); ++i) {
      const double xi = par[2 * i], eta = par[2 * i + 1];
      const Vec3 x = geometry::evaluate(deformed, xi, eta).x;
      const Vec3 X = geometry::evaluate(ref, xi, eta).x;
      EXPECT_LT((points[i] - x).norm(), 1e-14) << i;
      EXPECT_LT((u[i] - (x - X)).norm(), 1e-14) << i;
    }
    const auto& probe = s.probes.front();
    EXPECT_LT((u[corner] - probe.displacement).norm(), 1e-14);
    EXPECT_LT((points[corner] - probe.position).norm(), 1e-14);
    if (s.step == 5) {
      EXPECT_GT(u[corner].z(), 3e-5);  // the plate has moved
    }
  }
}

// n × n quads per knot span: (n·e_u + 1)(n·e_v + 1) points and n²·e_u·e_v VTK_QUADs for the
// e_u × e_v = 2 × 1 elements of the plate, for the default n = 4 and for n = 2.
TEST(KLSeries, PointsAndCellsAreTheTessellation) {
  const model::Model m = plate_model();
  const geometry::NurbsSurface& ref = system::kl_surface(m, m.kl_shells.front());
  const long eu = static_cast<long>(geometry::span_elements(ref.u).size());
  const long ev = static_cast<long>(geometry::span_elements(ref.v).size());
  ASSERT_EQ(eu, 2);
  ASSERT_EQ(ev, 1);
  for (const int n : {io::kKLShellQuadsPerSpan, 2}) {
    SCOPED_TRACE(n);
    TempDir dir;
    write_series(dir.path(), 5, n);
    for (const char* f : {"vtk/plate_000000.vtu", "vtk/plate_000005.vtu"}) {
      SCOPED_TRACE(f);
      const std::string xml = read_text(dir.path() / f);
      const long points = (n * eu + 1) * (n * ev + 1), cells = n * n * eu * ev;
      EXPECT_EQ(piece_attribute(xml, "NumberOfPoints"), points);
      EXPECT_EQ(piece_attribute(xml, "NumberOfCells"), cells);
      EXPECT_EQ(static_cast<long>(data_array(xml, "Points").size()), 3 * points);
      EXPECT_EQ(static_cast<long>(data_array(xml, "displacement").size()), 3 * points);
      EXPECT_EQ(static_cast<long>(data_array(xml, "von_mises_top").size()), points);
      const auto types = data_array(xml, "types");
      ASSERT_EQ(static_cast<long>(types.size()), cells);
      for (const double t : types) EXPECT_EQ(t, io::kVtkQuad);
    }
  }
  EXPECT_EQ(io::kKLShellQuadsPerSpan, 4);
}

// The patch files in binary and in ascii hold the same arrays bit for bit.
TEST(KLSeries, BinaryAndAsciiPatchFilesHoldTheSameArraysBitForBit) {
  TempDir dir;
  write_series(dir.path() / "binary", 2);
  write_series(dir.path() / "ascii", 2, io::kKLShellQuadsPerSpan, model::VtkFormat::ascii);
  for (const char* f : {"vtk/plate_000000.vtu", "vtk/plate_000004.vtu", "vtk/plate_000005.vtu",
                        "vtk/step_000005.vtu"}) {
    SCOPED_TRACE(f);
    const std::string binary = read_text(dir.path() / "binary" / f);
    const std::string ascii = read_text(dir.path() / "ascii" / f);
    EXPECT_EQ(xml_error(binary), "");
    EXPECT_EQ(xml_error(ascii), "");
    EXPECT_NE(binary.find("format=\"appended\""), std::string::npos);
    EXPECT_EQ(binary.find("format=\"ascii\""), std::string::npos);
    EXPECT_EQ(ascii.find("format=\"appended\""), std::string::npos);
    EXPECT_EQ(test::data_arrays_difference(binary, ascii), "");
  }
  EXPECT_EQ(data_array(read_text(dir.path() / "ascii/vtk/plate_000005.vtu"), "Points").size(),
            3u * 9 * 5);  // 2 × 1 elements, 4 × 4 quads each
}

// The patch file is kl_shell_vtu of the snapshot's x with the model's kinematics: the same
// fields as the static analysis writes, and the analysis overload is the patch overload.
TEST(KLSeries, PatchFileIsKLShellVtuWithTheStaticFields) {
  TempDir dir;
  write_series(dir.path(), 5);
  const model::Model m = plate_model();
  const auto patch = system::kl_patch(m, 0, system::kl_surface(m, m.kl_shells[0]));
  const VecX& x = plate_run().back().kl_patches.front().x;
  const std::string expected =
      io::kl_shell_vtu(*patch, system::kl_kinematics(m), x, 4, model::VtkFormat::binary);
  EXPECT_EQ(read_text(dir.path() / "vtk/plate_000005.vtu"), expected);
  const std::vector<std::string> fields = {"parameters",
                                           "displacement",
                                           "n",
                                           "m",
                                           "sigma_top",
                                           "sigma_bottom",
                                           "principal_top",
                                           "principal_bottom",
                                           "von_mises_top",
                                           "von_mises_bottom",
                                           "e1"};
  EXPECT_EQ(test::data_array_names(expected, "PointData"), fields);

  EXPECT_THROW(io::kl_shell_vtu(*patch, elements::KLKinematics::nonlinear, x.head(x.size() - 3), 2,
                                model::VtkFormat::binary),
               std::invalid_argument);
}

// A snapshot without kl_patches writes no patch file and no part 1, also for a model with
// kl_shells; a patch the model does not have, or of the wrong size, is an error.
TEST(KLSeries, NoPatchesNoPatchFilesAndBadPatchesThrow) {
  TempDir dir;
  integrate::Snapshot s = plate_run().front();
  s.kl_patches.clear();
  {
    io::VtkSeriesWriter w(dir.path(), plate_model(), 1, model::VtkFormat::binary);
    w.on_snapshot(s);
    w.on_finish();
    EXPECT_EQ(w.files(), std::vector<std::string>{"vtk/step_000000.vtu"});
  }
  EXPECT_FALSE(fs::exists(dir.path() / "vtk/plate_000000.vtu"));
  EXPECT_EQ(read_text(dir.path() / "results.pvd").find("part=\"1\""), std::string::npos);

  io::VtkSeriesWriter w(dir.path(), plate_model(), 1, model::VtkFormat::binary);
  integrate::Snapshot other = plate_run().front();
  other.kl_patches.front().shell = "sheet";
  EXPECT_THROW(w.on_snapshot(other), std::runtime_error);
  integrate::Snapshot short_x = plate_run().front();
  short_x.kl_patches.front().x.conservativeResize(short_x.kl_patches.front().x.size() - 1);
  EXPECT_THROW(w.on_snapshot(short_x), std::runtime_error);
}

// File stems: the name with characters other than A–Z, a–z, 0–9, _ . - replaced; never "step"
// (the step files) and never another patch's.
TEST(KLSeries, FileStemsAreSafeAndUnique) {
  model::Model m;
  m.kl_shells.resize(4);
  m.kl_shells[0].name = "step";
  m.kl_shells[1].name = "a b/c";
  m.kl_shells[2].name = "a_b_c";
  m.kl_shells[3].name = "Wing-2.left";
  const std::vector<std::string> expected = {"step-0", "a_b_c", "a_b_c-2", "Wing-2.left"};
  EXPECT_EQ(io::kl_patch_file_stems(m), expected);
}

// End to end: `isoflex run` of the plate writes the patch series next to the step files.
TEST(KLSeries, IsoflexRunWritesThePatchSeries) {
  TempDir dir;
  test::write_text(dir.path() / "plate.yaml", kPlate);
  const auto r = test::run_isoflex("run " + (dir.path() / "plate.yaml").string() +
                                   " --t-end 0.02 -o " + (dir.path() / "out").string());
  ASSERT_EQ(r.code, 0) << r.out;
  const auto entries = pvd_entries(read_text(dir.path() / "out/results.pvd"));
  ASSERT_EQ(entries.size(), 6u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(entries[2 * k].file, fmt::format("vtk/step_{:06d}.vtu", k));
    EXPECT_EQ(entries[2 * k + 1].file, fmt::format("vtk/plate_{:06d}.vtu", k));
    EXPECT_EQ(entries[2 * k + 1].part, 1);
    EXPECT_EQ(entries[2 * k + 1].t, entries[2 * k].t);
    EXPECT_TRUE(fs::is_regular_file(dir.path() / "out" / entries[2 * k + 1].file));
  }
}
