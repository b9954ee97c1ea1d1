#include "isoflex/geometry/knot_hierarchy.hpp"

#include <algorithm>
#include <stdexcept>
#include <vector>

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

}  // namespace isoflex::geometry
