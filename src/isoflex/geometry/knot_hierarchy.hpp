#pragma once
// The nested spline spaces behind geometric multigrid on NURBS patches (docs/theory/solvers.md
// §4): a coarser knot vector whose spline space lies inside the given one, and the matrix that
// writes the coarse B-splines in the fine ones (knot insertion, The NURBS Book §5.2–5.3, which
// is exact: S_coarse ⊂ S_fine when the coarse knots are a sub-multiset of the fine ones).
#include <Eigen/SparseCore>
#include <optional>

#include "isoflex/geometry/knot_vector.hpp"

namespace isoflex::geometry {

// Every other interior knot of multiplicity one removed (the knots of higher multiplicity, where
// the geometry has its own joints, are kept): about half the spans. nullopt if no knot can be
// removed.
std::optional<KnotVector> coarsen(const KnotVector& fine);

// A (n_fine × n_coarse) with N^coarse_i = Σ_j A_ji N^fine_j. The degree must be the same and the
// coarse knots a sub-multiset of the fine ones (std::invalid_argument otherwise).
Eigen::SparseMatrix<double> knot_insertion_matrix(const KnotVector& coarse, const KnotVector& fine);

}  // namespace isoflex::geometry
