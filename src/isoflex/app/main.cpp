// The `isoflex` command line: run, check, cad-info, --version (README "A short tour").
#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>
#include <new>
#include <stdexcept>
#include <utility>
#include <vector>

#include "isoflex/app/cad_info.hpp"
#include "isoflex/app/commands.hpp"
#include "isoflex/app/exit_codes.hpp"
#include "isoflex/solve/memory.hpp"

int main(int argc, char** argv) {
  isoflex::solve::retain_freed_memory();  // repeated large factorizations (solve/memory.hpp)
  CLI::App app{"isoflex — flexible multibody dynamics with energy-momentum integrators"};
  app.set_version_flag("--version", std::string("isoflex ") + ISOFLEX_VERSION);
  app.require_subcommand(1);

  isoflex::app::RunOptions run;
  std::string formulation;
  auto* r = app.add_subcommand("run", "integrate a model and write results");
  r->add_option("MODEL", run.model_file, "model file (YAML)")->required();
  r->add_option("-o,--output", run.outdir, "output directory (default out/<model folder>)");
  r->add_option("--formulation", formulation, "constrained | nullspace | reparametrized")
      ->check(CLI::IsMember({"constrained", "nullspace", "reparametrized"}));
  r->add_option("--dt", run.dt, "time step (overrides the model)");
  r->add_option("--t-end", run.t_end, "end time (overrides the model)");
  r->add_option("--max-subdivisions", run.max_subdivisions,
                "halvings of a step (or load step) whose Newton iteration fails, 0 ... 20 "
                "(overrides solver.max_subdivisions, default 6)")
      ->check(CLI::Range(0, 20));
  r->add_flag("--static", run.statics,
              "static equilibrium at t = dt, 2 dt, ..., t_end (t as a load parameter)");
  std::string run_memory, check_memory;
  const char* memory_help =
      "memory the model may use, e.g. 2G, 512M (K, M, G, T: powers of 1024; default: "
      "MemAvailable of /proc/meminfo); a model estimated to need more is refused";
  r->add_option("--max-memory", run_memory, memory_help);
  r->add_option("--threads", run.threads,
                "threads of the Kirchhoff-Love shell assembly (default 0: all cores; results "
                "are the same for any number; other elements assemble on one, and a run says "
                "so when more were asked for)")
      ->check(CLI::NonNegativeNumber);

  std::vector<std::string> run_set, check_set;
  const char* set_help =
      "KEY=VALUE: a model value over the file's, repeatable; KEY a path like solver.dt, "
      "bodies[0].mass or bodies[crank].mass, VALUE YAML (2, [0, 0, 1], \"sin(t)\")";
  r->add_option("--set", run_set, set_help)->allow_extra_args(false);
  auto* restart = r->add_option("--restart", run.restart_file,
                                "a results.h5 (output.hdf5: true) to continue a run from, at the "
                                "saved step --from-step");
  auto* from_step = r->add_option("--from-step", run.restart_step,
                                  "the step of --restart's file to continue from")
                        ->check(CLI::NonNegativeNumber);
  restart->needs(from_step);
  from_step->needs(restart);
  restart->excludes(r->get_option("--static"));

  std::string check_file;
  auto* c = app.add_subcommand("check", "validate a model and print its counts and joint forest");
  c->add_option("MODEL", check_file, "model file (YAML)")->required();
  c->add_option("--max-memory", check_memory, memory_help);
  c->add_option("--set", check_set, set_help)->allow_extra_args(false);

  std::string cad_file;
  auto* ci = app.add_subcommand("cad-info",
                                "print the NURBS patches of an IGES/STEP file and their "
                                "analysis-suitability checks");
  ci->add_option("FILE", cad_file, "CAD file (.igs, .iges, .stp, .step)")->required();

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }
  if (!formulation.empty()) run.formulation = isoflex::model::formulation_from_string(formulation);
  isoflex::app::CheckOptions check;
  for (auto [texts, target] :
       {std::pair{&run_set, &run.overrides}, std::pair{&check_set, &check.overrides}}) {
    for (const std::string& t : *texts) {
      try {
        target->push_back(isoflex::io::parse_model_override(t));
      } catch (const std::invalid_argument& e) {
        std::fprintf(stderr, "error: %s\n", e.what());
        return isoflex::app::kExitBadInput;
      }
    }
  }
  for (auto [text, target] :
       {std::pair{&run_memory, &run.max_memory}, std::pair{&check_memory, &check.max_memory}}) {
    if (text->empty()) continue;
    *target = isoflex::app::parse_memory_size(*text);
    if (!*target) {
      std::fprintf(stderr,
                   "error: --max-memory: \"%s\" is not a memory size (e.g. 2G, 512M, "
                   "3000000000)\n",
                   text->c_str());
      return isoflex::app::kExitBadInput;
    }
  }
  // The commands report running out of memory themselves (with what they were doing); this is
  // the last guard, so that no std::bad_alloc ends the process uncaught.
  try {
    if (*r) return isoflex::app::run_command(run);
    if (*c) return isoflex::app::check_command(check_file, stdout, stderr, check);
    if (*ci) return isoflex::app::cad_info_command(cad_file, std::cout, std::cerr);
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "error: out of memory (the model needs more than this machine has)\n");
    return isoflex::app::kExitNewtonFailure;
  }
  return 2;
}
