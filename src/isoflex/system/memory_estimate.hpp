#pragma once
// The memory a model needs, estimated from the model alone, before System::compile allocates
// anything of its size (issue #15: 10⁶ beam elements took 5.5 GB in `check`; a factorization
// that does not fit ended in std::bad_alloc). Conservative, not exact: it counts the large
// structures of a run, each from the sizes the model states, and the fill of the sparse
// factorization from a fit to CHOLMOD's and UMFPACK's own counts (docs/memory.md, with the
// measurements that set the constants). `isoflex check` prints it; check and run refuse a model
// whose estimate exceeds the memory available (or --max-memory).
#include <string>
#include <vector>

#include "isoflex/model/model.hpp"

namespace isoflex::system {

// One entry of the model (a Kirchhoff–Love shell, a beam, a director shell, the bodies) and what
// it costs, in bytes.
struct MemoryPart {
  std::string what;  // the model key: "kl_shells[0]", "beams[1]", "shells[0]", "bodies"
  model::Source source;
  std::string detail;        // "243 x 243 control points, 1.5 M quadrature points"
  double unknowns = 0;       // coordinates it adds (a Newton matrix row each)
  double data_bytes = 0;     // nodes, elements, quadrature data, vectors over q
  double matrix_bytes = 0;   // the sparse matrices (stiffness, mass, Newton matrix, copies)
  double factor_bytes = 0;   // the sparse LU of the Newton matrix
  double compile_bytes = 0;  // of the above, what System::compile allocates (`check`)
  double nnz = 0;            // non-zeros of its stiffness pattern
  double bytes() const { return data_bytes + matrix_bytes + factor_bytes; }
};

struct MemoryEstimate {
  std::vector<MemoryPart> parts;
  double base_bytes = 0;  // the process itself (libraries, small model parts)
  // What factor_bytes is: the sparse LU of the direct solvers, or nothing of its own on the
  // PETSc path (a static run with an iterative solver: docs/memory.md), where the matrix bytes
  // hold the preconditioner.
  std::string factor_label = "sparse LU";
  double total() const;    // what a run needs
  double compile() const;  // what `check` needs (no factorization, no Newton matrix)
  double unknowns() const;
  // The part with the most bytes (nullptr if there is none): where a refusal points.
  const MemoryPart* largest() const;
  // "177 147 unknowns: sparse LU ≈ 5.7 GB, sparse matrices ≈ 1.3 GB, data ≈ 0.6 GB"
  std::string breakdown() const;
};

MemoryEstimate estimate_memory(const model::Model& model);

// A structured director-shell mesh of nu × nv elements (the model reader checks it before it
// builds the mesh's nodes): the same count as estimate_memory's part for it.
MemoryPart director_shell_grid(double nu, double nv);

// Bytes in binary units as people read them: "512 MB", "4.3 GB", "31 GB" (1 GB = 2³⁰ bytes,
// the unit of free(1) -h and /proc/meminfo's kB).
std::string format_bytes(double bytes);

}  // namespace isoflex::system
