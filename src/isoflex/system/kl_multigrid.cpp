#include "isoflex/system/kl_multigrid.hpp"

#include <optional>

#include "isoflex/geometry/knot_hierarchy.hpp"
#include "isoflex/system/system.hpp"

namespace isoflex::system {

namespace {

using SpMat = Eigen::SparseMatrix<double>;

// One patch at one level: its knot vectors, and the first unknown of its control points in the
// level's numbering (−1 at the finest level, where the nodes' offsets in q are used).
struct PatchLevel {
  geometry::KnotVector u, v;
  int offset = -1;
};

}  // namespace

std::vector<SpMat> kl_transfer_operators(const System& sys, int coarsest_unknowns) {
  const auto& patches = sys.kl_patches();
  std::vector<bool> on_patch(static_cast<std::size_t>(sys.n()), false);
  std::vector<PatchLevel> level;
  for (const KLPatchInstance& P : patches) {
    for (int node : P.nodes)
      for (int c = 0; c < 3; ++c) on_patch[static_cast<std::size_t>(sys.q_offset(node) + c)] = true;
    const geometry::NurbsSurface& S = P.element->patch().reference();
    level.push_back({S.u, S.v, -1});
  }
  std::vector<int> others;  // the coordinates that pass through, in the fine numbering
  for (int i = 0; i < sys.n(); ++i)
    if (!on_patch[static_cast<std::size_t>(i)]) others.push_back(i);

  std::vector<SpMat> out;
  int n_fine = sys.n();
  while (n_fine > coarsest_unknowns) {
    std::vector<PatchLevel> coarse(level.size());
    bool any = false;
    int n_coarse = static_cast<int>(others.size());
    for (std::size_t k = 0; k < level.size(); ++k) {
      const auto cu = geometry::coarsen(level[k].u), cv = geometry::coarsen(level[k].v);
      any = any || cu || cv;
      coarse[k] = {cu ? *cu : level[k].u, cv ? *cv : level[k].v, n_coarse};
      n_coarse += 3 * coarse[k].u.n_basis() * coarse[k].v.n_basis();
    }
    if (!any) break;
    std::vector<Eigen::Triplet<double>> t;
    for (std::size_t k = 0; k < others.size(); ++k)
      t.emplace_back(out.empty() ? others[k] : static_cast<int>(k), static_cast<int>(k), 1.0);
    for (std::size_t k = 0; k < level.size(); ++k) {
      const SpMat Au = geometry::knot_insertion_matrix(coarse[k].u, level[k].u);
      const SpMat Av = geometry::knot_insertion_matrix(coarse[k].v, level[k].v);
      const int nu_f = level[k].u.n_basis(), nu_c = coarse[k].u.n_basis();
      const KLPatchInstance& P = patches[k];
      const std::vector<double>& w = P.element->patch().reference().weights;
      // Fine control point (i, j) from coarse (a, b): Au(i, a) Av(j, b), divided by w_ij at the
      // finest level (the header).
      for (int b = 0; b < Av.outerSize(); ++b)
        for (SpMat::InnerIterator jv(Av, b); jv; ++jv)
          for (int a = 0; a < Au.outerSize(); ++a)
            for (SpMat::InnerIterator iu(Au, a); iu; ++iu) {
              const int fine = static_cast<int>(iu.row()) + nu_f * static_cast<int>(jv.row());
              const int coarse_point = a + nu_c * b;
              double value = iu.value() * jv.value();
              int row0 = 0;
              if (out.empty()) {
                value /= w[static_cast<std::size_t>(fine)];
                row0 = sys.q_offset(P.nodes[static_cast<std::size_t>(fine)]);
              } else {
                row0 = level[k].offset + 3 * fine;
              }
              for (int c = 0; c < 3; ++c)
                t.emplace_back(row0 + c, coarse[k].offset + 3 * coarse_point + c, value);
            }
    }
    SpMat Pl(n_fine, n_coarse);
    Pl.setFromTriplets(t.begin(), t.end());
    Pl.makeCompressed();
    out.push_back(std::move(Pl));
    level = std::move(coarse);
    n_fine = n_coarse;
  }
  return out;
}

}  // namespace isoflex::system
