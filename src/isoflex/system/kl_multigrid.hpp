#pragma once
// The transfer operators of geometric multigrid over the knot hierarchy of the model's
// Kirchhoff–Love patches (docs/theory/solvers.md §4). The coarse spaces are spline spaces of the
// coarsened knot vectors (geometry/knot_hierarchy.hpp) divided by the fine patch's weight
// function W: a NURBS basis function of the fine patch is R_j = w_j N_j / W, and a coarse one
// N^c_i / W = Σ_j A_ji N_j / W = Σ_j (A_ji / w_j) R_j, so the coarse spaces are nested in the fine
// one exactly (no coarse geometry is needed: the coarse level has no weights of its own).
#include <Eigen/SparseCore>
#include <vector>

namespace isoflex::system {

class System;

// How the first coarse level is made: like the others, by removing knots (h-multigrid), or by
// lowering the patches' degree by one where it is above 2 (p-multigrid; a Kirchhoff–Love patch
// needs C¹ functions), with the knots of the lower degree's coarsenings below it. The lower-degree
// space is not nested in the fine one: P_1 is then the local projection of
// geometry::degree_transfer_matrix, exact for the patch's rigid motions where its geometry is
// one polynomial piece of degree < p (docs/theory/solvers.md §4).
enum class Coarsening { knots, degree_then_knots };

// Whether kl_transfer_operators' first level (if any) lowers a patch's degree: not nested in the
// fine space (integrate::StaticProblem::first_transfer_not_nested).
bool first_level_lowers_degree(const System& sys, Coarsening coarsening);

// P_1 (n × n_1), P_2 (n_1 × n_2), …, the coarsest last: the fine coefficients from the coarse
// ones, x_l = P_{l+1} x_{l+1}. Every coordinate of q that is not a control point of a patch
// passes to each coarse level unchanged (first, in its order), then the coarse points (x, y, z
// each): each patch's coarse control points, those of different patches (or of a seam) that
// interpolate the same values to the fine points they share merged into one, so that the coarse
// space is continuous where the fine one is; a fine point shared by several control points takes
// its row from the first of them. Levels are added while the patches coarsen and the level has more
// than `coarsest_unknowns` unknowns. Empty if no patch coarsens at all.
std::vector<Eigen::SparseMatrix<double>> kl_transfer_operators(
    const System& sys, int coarsest_unknowns = 3000, Coarsening coarsening = Coarsening::knots);

}  // namespace isoflex::system
