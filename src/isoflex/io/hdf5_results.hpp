#pragma once
// outdir/results.h5 (`output.hdf5: true`): the run's histories and its integrator states in one
// HDF5 file (libhdf5, C API), and the reading of a saved state for `isoflex run --restart`.
//
// Layout (docs/model-files.md "The HDF5 results file"):
//   /                    attributes isoflex_results (the layout's version, 1), model_file,
//                        model_name, analysis ("dynamic", "static", "cosimulation"),
//                        formulation (summary.json's), dt, t_end, n (coordinates),
//                        m (selected constraint rows), energy_initial (the energy at t = 0),
//                        state_every, isoflex_version; a restarted run restart_file and
//                        restart_from_step
//   /history/<column>    1-D, one entry per snapshot: the columns of history.csv
//                        (io::HistoryColumns), the same doubles
//   /probes/<name>/{position,displacement,velocity}   N × 3, per snapshot
//   /resultants/<beam>/{n,m}                          N × E × 3 (E elements), per snapshot
//   /steps/<step, 9 digits>/   the whole integrate::State of that step: the vectors q, v,
//                        last_unknowns, a, aux, lambda, q_prev, v_prev as 1-D datasets (empty
//                        ones of length 0), the scalars step, t, grid_start, grid_dt,
//                        grid_steps, last_dt, last_start, dissipated, external_work, driver_work
//                        as attributes; with the step's newton_iterations and residual (the
//                        history row of the step, recomputed from the state otherwise) and
//                        path (Snapshot::path). Written for the first snapshot, every step
//                        divisible by `state_every` and the last snapshot.
// Doubles are stored as IEEE binary64 (H5T_IEEE_F64LE from H5T_NATIVE_DOUBLE): exact. The
// series are chunked and extended per snapshot; the file is flushed (H5Fflush) after every
// snapshot, so that a run that ends without closing it leaves a file with everything up to the
// last flush. It is not locked (HDF5 1.10.7's H5Pset_file_locking), so that h5py can open it while
// the run writes it; such a read may meet a half-written snapshot.
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "isoflex/integrate/snapshot.hpp"
#include "isoflex/integrate/time_integrator.hpp"
#include "isoflex/model/model.hpp"

namespace isoflex::io {

// The root attributes that the model does not give.
struct ResultsFileRun {
  std::string formulation;      // as summary.json's
  int n = 0, m = 0;             // coordinates and selected constraint rows of the System
  double energy_initial = 0.0;  // the energy at t = 0 (a restarted run: the source's)
  std::string restart_file;     // a restarted run: its source file and step
  int restart_from_step = -1;
};

// Writes outdir/results.h5. Throws io::OutputError naming the file when it cannot be created or
// written (the cause from HDF5's error stack: the system's text where it has one).
class Hdf5ResultsWriter final : public integrate::Observer {
 public:
  Hdf5ResultsWriter(const std::filesystem::path& outdir, const model::Model& m,
                    const ResultsFileRun& run);
  ~Hdf5ResultsWriter() override;
  Hdf5ResultsWriter(const Hdf5ResultsWriter&) = delete;
  Hdf5ResultsWriter& operator=(const Hdf5ResultsWriter&) = delete;

  static constexpr const char* kFileName = "results.h5";

  // The state of the snapshot that comes next (nullptr: none, no /steps group for it); kept
  // until then.
  void set_state(const integrate::State* s) { state_ = s; }
  void on_snapshot(const integrate::Snapshot& s) override;
  // Writes the last snapshot's state if it was not written yet, and closes the file.
  void on_finish() override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  const integrate::State* state_ = nullptr;
};

// A file that cannot serve a restart (missing, not a results file, no such step, a state of
// another size): what() is the complete message, naming the file.
class RestartError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A state read back from a results file, with what the file says about its run.
struct SavedState {
  integrate::State state;
  int newton_iterations = 0;  // of the step (its history row)
  double residual = 0.0;
  double path = 0.0;
  std::string analysis, formulation, model_file;
  int n = 0, m = 0;
  double energy_initial = 0.0, dt = 0.0;
};

// The steps that `file` has a state of, ascending. Throws RestartError.
std::vector<int> saved_steps(const std::filesystem::path& file);

// The state of step `step` in `file` (read whole; the file is closed on return). Throws
// RestartError when the file is missing or not a results file, or has no state of that step
// (the message lists the steps it has).
SavedState read_saved_state(const std::filesystem::path& file, int step);

// "0 … 100 (11 steps: every 10)" or "0, 5, 7": the steps of saved_steps for a message.
std::string describe_steps(const std::vector<int>& steps);

}  // namespace isoflex::io
