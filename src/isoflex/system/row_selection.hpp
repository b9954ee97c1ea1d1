#pragma once
// The independent rows of a sparse constraint Jacobian (the loop-closing rows of a model,
// IGA-thesis Alg. 5.1). Up to kDenseEntries entries, by the dense factorizations of the whole
// matrix (solve::independent_rows_lu, solve::independent_rows_qr). Beyond, block by block: rows
// that share no column are independent of each other, so the rank-revealing factorizations run
// on the connected components of the rows' column graph — for Kirchhoff–Love couplings one small
// block per triple or interface instead of one dense matrix of all rows × all coordinates (a
// many-patch part: thousands of rows × 10⁵ coordinates). Full pivoting does not mix components
// and the rank thresholds are taken relative to the largest pivot of all blocks, as the whole
// matrix's factorization does, so the rank is the same; among rows that depend on each other the
// one dropped can differ (a tie decided by round-off), the span of the kept rows cannot.
#include <Eigen/SparseCore>
#include <vector>

#include "isoflex/math/types.hpp"

namespace isoflex::system {

struct IndependentRows {
  std::vector<int> rows;  // by full-pivot LU (solve::independent_rows_lu), sorted
  int rank_qr = 0;        // the rank by column-pivoted QR of Gᵀ (solve::independent_rows_qr)
};

constexpr double kDenseEntries = 4e6;  // 32 MB as a dense matrix

IndependentRows independent_rows(const Eigen::SparseMatrix<double>& G, double threshold = 1e-10);
// The rows of several groups chosen together (the AF-BS interfaces' rows, IGA-thesis Alg. 5.1):
// group after group, its rows projected off the span of the rows kept so far in the groups
// connected to it through shared columns, then by full-pivot LU of the projection the counts[g]
// rows of the largest pivots, or (counts[g] < 0) all independent ones, whose number is written back
// to counts[g]. Groups that share no column are chosen as by themselves; where they do (interfaces
// meeting at a corner), a row that the kept rows of an earlier group imply is not kept again.
// Returns per group the chosen rows (indices into its rows), sorted.
std::vector<std::vector<int>> select_group_rows(
    const std::vector<Eigen::SparseMatrix<double>>& groups, std::vector<int>& counts);

// The block path alone (tests; qr_rank false: rank_qr not computed, 0). Also the Kirchhoff–Love
// supports' slope rows at any size (KLBoundaryConditions): each touches one or two control
// points, so their blocks are tiny, where one dense LU of all of them (2 308 rows at 10⁶
// unknowns, memory-bound) made `isoflex check` of the quarter roof take 73 s instead of 41 s.
IndependentRows independent_rows_by_blocks(const Eigen::SparseMatrix<double>& G,
                                           double threshold = 1e-10, bool qr_rank = true);

}  // namespace isoflex::system
