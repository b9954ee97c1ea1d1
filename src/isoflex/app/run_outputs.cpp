#include "isoflex/app/run_outputs.hpp"

#include "isoflex/app/progress.hpp"
#include "isoflex/io/history_writer.hpp"
#include "isoflex/io/output_error.hpp"
#include "isoflex/io/vtk_writer.hpp"

namespace isoflex::app {

namespace {
// history.csv's path column of a static run with path following (io/history_writer.hpp).
std::string path_column(const model::Model& m) {
  if (m.solver.analysis != model::Analysis::statics) return {};
  switch (m.solver.path.method) {
    case model::PathMethod::arc_length:
      return "arc_length";
    case model::PathMethod::displacement:
      return "control_displacement";
    case model::PathMethod::load:
      break;
  }
  return {};
}
}  // namespace

RunOutputs::RunOutputs(const std::filesystem::path& outdir, const model::Model& m,
                       std::FILE* progress) {
  if (m.output.history) {  // history.csv, probes.csv, resultants.csv, forces.csv, reactions.csv
    observers_.push_back(
        std::make_unique<io::HistoryWriter>(outdir, model::has_material_damping(m), path_column(m),
                                            model::has_external_loads(m), model::has_drivers(m)));
    observers_.push_back(std::make_unique<io::ProbeWriter>(outdir, m));
    observers_.push_back(std::make_unique<io::ResultantsWriter>(outdir, m));
    observers_.push_back(std::make_unique<io::ForcesWriter>(outdir, m));
    if (m.output.reactions) observers_.push_back(std::make_unique<io::ReactionsWriter>(outdir, m));
  }
  if (m.output.vtk_every > 0)
    observers_.push_back(std::make_unique<io::VtkSeriesWriter>(outdir, m, m.output.vtk_every));
  const bool by_path = m.solver.analysis == model::Analysis::statics &&
                       m.solver.path.method == model::PathMethod::displacement;
  observers_.push_back(
      by_path ? std::make_unique<ProgressBar>(m.solver.t_end, m.solver.path.displacement, progress)
              : std::make_unique<ProgressBar>(m.solver.t_end, progress));
}

void RunOutputs::snapshot(const integrate::Snapshot& s) {
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
