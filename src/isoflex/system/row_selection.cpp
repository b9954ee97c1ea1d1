#include "isoflex/system/row_selection.hpp"

#include <Eigen/LU>
#include <Eigen/QR>
#include <algorithm>
#include <iterator>
#include <numeric>

#include "isoflex/solve/linear_solver.hpp"

namespace isoflex::system {

namespace {

// Union–find over the rows.
int root(std::vector<int>& parent, int i) {
  while (parent[static_cast<std::size_t>(i)] != i)
    i = parent[static_cast<std::size_t>(i)] =
        parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
  return i;
}

struct Block {
  std::vector<int> rows, cols;
};

}  // namespace

IndependentRows independent_rows_by_blocks(const Eigen::SparseMatrix<double>& G, double threshold,
                                           bool qr_rank) {
  IndependentRows out;
  const int m = static_cast<int>(G.rows());
  if (m == 0 || G.cols() == 0) return out;
  std::vector<int> parent(static_cast<std::size_t>(m));
  std::iota(parent.begin(), parent.end(), 0);
  std::vector<std::vector<int>> col_rows(static_cast<std::size_t>(G.cols()));
  for (int k = 0; k < G.outerSize(); ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(G, k); it; ++it)
      if (it.value() != 0.0) col_rows[static_cast<std::size_t>(it.col())].push_back(it.row());
  for (const auto& rows : col_rows)
    for (std::size_t i = 1; i < rows.size(); ++i)
      parent[static_cast<std::size_t>(root(parent, rows[i]))] = root(parent, rows[0]);
  std::vector<int> block_of(static_cast<std::size_t>(m), -1);
  std::vector<Block> blocks;
  for (int r = 0; r < m; ++r) {
    int& b = block_of[static_cast<std::size_t>(root(parent, r))];
    if (b < 0) {
      b = static_cast<int>(blocks.size());
      blocks.emplace_back();
    }
    blocks[static_cast<std::size_t>(b)].rows.push_back(r);
  }
  for (int c = 0; c < static_cast<int>(col_rows.size()); ++c) {
    const auto& rows = col_rows[static_cast<std::size_t>(c)];
    if (!rows.empty())
      blocks[static_cast<std::size_t>(block_of[static_cast<std::size_t>(root(parent, rows[0]))])]
          .cols.push_back(c);
  }
  // Each block dense, factorized; the pivots judged against the largest of all blocks.
  std::vector<Eigen::FullPivLU<MatX>> lus;
  std::vector<Eigen::ColPivHouseholderQR<MatX>> qrs;
  double lu_max = 0.0, qr_max = 0.0;
  for (const Block& b : blocks) {
    if (b.cols.empty()) {  // a zero row (Eigen's decompositions assert on empty matrices)
      lus.emplace_back();
      if (qr_rank) qrs.emplace_back();
      continue;
    }
    MatX D = MatX::Zero(static_cast<Eigen::Index>(b.rows.size()),
                        static_cast<Eigen::Index>(b.cols.size()));
    for (std::size_t j = 0; j < b.cols.size(); ++j)
      for (Eigen::SparseMatrix<double>::InnerIterator it(G, b.cols[j]); it; ++it) {
        const auto i = std::lower_bound(b.rows.begin(), b.rows.end(), it.row()) - b.rows.begin();
        D(i, static_cast<Eigen::Index>(j)) = it.value();
      }
    lus.emplace_back(D);
    lu_max = std::max(lu_max, std::abs(lus.back().maxPivot()));
    if (!qr_rank) continue;
    qrs.emplace_back(MatX(D.transpose()));
    qr_max = std::max(qr_max, std::abs(qrs.back().maxPivot()));
  }
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    const Block& b = blocks[k];
    if (b.cols.empty()) continue;  // zero rows: dependent
    const auto& lu = lus[k];
    int rank = 0;
    for (Eigen::Index i = 0; i < lu.nonzeroPivots(); ++i)
      if (std::abs(lu.matrixLU()(i, i)) > threshold * lu_max) ++rank;
    const auto& p = lu.permutationP().indices();
    for (std::size_t i = 0; i < b.rows.size(); ++i)
      if (p(static_cast<Eigen::Index>(i)) < rank) out.rows.push_back(b.rows[i]);
    if (!qr_rank) continue;
    const auto& qr = qrs[k];
    for (Eigen::Index i = 0; i < qr.nonzeroPivots(); ++i)
      if (std::abs(qr.matrixQR()(i, i)) > threshold * qr_max) ++out.rank_qr;
  }
  std::sort(out.rows.begin(), out.rows.end());
  return out;
}

