#pragma once
// `isoflex check` and `isoflex run --static` for a model with a Kirchhoff–Love shell
// (integrate::KLShellAnalysis): the counts of the patch and the load-stepping solve with its
// outputs (docs/model-files.md "kl_shells", "Outputs").
#include <cstdio>
#include <filesystem>
#include <string>

#include "isoflex/integrate/kl_shell_analysis.hpp"
#include "isoflex/model/model.hpp"

namespace isoflex::app {

// The shell's counts after `surface` lines: control points, DOFs, eliminated components,
// multipliers, unknowns, elements, quadrature points and the reference data per point.
void print_kl_check(const integrate::KLShellAnalysis& a, std::FILE* out);

// Runs the static analysis; writes history.csv, probes.csv, vtk/ + results.pvd and summary.json
// to outdir. Returns 0, or 3 when Newton fails (results up to the last load step are kept).
int run_kl_static(const std::string& model_file, const model::Model& m,
                  const integrate::KLShellAnalysis& a, const std::filesystem::path& outdir,
                  std::FILE* out, std::FILE* err);

}  // namespace isoflex::app
