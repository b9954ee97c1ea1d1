// system::independent_rows (row_selection.hpp): the loop-row selection by connected blocks gives
// exactly the rows and the QR rank of the dense factorizations of the whole matrix
// (solve::independent_rows_lu, solve::independent_rows_qr), on matrices of several blocks with
// dependent rows, a zero row, a block of small entries (the threshold is the whole matrix's) and
// columns in no block.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>
#include <string>

#include "isoflex/integrate/static_equilibrium.hpp"
#include "isoflex/io/model_reader.hpp"
#include "isoflex/solve/linear_solver.hpp"
#include "isoflex/system/row_selection.hpp"
#include "isoflex/system/system.hpp"
#include "support/finite_difference.hpp"
#include "support/kl_plate_grid.hpp"

using namespace isoflex;

namespace {

// Blocks of 3 rows over 4 private columns each (row 2 = row 0 + row 1 in every second block),
// block 1 scaled by `small`, one zero row, and 5 untouched columns; rows shuffled.
MatX blocky(std::mt19937& g, int blocks, double small) {
  const int m = 3 * blocks + 1, n = 4 * blocks + 5;
  MatX G = MatX::Zero(m, n);
  for (int b = 0; b < blocks; ++b) {
    const double s = b == 1 ? small : 1.0;
    for (int i = 0; i < 2; ++i) G.row(3 * b + i).segment(4 * b, 4) = s * test::random_vector(g, 4);
    G.row(3 * b + 2).segment(4 * b, 4) =
        b % 2 == 0 ? VecX(G.row(3 * b).segment(4 * b, 4) + G.row(3 * b + 1).segment(4 * b, 4))
                   : VecX(s * test::random_vector(g, 4));
  }
  std::vector<int> order(static_cast<std::size_t>(m));
  for (int i = 0; i < m; ++i) order[static_cast<std::size_t>(i)] = i;
  std::shuffle(order.begin(), order.end(), g);
  MatX P(m, n);
  for (int i = 0; i < m; ++i) P.row(i) = G.row(order[static_cast<std::size_t>(i)]);
  return P;
}

}  // namespace

// The rank of the selected rows of G.
int rank_of(const MatX& G, const std::vector<int>& rows) {
  MatX S(rows.size(), G.cols());
  for (std::size_t i = 0; i < rows.size(); ++i) S.row(static_cast<int>(i)) = G.row(rows[i]);
  return static_cast<int>(solve::independent_rows_lu(S).size());
}

TEST(RowSelection, BlocksGiveTheWholeMatrixSelection) {
  std::mt19937 g(17);
  for (double small : {1.0, 1e-6, 1e-12}) {
    const MatX G = blocky(g, 6, small);
    const system::IndependentRows r = system::independent_rows_by_blocks(G.sparseView());
    const std::vector<int> dense = solve::independent_rows_lu(G);
    EXPECT_EQ(r.rows.size(), dense.size()) << "small " << small;
    EXPECT_EQ(rank_of(G, r.rows), static_cast<int>(r.rows.size())) << "small " << small;
    EXPECT_EQ(r.rank_qr, static_cast<int>(solve::independent_rows_qr(G).size()))
        << "small " << small;
    // Below the dense limit the dispatch is the dense selection itself.
    EXPECT_EQ(system::independent_rows(G.sparseView()).rows, dense);
  }
  EXPECT_EQ(system::independent_rows_by_blocks(blocky(g, 6, 1.0).sparseView()).rows.size(),
            6u * 3u - 3u);
  // Independent rows: the very rows of the dense factorization.
  MatX F = MatX::Zero(8, 20);
  for (int i = 0; i < 8; ++i) F.row(i).segment(2 * i, 4) = test::random_vector(g, 4);
  EXPECT_EQ(system::independent_rows_by_blocks(F.sparseView()).rows, solve::independent_rows_lu(F));
  EXPECT_TRUE(system::independent_rows(Eigen::SparseMatrix<double>(0, 3)).rows.empty());
}

// AF-BS (strip_constraints) rows are chosen together (system::select_group_rows): where four
// patches meet at an inner corner, the rows of the interfaces there depend on each other through
// the corner triples (a 2 × 2 grid: 27 independent together, 28 apart), which a per-interface
// selection could not see — its Newton matrix was singular (the first correction 10¹⁶ times the
// residual). A flat plate of 3 × 3 patches under pressure, nonlinear, clamped: AF-BS converges
// and gives AF-D's deflection (both hold the flat interfaces' slopes) and the one patch's.
TEST(RowSelection, StripConstraintsAtInnerCornersAreChosenTogether) {
  const auto plate = [](int pu, const std::string& coupling) {
    test::PlateGrid g;
    g.pu = g.pv = pu;
    g.coupling = coupling;
    g.centre_probe = true;
    return test::plate_grid_yaml(g);
  };
  const auto centre = [&](int pu, const std::string& coupling) {
    const model::Model m = io::read_model_string(plate(pu, coupling), "m.yaml");
    const auto sys = system::System::compile(m);
    integrate::StaticEquilibrium eq(sys, m.solver);
    const VecX q = eq.solve().x.head(sys.n());
    return sys.probe_point(q, sys.probes()[0]).z();
  };
  const double af_bs = centre(3, "strip_constraints"), af_d = centre(3, "angle"),
               one = centre(1, "");
  std::printf(
      "  [AF-BS] 3 x 3 patches: centre deflection AF-BS %.12g, AF-D %.12g, one patch %.12g\n",
      af_bs, af_d, one);
  EXPECT_LT(af_bs, -1e-4);
  EXPECT_LT(std::abs(af_bs - af_d), 1e-5 * std::abs(af_d));  // measured 1.1e-6
  EXPECT_LT(std::abs(af_bs - one), 1e-5 * std::abs(one));    // measured 9.1e-7
}

// The first load step starts at the reference and takes the rows System::compile chose there
// (ReselectedGroup::reference_rows) instead of choosing again: the same rows as a new choice with
// the reference counts (the rank leading pivots of the same factorizations).
TEST(RowSelection, ReferenceChoiceIsTheChoiceAtTheReference) {
  test::PlateGrid g;
  g.pu = 4;
  g.pv = 3;
  g.elements = 12;
  g.coupling = "strip_constraints";
  const model::Model m = io::read_model_string(test::plate_grid_yaml(g), "m.yaml");
  const auto sys = system::System::compile(m);
  ASSERT_EQ(sys.reselected_groups().size(), 17u);
  std::vector<int> counts;
  std::vector<std::vector<int>> reference;
  for (const auto& group : sys.reselected_groups()) {
    counts.push_back(group.rank);
    reference.push_back(group.reference_rows);
    EXPECT_EQ(static_cast<int>(group.reference_rows.size()), group.rank);
  }
  EXPECT_EQ(system::select_group_rows(sys.reselected_group_jacobians(sys.q0()), counts), reference);
}