IndependentRows independent_rows(const Eigen::SparseMatrix<double>& G, double threshold) {
  if (static_cast<double>(G.rows()) * static_cast<double>(G.cols()) > kDenseEntries)
    return independent_rows_by_blocks(G, threshold);
  const MatX D(G);
  return {solve::independent_rows_lu(D, threshold),
          static_cast<int>(solve::independent_rows_qr(D, threshold).size())};
}

std::vector<std::vector<int>> select_group_rows(
    const std::vector<Eigen::SparseMatrix<double>>& groups, std::vector<int>& counts) {
  using SpMat = Eigen::SparseMatrix<double>;
  using SpRow = Eigen::SparseVector<double>;
  std::vector<std::vector<SpRow>> kept(groups.size());  // per group, the rows kept
  std::vector<std::vector<int>> group_columns(groups.size());
  for (std::size_t g = 0; g < groups.size(); ++g)
    for (int c = 0; c < groups[g].outerSize(); ++c)
      if (SpMat::InnerIterator(groups[g], c)) group_columns[g].push_back(c);
  // Groups connected through shared columns (interfaces meeting at corners, and on through the
  // grid): a dependency among rows may run through any group of the component.
  std::vector<std::size_t> component(groups.size());
  std::iota(component.begin(), component.end(), std::size_t{0});
  const auto root = [&](std::size_t g) {
    while (component[g] != g) g = component[g] = component[component[g]];
    return g;
  };
  for (std::size_t a = 0; a < groups.size(); ++a)
    for (std::size_t b = a + 1; b < groups.size(); ++b) {
      std::vector<int> common;
      std::set_intersection(group_columns[a].begin(), group_columns[a].end(),
                            group_columns[b].begin(), group_columns[b].end(),
                            std::back_inserter(common));
      if (!common.empty()) component[root(a)] = root(b);
    }
  std::vector<std::vector<int>> out(groups.size());
  for (std::size_t g = 0; g < groups.size(); ++g) {
    const SpMat& G = groups[g];
    const std::vector<int>& columns = group_columns[g];
    std::vector<const SpRow*> near;
    for (std::size_t h = 0; h < g; ++h)
      if (root(h) == root(g))
        for (const SpRow& r : kept[h]) near.push_back(&r);
    // The union of the columns, and G and the near kept rows dense over it.
    std::vector<int> all = columns;
    for (const SpRow* r : near)
      for (SpRow::InnerIterator it(*r); it; ++it) all.push_back(static_cast<int>(it.index()));
    std::sort(all.begin(), all.end());
    all.erase(std::unique(all.begin(), all.end()), all.end());
    const auto at = [&](int c) {
      return static_cast<Eigen::Index>(std::lower_bound(all.begin(), all.end(), c) - all.begin());
    };
    MatX D = MatX::Zero(G.rows(), static_cast<Eigen::Index>(all.size()));
    for (int c : columns)
      for (SpMat::InnerIterator it(G, c); it; ++it) D(it.row(), at(c)) = it.value();
    // The rank threshold stays relative to the rows before the projection: where they nearly lie
    // in the kept rows' span, the projection is round-off, and a threshold relative to its own
    // largest pivot would keep it (9 "independent" rows of 4 triples on a flat 3 × 3 plate with
    // clamped edges, and a singular Newton matrix).
    double threshold = 1e-10;
    if (!near.empty()) {
      const double before = D.cwiseAbs().maxCoeff();
      MatX K = MatX::Zero(static_cast<Eigen::Index>(near.size()), D.cols());
      for (std::size_t i = 0; i < near.size(); ++i)
        for (SpRow::InnerIterator it(*near[i]); it; ++it)
          K(static_cast<Eigen::Index>(i), at(static_cast<int>(it.index()))) = it.value();
      const Eigen::ColPivHouseholderQR<MatX> qr(K.transpose());
      const MatX Q = MatX(qr.householderQ()).leftCols(qr.rank());
      D -= (D * Q) * Q.transpose();
      const double after = D.cwiseAbs().maxCoeff();
      threshold = after > 1e-10 * before ? 1e-10 * before / after : 1.0;
    }
    std::vector<int>& chosen = out[g];
    if (counts[g] < 0) {
      chosen = threshold < 1.0 ? solve::independent_rows_lu(D, threshold) : std::vector<int>{};
      counts[g] = static_cast<int>(chosen.size());
    } else {
      chosen = solve::leading_rows_lu(D, counts[g]);
    }
    std::sort(chosen.begin(), chosen.end());
    const Eigen::SparseMatrix<double, Eigen::RowMajor> R = G;  // its rows as sparse vectors
    for (int i : chosen) kept[g].push_back(R.row(i));
  }
  return out;
}

}  // namespace isoflex::system
