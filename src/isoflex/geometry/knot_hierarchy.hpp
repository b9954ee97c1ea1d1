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

// p-multigrid (docs/theory/solvers.md §4): the same breakpoints at degree p − 1, an interior knot
// of multiplicity m ≥ 2 kept (m − 1)-fold (the same continuity C^{p−m}), a simple one kept simple
// (C^{p−2} where the fine space is C^{p−1}). nullopt for degree 0.
std::optional<KnotVector> lower_degree(const KnotVector& fine);

// The lower-degree space is not inside the fine one (its functions are C^{p−2} at simple knots),
// so no matrix writes it there exactly: A (n_fine × n_coarse) maps a coarse coefficient vector c
// to fine coefficients by a local projection. Fine coefficient j is that of the fine polynomial
// equal to Σ c_i N^coarse_i on one span of N_j's support (the middle one; degree p − 1 < p, so it
// is one), its coefficient in the p + 1 B-splines of that span. A reproduces exactly every coarse
// function that is also a fine one, polynomials of degree < p on the domain among them (a NURBS
// patch's geometry where it came from one such piece, hence its rigid motions). The breakpoints
// must be the same (std::invalid_argument otherwise).
Eigen::SparseMatrix<double> degree_transfer_matrix(const KnotVector& coarse,
                                                   const KnotVector& fine);

}  // namespace isoflex::geometry
