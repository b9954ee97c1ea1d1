// The nested spline spaces of geometric multigrid (geometry/knot_hierarchy.hpp): the coarsened
// knot vector, and the knot-insertion matrix checked against the B-spline bases themselves.
#include <gtest/gtest.h>

#include <random>

#include "isoflex/geometry/knot_hierarchy.hpp"
#include "isoflex/math/types.hpp"
#include "support/geometry.hpp"

using namespace isoflex;
using geometry::KnotVector;

TEST(KnotHierarchy, CoarseningDropsEveryOtherSimpleKnotAndKeepsRepeatedOnes) {
  // Degree 3; interior knots 0.1 … 0.9 simple, 0.5 double (a joint of the geometry).
  const KnotVector fine(3,
                        {0, 0, 0, 0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.5, 0.6, 0.7, 0.8, 0.9, 1, 1, 1, 1});
  const auto coarse = geometry::coarsen(fine);
  ASSERT_TRUE(coarse);
  const std::vector<double> expected{0, 0, 0, 0, 0.2, 0.4, 0.5, 0.5, 0.7, 0.9, 1, 1, 1, 1};
  EXPECT_EQ(coarse->knots(), expected);
  // Nothing left to drop: no coarser vector.
  EXPECT_FALSE(geometry::coarsen(KnotVector(2, {0, 0, 0, 0.5, 0.5, 1, 1, 1})));
  EXPECT_FALSE(geometry::coarsen(KnotVector::open_uniform(3, 1)));
}

// N^coarse_i(u) = Σ_j A_ji N^fine_j(u) at points all over the domain, to round-off, for every
// degree and for two coarsenings in a row.
TEST(KnotHierarchy, InsertionMatrixWritesTheCoarseBasisInTheFineOne) {
  std::mt19937 g(5);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  for (int p = 1; p <= 5; ++p) {
    const KnotVector fine = KnotVector::open_uniform(p, 23);
    const KnotVector mid = *geometry::coarsen(fine);
    const KnotVector coarse = *geometry::coarsen(mid);
    const Eigen::SparseMatrix<double> A = geometry::knot_insertion_matrix(mid, fine);
    const Eigen::SparseMatrix<double> B = geometry::knot_insertion_matrix(coarse, mid);
    ASSERT_EQ(A.rows(), fine.n_basis());
    ASSERT_EQ(A.cols(), mid.n_basis());
    double worst = 0.0;
    for (int k = 0; k < 200; ++k) {
      const double u = k == 0 ? 0.0 : k == 1 ? 1.0 : u01(g);
      const VecX Nf = test::all_basis_functions(fine, u), Nm = test::all_basis_functions(mid, u),
                 Nc = test::all_basis_functions(coarse, u);
      worst = std::max(worst, (VecX(A.transpose() * Nf) - Nm).cwiseAbs().maxCoeff());
      worst = std::max(worst, (VecX((A * B).transpose() * Nf) - Nc).cwiseAbs().maxCoeff());
    }
    EXPECT_LT(worst, 1e-13) << "degree " << p;
    // Each column is non-negative and sums to 1 (partition of unity on both sides).
    const VecX sums = VecX::Ones(A.rows()).transpose() * A;
    for (Eigen::Index i = 0; i < A.cols(); ++i) EXPECT_GT(sums(i), 0.0);
    EXPECT_LT((VecX(A * VecX::Ones(A.cols())) - VecX::Ones(A.rows())).cwiseAbs().maxCoeff(), 1e-14);
  }
}

TEST(KnotHierarchy, InsertionMatrixRefusesWhatIsNotASubspace) {
  const KnotVector fine = KnotVector::open_uniform(3, 8);
  EXPECT_THROW(geometry::knot_insertion_matrix(KnotVector::open_uniform(2, 4), fine),
               std::invalid_argument);
  // 1/3 is not a knot of the fine vector (spans of 1/8).
  EXPECT_THROW(
      geometry::knot_insertion_matrix(KnotVector(3, {0, 0, 0, 0, 1.0 / 3, 1, 1, 1, 1}), fine),
      std::invalid_argument);
}

