// A program built against the installed isoflex package (CMakeLists.txt beside it).
//
//   isoflex_consumer MODEL T_END   runs the model's time steps up to T_END as `isoflex run` does
//                                  (app/commands.cpp) and prints the last state: a line
//                                  `energy,t,kinetic,potential,total` (the first columns of
//                                  history.csv) and one `probe,` line per probe (a probes.csv row)
//   isoflex_consumer --cad FILE    reads a CAD file through the installed import module and prints
//                                  `patches N` and `module PATH`, the module that was loaded
//
// Numbers as the run's CSV files write them ({:.17g}), so that the test compares text.
#include <fmt/format.h>
#include <link.h>

#include <cmath>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

#include "isoflex/integrate/energy_momentum.hpp"
#include "isoflex/integrate/time_integrator.hpp"
#include "isoflex/io/cad/cad_reader.hpp"
#include "isoflex/io/model_reader.hpp"
#include "isoflex/system/system.hpp"

namespace {

using namespace isoflex;

int run(const std::string& file, double t_end) {
  model::Model m = io::read_model(file);
  m.solver.t_end = t_end;
  const system::System sys = system::System::compile(m);
  const auto integrator = integrate::make_time_integrator(sys, m.solver);
  // As `isoflex run` sets it: the energy–momentum schemes' Newton start depends on it.
  integrator->set_joint_reactions(m.output.history && m.output.reactions &&
                                  !(m.joints.empty() && m.kl_surface_joints.empty()));
  integrate::State state = integrator->initial_state();
  integrate::StepStats stats;
  const long steps = std::lround(t_end / m.solver.dt);
  for (long i = 0; i < steps; ++i) stats = integrator->step(state);

  const integrate::Snapshot s = integrate::snapshot(sys, state, stats, {});
  fmt::print("energy,{:.17g},{:.17g},{:.17g},{:.17g}\n", s.t, s.kinetic_energy, s.potential_energy,
             s.total_energy);
  for (const integrate::ProbeValue& p : s.probes) {
    const Vec3 &x = p.position, &u = p.displacement, &v = p.velocity;
    fmt::print(
        "probe,{:.17g},{},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g}"
        "\n",
        s.t, p.name, x.x(), x.y(), x.z(), u.x(), u.y(), u.z(), v.x(), v.y(), v.z());
  }
  return 0;
}

// The file the dynamic loader opened for the CAD import module ("" if none is loaded).
std::string loaded_module() {
  std::string path;
  dl_iterate_phdr(
      [](dl_phdr_info* info, size_t, void* out) {
        if (std::strstr(info->dlpi_name, "libisoflex_cad_occt")) {
          *static_cast<std::string*>(out) = info->dlpi_name;
          return 1;
        }
        return 0;
      },
      &path);
  return path;
}

int read_cad(const std::string& file) {
  const io::CadModel cad = io::read_cad(file);
  fmt::print("patches {}\nmodule {}\n", cad.patches.size(), loaded_module());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  try {
    if (args.size() == 2 && args[0] == "--cad") return read_cad(args[1]);
    if (args.size() == 2) return run(args[0], std::stod(args[1]));
  } catch (const std::exception& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return 1;
  }
  fmt::print(stderr, "usage: isoflex_consumer MODEL T_END | isoflex_consumer --cad FILE\n");
  return 2;
}
