#pragma once
// The outputs of one run, fed with every snapshot: history.csv, probes.csv, resultants.csv, the
// VTK series, results.h5 (as the model's `output` asks) and the progress bar. The VTK series of an
// earlier run into the same folder (results.pvd, vtk/*.vtu) is removed first, whether or not this
// run writes one. A file that cannot be written (or removed) is an io::OutputError (exit code 4),
// also from the constructor; finish() closes every output even after one of them failed, so
// that each leaves complete files.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "isoflex/integrate/snapshot.hpp"
#include "isoflex/model/model.hpp"

namespace isoflex::integrate {
struct State;
}
namespace isoflex::io {
struct ResultsFileRun;
class Hdf5ResultsWriter;
}  // namespace isoflex::io

namespace isoflex::app {

class RunOutputs {
 public:
  // Opens the files in `outdir`; the progress bar goes to `progress` (shown on a terminal only).
  // `results_file`: what results.h5 records beyond the model (needed when output.hdf5 is on).
  RunOutputs(const std::filesystem::path& outdir, const model::Model& m, std::FILE* progress,
             const io::ResultsFileRun* results_file = nullptr);

  // Passes `s` to every output, and `state`, the integrator state it is of, to results.h5;
  // throws io::OutputError.
  void snapshot(const integrate::Snapshot& s, const integrate::State* state = nullptr);

  // Finishes every output (the last snapshot of the VTK series, results.pvd); the messages of
  // the io::OutputErrors on the way, if any.
  std::vector<std::string> finish();

 private:
  std::vector<std::unique_ptr<integrate::Observer>> observers_;
  io::Hdf5ResultsWriter* hdf5_ = nullptr;  // in observers_
};

}  // namespace isoflex::app
