#include "isoflex/geometry/knot_hierarchy.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "isoflex/geometry/bspline_basis.hpp"
#include "isoflex/geometry/nurbs_curve.hpp"
#include "isoflex/geometry/refinement.hpp"

namespace isoflex::geometry {

std::optional<KnotVector> coarsen(const KnotVector& fine) {
  const std::vector<double>& U = fine.knots();
  const int p = fine.degree();
  std::vector<double> kept(U.begin(), U.begin() + p + 1);
  bool drop = true, dropped = false;
  for (std::size_t k = static_cast<std::size_t>(p) + 1; k + p + 1 < U.size(); ++k) {
    const double u = U[k];
    if (fine.multiplicity(u) == 1) {
      if (!drop) kept.push_back(u);
      dropped = dropped || drop;
      drop = !drop;
    } else {
      kept.push_back(u);
    }
  }
  kept.insert(kept.end(), U.end() - p - 1, U.end());
  if (!dropped) return std::nullopt;
  return KnotVector(p, std::move(kept));
}

Eigen::SparseMatrix<double> knot_insertion_matrix(const KnotVector& coarse,
                                                  const KnotVector& fine) {
  if (coarse.degree() != fine.degree())
    throw std::invalid_argument("knot_insertion_matrix: the degrees differ");
  // The fine knots that the coarse vector lacks (both sorted).
  std::vector<double> inserted;
  std::set_difference(fine.knots().begin(), fine.knots().end(), coarse.knots().begin(),
                      coarse.knots().end(), std::back_inserter(inserted));
  if (fine.knots().size() != coarse.knots().size() + inserted.size())
    throw std::invalid_argument("knot_insertion_matrix: the coarse knots are not fine knots");
  const int nc = coarse.n_basis(), nf = fine.n_basis();
  std::vector<Eigen::Triplet<double>> t;
  // Three coarse B-splines at a time: the curve whose coordinate c has the coefficients of the
  // unit vector e_{i+c}, refined, has the coefficients of N^coarse_{i+c} in coordinate c.
  for (int i = 0; i < nc; i += 3) {
    NurbsCurve c{coarse, std::vector<Vec3>(static_cast<std::size_t>(nc), Vec3::Zero()),
                 std::vector<double>(static_cast<std::size_t>(nc), 1.0)};
    for (int k = 0; k < 3 && i + k < nc; ++k) c.points[static_cast<std::size_t>(i + k)](k) = 1.0;
    const NurbsCurve f = inserted.empty() ? c : refine_knots(c, inserted);
    for (int j = 0; j < nf; ++j)
      for (int k = 0; k < 3 && i + k < nc; ++k) {
        const double a = f.points[static_cast<std::size_t>(j)](k);
        if (a != 0.0) t.emplace_back(j, i + k, a);
      }
  }
  Eigen::SparseMatrix<double> A(nf, nc);
  A.setFromTriplets(t.begin(), t.end());
  return A;
}

std::optional<KnotVector> lower_degree(const KnotVector& fine) {
  const int p = fine.degree();
  if (p == 0) return std::nullopt;
  const std::vector<double> breaks = fine.breakpoints();
  std::vector<double> knots(static_cast<std::size_t>(p), breaks.front());
  for (std::size_t k = 1; k + 1 < breaks.size(); ++k)
    knots.insert(knots.end(),
                 static_cast<std::size_t>(std::max(1, fine.multiplicity(breaks[k]) - 1)),
                 breaks[k]);
  knots.insert(knots.end(), static_cast<std::size_t>(p), breaks.back());
  return KnotVector(p - 1, std::move(knots));
}

Eigen::SparseMatrix<double> degree_transfer_matrix(const KnotVector& coarse,
                                                   const KnotVector& fine) {
  const int p = fine.degree();
  if (coarse.degree() != p - 1)
    throw std::invalid_argument("degree_transfer_matrix: the coarse degree is not p − 1");
  if (coarse.breakpoints() != fine.breakpoints())
    throw std::invalid_argument("degree_transfer_matrix: the breakpoints differ");
  using Local =
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxDegree + 1, kMaxDegree + 1>;
  const std::vector<double>& U = fine.knots();
  const int nf = fine.n_basis();
  std::vector<Eigen::Triplet<double>> t;
  BasisArray d{};
  for (int j = 0; j < nf; ++j) {
    // The non-empty span of N_j's support nearest its middle.
    int span = -1;
    for (int s = std::max(j, p); s <= std::min(j + p, nf - 1); ++s)
      if (U[static_cast<std::size_t>(s)] < U[static_cast<std::size_t>(s) + 1] &&
          (span < 0 || std::abs(s - j - 0.5 * p) < std::abs(span - j - 0.5 * p)))
        span = s;
    const double a = U[static_cast<std::size_t>(span)], b = U[static_cast<std::size_t>(span) + 1];
    const int coarse_span = coarse.find_span(0.5 * (a + b));
    Local Vf(p + 1, p + 1), Vc(p + 1, p);
    for (int k = 0; k <= p; ++k) {
      const double u = a + (b - a) * (k + 1) / (p + 2);
      bspline_basis_unchecked(fine, span, u, d);
      for (int i = 0; i <= p; ++i) Vf(k, i) = d[0][i];
      bspline_basis_unchecked(coarse, coarse_span, u, d);
      for (int i = 0; i < p; ++i) Vc(k, i) = d[0][i];
    }
    // The span's fine coefficients of each coarse function: Vf C = Vc; N_j is row j − (span − p).
    const Local C = Vf.fullPivLu().solve(Vc);
    for (int i = 0; i < p; ++i)
      if (const double v = C(j - span + p, i); std::abs(v) > 1e-14)
        t.emplace_back(j, coarse_span - (p - 1) + i, v);
  }
  Eigen::SparseMatrix<double> A(nf, coarse.n_basis());
  A.setFromTriplets(t.begin(), t.end());
  return A;
}

}  // namespace isoflex::geometry
