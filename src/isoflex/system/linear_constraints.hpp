#pragma once
// Linear conditions on the coordinates of a system, the form Dirichlet conditions take
// (docs/theory/kl-static.md §2): eliminated coordinates x_i = X_i + ū_i(t) and multiplier rows
// C (x − X) = d(t) with a constant C. The static solver (integrate/static_newton.hpp) removes the
// eliminated coordinates from its unknowns and borders its matrix with C.
#include <Eigen/SparseCore>
#include <functional>
#include <string>
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

  int multipliers() const { return static_cast<int>(C.rows()); }
  // Adds an eliminated dof (keeps the list sorted; a dof already eliminated is replaced).
  void eliminate(int dof, std::function<double(double)> value = {});
};

// Full ↔ reduced dofs.
struct DofMap {
  int n_full = 0;
  std::vector<int> free;          // free full indices, ascending
  std::vector<int> full_to_free;  // −1 for eliminated dofs
  static DofMap build(int n_full, const std::vector<int>& eliminated);
  int n_free() const { return static_cast<int>(free.size()); }
};

}  // namespace isoflex::system
