#include "isoflex/app/run_outputs.hpp"

#include "isoflex/app/progress.hpp"
#include "isoflex/io/hdf5_results.hpp"
#include "isoflex/io/history_writer.hpp"
#include "isoflex/io/output_error.hpp"
#include "isoflex/io/vtk_writer.hpp"

namespace isoflex::app {

namespace {

// The VTK series of an earlier run into the same folder: results.pvd and vtk/*.vtu. Left there,
// ParaView would show its later steps after a shorter run's, or the whole old series after a run
// without VTK output. Other files are the user's.
void remove_earlier_vtk_series(const std::filesystem::path& outdir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  std::vector<fs::path> stale;
  if (fs::is_regular_file(outdir / "results.pvd", ec)) stale.push_back(outdir / "results.pvd");
  if (fs::is_directory(outdir / "vtk", ec)) {
    for (fs::directory_iterator it(outdir / "vtk", ec), end; !ec && it != end; it.increment(ec)) {
      const std::string name = it->path().filename().string();
      if (name.ends_with(".vtu")) stale.push_back(it->path());
    }
    if (ec) throw io::OutputError(outdir / "vtk", ec.message(), "list");
  }
  for (const auto& p : stale)
    if (!fs::remove(p, ec) && ec) throw io::OutputError(p, ec.message(), "remove");
}
}  // namespace

RunOutputs::RunOutputs(const std::filesystem::path& outdir, const model::Model& m,
                       std::FILE* progress, const io::ResultsFileRun* results_file) {
  remove_earlier_vtk_series(outdir);
  if (m.output.history) {  // history.csv, probes.csv, resultants.csv, forces.csv, reactions.csv
    observers_.push_back(std::make_unique<io::HistoryWriter>(outdir, m));
    observers_.push_back(std::make_unique<io::ProbeWriter>(outdir, m));
    observers_.push_back(std::make_unique<io::ResultantsWriter>(outdir, m));
    observers_.push_back(std::make_unique<io::ForcesWriter>(outdir, m));
    if (m.output.reactions) observers_.push_back(std::make_unique<io::ReactionsWriter>(outdir, m));
  }
  if (m.output.vtk_every > 0)
    observers_.push_back(
        std::make_unique<io::VtkSeriesWriter>(outdir, m, m.output.vtk_every, m.output.vtk_format));
  if (m.output.hdf5) {
    auto w = std::make_unique<io::Hdf5ResultsWriter>(
        outdir, m, results_file ? *results_file : io::ResultsFileRun{});
    hdf5_ = w.get();
    observers_.push_back(std::move(w));
  }
  const bool by_path = m.solver.analysis == model::Analysis::statics &&
                       m.solver.path.method == model::PathMethod::displacement;
  observers_.push_back(
      by_path ? std::make_unique<ProgressBar>(m.solver.t_end, m.solver.path.displacement, progress)
              : std::make_unique<ProgressBar>(m.solver.t_end, progress));
}

void RunOutputs::snapshot(const integrate::Snapshot& s, const integrate::State* state) {
  if (hdf5_) hdf5_->set_state(state);
  for (auto& ob : observers_) ob->on_snapshot(s);
}

std::vector<std::string> RunOutputs::finish() {
  std::vector<std::string> errors;
  for (auto& ob : observers_) {
    try {
      ob->on_finish();
    } catch (const io::OutputError& e) {
      errors.push_back(e.what());
    }
  }
  return errors;
}

}  // namespace isoflex::app
