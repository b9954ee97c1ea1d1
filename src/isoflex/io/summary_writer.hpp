#pragma once
// summary.json: the facts of one run (sizes, effort, accuracy, final probe values), written by hand
// as JSON. Doubles are written with 17 significant digits; NaN and ±inf become null.
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "isoflex/integrate/snapshot.hpp"

namespace isoflex::io {

struct RunSummary {
  std::string model;
  std::vector<std::string> set;  // the --set KEY=VALUE of the run, in order (written if any)
  std::string formulation;
  int n_coordinates = 0;
  int n_constraints = 0;
  int n_unknowns = 0;
  int n_redundant_constraints = 0;
  int steps = 0;
  int newton_iterations_total = 0;
  // Energy–momentum runs: Newton starts that failed before another converged (in the iterations
  // above; integrate::StepStats::failed_starts).
  std::optional<int> newton_failed_starts;
  // Time integration: steps taken in parts because Newton failed on the whole step
  // (solver.max_subdivisions; integrate::StepStats::substeps > 1).
  std::optional<int> subdivided_steps;
  double dt = 0.0;
  double t_end = 0.0;
  double wall_time_s = 0.0;
  int threads = 1;  // threads the element assembly ran on (Kirchhoff–Love shells; 1 otherwise)
  // Why fewer threads ran than `--threads` asked for, when it asked for more than one.
  std::optional<std::string> threads_note;
  // A run on several MPI ranks (mpirun -n N, N > 1; docs/theory/solvers.md §6): N.
  std::optional<int> mpi_ranks;
  double max_constraint_violation = 0.0;
  double energy_initial = 0.0;
  double energy_final = 0.0;
  // max |E − E_ref| / |E_ref| after the last load has ceased (NaN when not applicable)
  double max_energy_drift_after_loads = 0.0;
  // Written only when set: the work of the viscous forces (a model with material damping; the
  // drift above is then that of energy + dissipated energy), and the load steps of the static
  // equilibrium the run started from (solver.initial_equilibrium).
  std::optional<double> dissipated_energy;
  std::optional<double> external_work;  // a dynamic run with loads: their work since t = 0
  std::optional<double> driver_work;    // a dynamic run with joint drivers: their work since t = 0
  std::optional<int> initial_equilibrium_load_steps;
  // A dynamic run: the relative change ‖v₀ − v_given‖/max(1, ‖v_given‖) of the initial twists by
  // their projection onto the velocities the joints admit (0: the given ones were admissible).
  std::optional<double> initial_velocity_projection;
  // A static run whose saddle-point systems went to the augmented Lagrangian
  // (solver.saddle_point_solver): its GMRES iterations in all, and the solves that fell back to
  // the sparse LU.
  std::optional<int> krylov_iterations_total;
  std::optional<int> saddle_point_fallbacks;
  // A static run with a PETSc solver (solver.linear_solver): its name, and the solves that fell
  // back to the direct solvers (krylov_iterations_total counts its CG iterations).
  std::optional<std::string> linear_solver;
  std::optional<int> linear_solver_fallbacks;
  // A restarted run (isoflex run --restart FILE --from-step N): FILE and N.
  std::optional<std::string> restart_file;
  int restart_from_step = 0;
  std::vector<integrate::ProbeValue> probes;
  // "completed"; "failed" (Newton), "output_error" (a file could not be written), "interrupted"
  // (SIGINT, SIGTERM): README "Exit codes"
  std::string status = "completed";
  std::string message;  // why the run ended early; empty when completed
};

// Writes `s` as a JSON object to `file` atomically (temporary file, then rename).
// Throws io::OutputError when the file cannot be written.
void write_summary_json(const std::filesystem::path& file, const RunSummary& s);

// The JSON text written by write_summary_json.
std::string summary_json(const RunSummary& s);

// `text` as a JSON string literal, quotes included.
std::string json_string(std::string_view text);

// Writes `content` to `file.tmp`, then renames it to `file`, so that readers see either the old
// or the new complete file. Creates missing parent directories. Throws io::OutputError (naming
// `file`, not the temporary file, which is removed).
void write_file_atomic(const std::filesystem::path& file, std::string_view content);

}  // namespace isoflex::io