TEST(KnotHierarchy, LowerDegreeKeepsTheBreakpointsAndTheJointsOfTheGeometry) {
  const KnotVector fine(3,
                        {0, 0, 0, 0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.5, 0.6, 0.7, 0.8, 0.9, 1, 1, 1, 1});
  const auto coarse = geometry::lower_degree(fine);
  ASSERT_TRUE(coarse);
  EXPECT_EQ(coarse->degree(), 2);
  // The double knot (C¹ at degree 3) simple at degree 2 (C¹ still); the simple ones stay simple.
  const std::vector<double> expected{0, 0, 0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1, 1, 1};
  EXPECT_EQ(coarse->knots(), expected);
  // A C⁰ joint (3-fold at degree 3) stays C⁰ (2-fold at degree 2).
  const auto joint = geometry::lower_degree(KnotVector(3, {0, 0, 0, 0, 0.5, 0.5, 0.5, 1, 1, 1, 1}));
  EXPECT_EQ(joint->knots(), (std::vector<double>{0, 0, 0, 0.5, 0.5, 1, 1, 1}));
  EXPECT_FALSE(geometry::lower_degree(KnotVector(0, {0, 0.5, 1})));
}

// The lower-degree space is not inside the fine one, but every polynomial of degree < p is in both,
// and the transfer reproduces it: Σ_j (A c)_j N^fine_j = Σ_i c_i N^coarse_i wherever the coarse
// function is such a polynomial, on uneven knots with a joint, for every degree. Each fine
// coefficient comes from one span (at most p coarse functions).
TEST(KnotHierarchy, DegreeTransferReproducesThePolynomialsOfLowerDegree) {
  std::mt19937 g(11);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  for (int p = 2; p <= 5; ++p) {
    std::vector<double> knots(static_cast<std::size_t>(p) + 1, 0.0);
    for (double u : {0.07, 0.13, 0.3, 0.41, 0.5, 0.5, 0.66, 0.8, 0.93}) knots.push_back(u);
    knots.insert(knots.end(), static_cast<std::size_t>(p) + 1, 1.0);
    const KnotVector fine(p, knots);
    const KnotVector coarse = *geometry::lower_degree(fine);
    const Eigen::SparseMatrix<double> A = geometry::degree_transfer_matrix(coarse, fine);
    ASSERT_EQ(A.rows(), fine.n_basis());
    ASSERT_EQ(A.cols(), coarse.n_basis());
    const Eigen::SparseMatrix<double, Eigen::RowMajor> rows = A;
    for (int j = 0; j < fine.n_basis(); ++j) EXPECT_LE(rows.row(j).nonZeros(), p) << "row " << j;
    // A polynomial of degree p − 1 with random coefficients, its coarse coefficients by least
    // squares at 200 points (exact: it is in that space).
    VecX a(p);
    for (int k = 0; k < p; ++k) a(k) = u01(g) - 0.5;
    const auto poly = [&](double u) {
      double s = 0.0;
      for (int k = p - 1; k >= 0; --k) s = s * u + a(k);
      return s;
    };
    const int nc = coarse.n_basis();
    MatX V(200, nc);
    VecX y(200);
    for (int k = 0; k < 200; ++k) {
      const double u = (k + 0.5) / 200;
      V.row(k) = test::all_basis_functions(coarse, u).transpose();
      y(k) = poly(u);
    }
    const VecX c = V.colPivHouseholderQr().solve(y);
    ASSERT_LT((V * c - y).cwiseAbs().maxCoeff(), 1e-13) << "degree " << p;
    const VecX d = A * c;
    double worst = 0.0;
    for (int k = 0; k < 100; ++k) {
      const double u = k == 0 ? 0.0 : k == 1 ? 1.0 : u01(g);
      worst = std::max(worst, std::abs(test::all_basis_functions(fine, u).dot(d) - poly(u)));
    }
    EXPECT_LT(worst, 1e-12) << "degree " << p;
  }
  EXPECT_THROW(geometry::degree_transfer_matrix(KnotVector::open_uniform(2, 4),
                                                KnotVector::open_uniform(3, 8)),
               std::invalid_argument);
  EXPECT_THROW(geometry::degree_transfer_matrix(KnotVector::open_uniform(3, 8),
                                                KnotVector::open_uniform(3, 8)),
               std::invalid_argument);
}
