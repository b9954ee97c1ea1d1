// The memory estimate (memory_estimate.hpp). Every constant below is an upper bound of what the
// code allocates per item, or a fit with margin to measured counts; docs/memory.md lists the
// measurements (estimate vs peak resident memory of `isoflex run` and `check`).
#include "isoflex/system/memory_estimate.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "isoflex/elements/beam_element.hpp"
#include "isoflex/elements/director_shell_element.hpp"
#include "isoflex/elements/kl_shell_point.hpp"

namespace isoflex::system {

namespace {

// The process before any model (libraries, the reader, small vectors): measured 25–40 MB.
constexpr double kBaseBytes = 64.0 * (1 << 20);
// Per coordinate of q: q₀, v₀, the states, residuals, Newton increments, snapshots and output
// rows (≈ 25 vectors of doubles).
constexpr double kBytesPerCoordinate = 200.0;
// Per node: its entry, its name ("crank[123]") and the name index of the compile phase.
constexpr double kBytesPerNode = 400.0;
// Per heap object: the allocator's header and the vectors an element owns.
constexpr double kObjectOverhead = 64.0;
// Per non-zero of the stiffness pattern, in all the sparse matrices and their temporaries at
// once, per element kind (the patterns' triplets and maps while compiling, the element's own
// pattern and values, the system's fixed pattern, mass matrices, the Newton matrix and the
// solver's copies while running), set from the measured peaks of `check` and `run` with margin
// (docs/memory.md): measured for a Kirchhoff–Love patch 84–92 B (check) and up to 150 B (run,
// with the 64-bit copy), for a beam 83 B in both, for a director-shell grid 85 B (check).
struct MatrixBytes {
  double compile, run;
};
constexpr MatrixBytes kKLMatrixBytes{100, 170}, kBeamMatrixBytes{100, 120},
    kShellMatrixBytes{100, 140}, kBodyMatrixBytes{200, 200};
// Per entry of the Cholesky factor L that the fit below predicts: UMFPACK's LU holds L and U
// (2.1 × the Cholesky count with its AMD ordering against CHOLMOD's METIS, measured 2.11–2.13 at
// 1.2·10⁴–4.6·10⁴ unknowns) at 9.5 bytes per entry (UMFPACK_PEAK_MEMORY / (lnz + unz)): 20
// bytes; 28 with margin.
constexpr double kFactorBytesPerEntry = 28.0;
// Per non-zero of the stiffness pattern on the PETSc path (docs/theory/solvers.md §3–4), which
// has no factorization of the whole matrix and no 64-bit copy: the matrices as for the direct
// path, less that copy, and the preconditioner (the Galerkin matrices of the coarse levels, about
// a third of the fine one's entries, the smoother's block factors, PETSc's work vectors). Set from
// the peaks of `isoflex run` on the whole Scordelis–Lo roof (bench/large_shells.md): 15.4–16.5 GB
// at 1.0·10⁶ unknowns (1.46·10⁸ entries), 113–121 B per entry with the model data; 130 with margin.
constexpr double kIterativeBytesPerEntry = 130.0;

// Nested dissection of a 2D grid of N nodes with d unknowns per node and coupling reach w (a
// B-spline of degree p couples control points p apart, so a separator is p rows wide): the
// factor has ≈ c (d w)² N (log₂ N − log₂(30 w²)) entries (George 1973 for w = d = 1 up to the
// constant; the subtracted term: below ~30 w² nodes the factor is the dense part). c = 4 bounds
// CHOLMOD's count (cholmod_l_analyze, METIS) for p = 2…5 and N = 6·10²…1.6·10⁵ (fitted c =
// 3.3–3.6; docs/memory.md); never less than the matrix's own lower triangle.
double grid_factor_entries(double N, double d, double w, double nnz) {
  const double levels = std::max(1.0, std::log2(std::max(N, 2.0)) - std::log2(30.0 * w * w));
  return std::max(0.5 * nnz, 4.0 * (d * w) * (d * w) * N * levels);
}

// Basis functions of a 1D B-spline space of n functions of degree p whose supports share a span
// with a given one, summed over all: n (2p + 1) − p (p + 1) with simple interior knots, an upper
// bound otherwise.
double coupled_pairs(double n, double p) {
  return std::max(n, n * (2 * p + 1) - p * (p + 1));
}

std::string count(double x) {
  if (x >= 1e6) return fmt::format("{:.1f} M", x / 1e6);
  return fmt::format("{:.0f}", x);
}

void finish(MemoryPart& part, double coordinates, double nnz, double factor_entries,
            MatrixBytes per_entry, double model_data) {
  part.unknowns = coordinates;
  part.nnz = nnz;
  part.data_bytes += coordinates * kBytesPerCoordinate + model_data;
  part.matrix_bytes = nnz * per_entry.run;
  part.factor_bytes = factor_entries * kFactorBytesPerEntry;
  part.compile_bytes = part.data_bytes + nnz * per_entry.compile;
}

MemoryPart kl_shell(const model::Model& m, std::size_t i, bool dynamic) {
  const model::KLShell& s = m.kl_shells[i];
  MemoryPart part{fmt::format("kl_shells[{}]", i), s.source, "", 0, 0, 0, 0, 0};
  const auto surface = std::find_if(m.surfaces.begin(), m.surfaces.end(),
                                    [&](const model::Surface& f) { return f.name == s.surface; });
  if (surface == m.surfaces.end()) return part;  // a located error of System::compile
  const geometry::NurbsSurface& g = surface->surface;
  const double pu = g.degree_u(), pv = g.degree_v();
  const double nu = g.n_u(), nv = g.n_v(), N = nu * nv;
  const double E = double(g.u.element_spans().size()) * double(g.v.element_spans().size());
  const double qu = s.quadrature[0] > 0 ? s.quadrature[0] : pu + 1;
  const double qv = s.quadrature[1] > 0 ? s.quadrature[1] : pv + 1;
  const double points = E * qu * qv, functions = (pu + 1) * (pv + 1);
  const double nnz = 9.0 * coupled_pairs(nu, pu) * coupled_pairs(nv, pv);
  // Per element: its span record and the loop's entry, the connectivity (4 B per function) and
  // the assembly positions in the pattern (4 B per pair of functions, kl_shell_patch_impl.hpp);
  // per quadrature point the pre-evaluated reference geometry (kl::ReferencePoint), twice in a
  // dynamic run (the mass quadrature).
  part.data_bytes = E * (2 * kObjectOverhead + 4.0 * functions * (functions + 1)) +
                    points * double(sizeof(elements::kl::ReferencePoint)) * (dynamic ? 2 : 1) +
                    N * kBytesPerNode * 0.25;  // point nodes: no names kept per control point
  finish(part, 3 * N, nnz, grid_factor_entries(N, 3, std::max(pu, pv), nnz), kKLMatrixBytes, 0);
  part.detail = fmt::format("{:.0f} x {:.0f} control points, {} elements, {} quadrature points", nu,
                            nv, count(E), count(points));
  return part;
}

MemoryPart beam(const model::Model& m, std::size_t i) {
  const model::Beam& b = m.beams[i];
  MemoryPart part{fmt::format("beams[{}]", i), b.source, "", 0, 0, 0, 0, 0};
  double elements = 0;
  for (int e : b.elements) elements += e;
  const double nodes = elements + 1;
  part.data_bytes =
      nodes * kBytesPerNode + elements * (sizeof(elements::BeamElement) + kObjectOverhead);
  // A chain of frame nodes: 12 × 12 blocks with itself and its two neighbours; the factor of a
  // banded matrix stays in its band: 18 unknowns per node (12 coordinates, 6 internal rows) and
  // a half-bandwidth of two nodes' unknowns.
  const double nnz = 3 * 144 * nodes;
  finish(part, 12 * nodes, nnz, 18 * 36 * nodes, kBeamMatrixBytes, 0);
  part.detail = fmt::format("{} elements, {} frame nodes", count(elements), count(nodes));
  return part;
}

MemoryPart shell_part(double nodes, double elements) {
  MemoryPart part;
  // The model's mesh (points, directors, quads), the nodes and the elements.
  const double mesh = nodes * 48 + elements * 16;
  part.data_bytes =
      nodes * kBytesPerNode + elements * (sizeof(elements::DirectorShellElement) + kObjectOverhead);
  // Director nodes on a grid: 6 × 6 blocks with the 8 neighbours; 7 unknowns per node (the
  // internal row), reach 1.
  const double nnz = 9 * 36 * nodes;
  finish(part, 6 * nodes, nnz, grid_factor_entries(nodes, 7, 1, nnz), kShellMatrixBytes, mesh);
  part.detail = fmt::format("{} elements, {} director nodes", count(elements), count(nodes));
  return part;
}

}  // namespace

MemoryPart director_shell_grid(double nu, double nv) {
  return shell_part((nu + 1) * (nv + 1), nu * nv);
}

namespace {

// Whether a static run solves with a PETSc iterative solver (integrate/static_newton.hpp
// LinearSolverMethod): asked for, or automatic for Kirchhoff–Love patches alone, held by
// eliminated components only (no multiplier or tied rows), from 50 000 unknowns on.
bool iterative_solver(const model::Model& m, const MemoryEstimate& parts) {
  using model::LinearSolver;
  if (m.solver.analysis != model::Analysis::statics) return false;
  switch (m.solver.linear_solver) {
    case LinearSolver::cg_gamg:
    case LinearSolver::cg_hypre:
    case LinearSolver::cg_multigrid:
      return true;
    case LinearSolver::direct:
    case LinearSolver::mumps:
      return false;
    case LinearSolver::automatic:
      break;
  }
  const bool fixed_only =
      std::all_of(m.kl_supports.begin(), m.kl_supports.end(),
                  [](const model::KLSupport& s) { return s.kind == model::KLSupportKind::fixed; });
  return m.kl_shells.size() == 1 && m.bodies.empty() && m.beams.empty() && m.shells.empty() &&
         fixed_only && parts.unknowns() >= 50000;
}

}  // namespace

MemoryEstimate estimate_memory(const model::Model& m) {
  const bool dynamic = m.solver.analysis != model::Analysis::statics;
  MemoryEstimate est;
  est.base_bytes = kBaseBytes;
  for (std::size_t i = 0; i < m.kl_shells.size(); ++i) est.parts.push_back(kl_shell(m, i, dynamic));
  for (std::size_t i = 0; i < m.beams.size(); ++i) est.parts.push_back(beam(m, i));
  for (std::size_t i = 0; i < m.shells.size(); ++i) {
    const model::Shell& s = m.shells[i];
    MemoryPart part = shell_part(s.node_count(), double(s.quads.size()));
    part.what = fmt::format("shells[{}]", i);
    part.source = s.source;
    est.parts.push_back(part);
  }
  if (iterative_solver(m, est)) {
    est.factor_label = "preconditioner";
    for (MemoryPart& p : est.parts) {
      p.matrix_bytes = p.nnz * kIterativeBytesPerEntry;
      p.factor_bytes = 0.0;
    }
  }
  if (!m.bodies.empty()) {
    MemoryPart part;
    part.what = "bodies";
    part.source = m.bodies.front().source;
    const double n = double(m.bodies.size());
    part.data_bytes = n * (kBytesPerNode + 1024);
    finish(part, 12 * n, 144 * n, 18 * 36 * n, kBodyMatrixBytes, 0);
    part.detail = fmt::format("{} rigid bodies", count(n));
    est.parts.push_back(part);
  }
  return est;
}

double MemoryEstimate::total() const {
  double t = base_bytes;
  for (const MemoryPart& p : parts) t += p.bytes();
  return t;
}

double MemoryEstimate::compile() const {
  double t = base_bytes;
  for (const MemoryPart& p : parts) t += p.compile_bytes;
  return t;
}

double MemoryEstimate::unknowns() const {
  double n = 0;
  for (const MemoryPart& p : parts) n += p.unknowns;
  return n;
}

const MemoryPart* MemoryEstimate::largest() const {
  const MemoryPart* best = nullptr;
  for (const MemoryPart& p : parts)
    if (!best || p.bytes() > best->bytes()) best = &p;
  return best;
}

std::string MemoryEstimate::breakdown() const {
  double data = base_bytes, matrices = 0, factor = 0;
  for (const MemoryPart& p : parts) {
    data += p.data_bytes;
    matrices += p.matrix_bytes;
    factor += p.factor_bytes;
  }
  if (factor == 0.0)
    return fmt::format("{} unknowns: sparse matrices and {} {}, model data {}", count(unknowns()),
                       factor_label, format_bytes(matrices), format_bytes(data));
  return fmt::format("{} unknowns: {} {}, sparse matrices {}, model data {}", count(unknowns()),
                     factor_label, format_bytes(factor), format_bytes(matrices),
                     format_bytes(data));
}

std::string format_bytes(double bytes) {
  constexpr double kMB = 1 << 20, kGB = 1 << 30;
  if (bytes >= 10 * kGB) return fmt::format("{:.0f} GB", bytes / kGB);
  if (bytes >= kGB) return fmt::format("{:.1f} GB", bytes / kGB);
  if (bytes >= 10 * kMB) return fmt::format("{:.0f} MB", bytes / kMB);
  return fmt::format("{:.1f} MB", bytes / kMB);
}

}  // namespace isoflex::system
