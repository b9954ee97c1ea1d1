#pragma once
// Linear conditions on the coordinates of a system, the form Dirichlet conditions take
// (docs/theory/kl-static.md §2): eliminated coordinates x_i = X_i + ū_i(t), multiplier rows
// C (x − X) = d(t) with a constant C, and tied rows Σ a_j (x_j − X_j) = 0 eliminated by
// master–slave substitution (AF-D's G¹ rows on straight triples, IGA-thesis (5.36)). The static
// solver (integrate/static_newton.hpp) removes the eliminated and the slave coordinates from its
// unknowns (x = X + T u_r + prescribed, its matrix Tᵀ K T) and borders its matrix with C.
#include <Eigen/SparseCore>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "isoflex/math/types.hpp"

namespace isoflex::system {

// Dirichlet conditions on the full dofs: eliminated dofs and multiplier rows.
struct LinearConstraints {
  // Eliminated dofs, sorted and unique, and their prescribed displacements ū_i(t) (same length;
  // an empty function means 0, the homogeneous condition).
  std::vector<int> eliminated;
  std::vector<std::function<double(double)>> eliminated_value;
  // Multiplier rows C (x − X) = d(t): C is m × n (constant), d(t) ∈ R^m (empty function: 0).
  Eigen::SparseMatrix<double> C;
  std::function<VecX(double)> rhs;
  // Labels of the multiplier rows (for messages), optional.
  std::vector<std::string> row_labels;
  // Per row of C (optional; missing entries false): d_i(t) ≡ 0, a homogeneous row (the slope rows
  // of symmetry planes and clamps), which a solver may eliminate as a tied row instead of giving
  // it a multiplier (the static solver does for its PETSc solvers, docs/theory/solvers.md §7).
  std::vector<bool> homogeneous;
  // Tied rows: each a list of (dof, a_j) with Σ a_j (x_j − X_j) = 0. Independent or not: the
  // DofMap picks a slave per row and drops the rows that the others imply.
  std::vector<std::vector<std::pair<int, double>>> tied;

  int multipliers() const { return static_cast<int>(C.rows()); }
  bool is_homogeneous(int row) const {
    return static_cast<std::size_t>(row) < homogeneous.size() &&
           homogeneous[static_cast<std::size_t>(row)];
  }
  // Adds an eliminated dof (keeps the list sorted; a dof already eliminated is replaced).
  void eliminate(int dof, std::function<double(double)> value = {});
};

// Full ↔ reduced dofs: x_i − X_i = Σ_j T_ij u_j + (prescribed), T the identity on the free dofs
// and, on a slave, the combination of free and eliminated dofs that its tied rows give.
struct DofMap {
  struct Slave {
    int dof;
    std::vector<std::pair<int, double>> terms;  // (full dof, free or eliminated; coefficient)
  };
  int n_full = 0;
  std::vector<int> free;          // free full indices, ascending
  std::vector<int> full_to_free;  // −1 for eliminated and slave dofs
  std::vector<Slave> slaves;      // by dof
  int dropped_tied_rows = 0;      // tied rows implied by the others (or by the eliminated dofs)

  // Gaussian elimination of the tied rows over the dofs not eliminated, row by row with the
  // largest remaining coefficient as the pivot (partial pivoting); a row whose remaining
  // coefficients are round-off (≤ 1e-12 of its largest) is implied by the others and dropped.
  // Throws std::invalid_argument for a dof outside [0, n_full).
  static DofMap build(int n_full, const std::vector<int>& eliminated,
                      const std::vector<std::vector<std::pair<int, double>>>& tied = {});
  int n_free() const { return static_cast<int>(free.size()); }
  // x's slave entries from its free and eliminated ones (X the reference).
  void set_slaves(VecX& x, const VecX& X) const;
  // Tᵀ r on the free dofs: a slave's entry added to its free terms with their coefficients.
  VecX reduce(const VecX& r) const;
  // The reduced dofs (free index, weight) that full dof i stands for: {(f, 1)} when free, its
  // free terms when a slave, none when eliminated.
  std::vector<std::pair<int, double>> expansion(int i) const;
};

}  // namespace isoflex::system
