#include "isoflex/system/kl_multigrid.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <unordered_map>

#include "isoflex/geometry/knot_hierarchy.hpp"
#include "isoflex/system/system.hpp"

namespace isoflex::system {

namespace {

using SpMat = Eigen::SparseMatrix<double>;

// One patch at one level: its knot vectors, and the level's point of each of its control points
// (at the finest level the node; a point that two patches share, or a patch's seam, appears
// several times).
struct PatchLevel {
  geometry::KnotVector u, v;
  std::vector<int> points;
};

// A coarse control point's column restricted to the fine points that several control points
// share: (fine point, value), by point. Coarse points of different patches (or the two sides of a
// seam) with the same nonempty column are one coarse point: the coarse space is then as conforming
// as the fine one, and a field continuous across an interface at the coarse level is interpolated
// to the same values from either side.
using SharedColumn = std::vector<std::pair<int, double>>;

bool same_column(const SharedColumn& a, const SharedColumn& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t k = 0; k < a.size(); ++k)
    if (a[k].first != b[k].first ||
        std::abs(a[k].second - b[k].second) > 1e-12 * std::max(1.0, std::abs(a[k].second)))
      return false;
  return true;
}

// p-multigrid stops at degree 2: a Kirchhoff–Love patch needs C¹ functions.
bool lowers(const geometry::KnotVector& kv) {
  return kv.degree() > 2;
}

}  // namespace

bool first_level_lowers_degree(const System& sys, Coarsening coarsening) {
  if (coarsening != Coarsening::degree_then_knots) return false;
  for (const KLPatchInstance& P : sys.kl_patches()) {
    const geometry::NurbsSurface& S = P.element->patch().reference();
    if (lowers(S.u) || lowers(S.v)) return true;
  }
  return false;
}

std::vector<SpMat> kl_transfer_operators(const System& sys, int coarsest_unknowns,
                                         Coarsening coarsening) {
  const auto& patches = sys.kl_patches();
  std::vector<bool> on_patch(static_cast<std::size_t>(sys.n()), false);
  std::vector<PatchLevel> level;
  for (const KLPatchInstance& P : patches) {
    for (int node : P.nodes)
      for (int c = 0; c < 3; ++c) on_patch[static_cast<std::size_t>(sys.q_offset(node) + c)] = true;
    const geometry::NurbsSurface& S = P.element->patch().reference();
    level.push_back({S.u, S.v, P.nodes});
  }
  std::vector<int> others;  // the coordinates that pass through, in the fine numbering
  for (int i = 0; i < sys.n(); ++i)
    if (!on_patch[static_cast<std::size_t>(i)]) others.push_back(i);
  const int n_others = static_cast<int>(others.size());

  std::vector<SpMat> out;
  int n_fine = sys.n();
  int n_points = sys.node_count();
  // The first unknown of a point of the level: its node's offset in q at the finest level, after
  // the coordinates that pass through at the coarse ones.
  const auto first_row = [&](int point) {
    return out.empty() ? sys.q_offset(point) : n_others + 3 * point;
  };
  while (n_fine > coarsest_unknowns) {
    std::vector<PatchLevel> coarse(level.size());
    bool any = false;
    for (int pass = coarsening == Coarsening::degree_then_knots && out.empty() ? 0 : 1;
         pass < 2 && !any; ++pass)
      for (std::size_t k = 0; k < level.size(); ++k) {
        const auto lower = [&](const geometry::KnotVector& kv) {
          if (pass == 1) return geometry::coarsen(kv);
          return lowers(kv) ? geometry::lower_degree(kv) : std::nullopt;
        };
        const auto cu = lower(level[k].u), cv = lower(level[k].v);
        any = any || cu || cv;
        coarse[k].u = cu ? *cu : level[k].u;
        coarse[k].v = cv ? *cv : level[k].v;
      }
    if (!any) break;
    const auto transfer = [](const geometry::KnotVector& c, const geometry::KnotVector& f) {
      return c.degree() == f.degree() ? geometry::knot_insertion_matrix(c, f)
                                      : geometry::degree_transfer_matrix(c, f);
    };
    std::vector<int> uses(static_cast<std::size_t>(n_points), 0);
    for (const PatchLevel& L : level)
      for (int p : L.points) ++uses[static_cast<std::size_t>(p)];
    // Each patch's interpolation: (fine control point, coarse control point, value).
    struct Entry {
      int fine, coarse;
      double value;
    };
    std::vector<std::vector<Entry>> entries(level.size());
    for (std::size_t k = 0; k < level.size(); ++k) {
      const SpMat Au = transfer(coarse[k].u, level[k].u);
      const SpMat Av = transfer(coarse[k].v, level[k].v);
      const int nu_f = level[k].u.n_basis(), nu_c = coarse[k].u.n_basis();
      const std::vector<double>& w = patches[k].element->patch().reference().weights;
      // Fine control point (i, j) from coarse (a, b): Au(i, a) Av(j, b), divided by w_ij at the
      // finest level (the header).
      for (int b = 0; b < Av.outerSize(); ++b)
        for (SpMat::InnerIterator jv(Av, b); jv; ++jv)
          for (int a = 0; a < Au.outerSize(); ++a)
            for (SpMat::InnerIterator iu(Au, a); iu; ++iu) {
              const int fine = static_cast<int>(iu.row()) + nu_f * static_cast<int>(jv.row());
              double value = iu.value() * jv.value();
              if (out.empty()) value /= w[static_cast<std::size_t>(fine)];
              entries[k].push_back({fine, a + nu_c * b, value});
            }
    }
    // The coarse points: one per coarse control point, those with the same shared column merged.
    std::vector<std::pair<SharedColumn, int>> merged;  // the columns seen, with their point
    std::unordered_map<int, std::vector<std::size_t>> by_first;  // merged's, by first fine point
    int n_coarse_points = 0;
    for (std::size_t k = 0; k < level.size(); ++k) {
      std::vector<SharedColumn> column(
          static_cast<std::size_t>(coarse[k].u.n_basis() * coarse[k].v.n_basis()));
      for (const Entry& e : entries[k])
        if (const int p = level[k].points[static_cast<std::size_t>(e.fine)];
            uses[static_cast<std::size_t>(p)] > 1)
          column[static_cast<std::size_t>(e.coarse)].emplace_back(p, e.value);
      coarse[k].points.assign(column.size(), -1);
      for (std::size_t a = 0; a < column.size(); ++a) {
        SharedColumn& c = column[a];
        int id = -1;
        if (!c.empty()) {
          std::sort(c.begin(), c.end());
          for (std::size_t s : by_first[c.front().first])
            if (same_column(merged[s].first, c)) {
              id = merged[s].second;
              break;
            }
        }
        if (id < 0) {
          id = n_coarse_points++;
          if (!c.empty()) {
            by_first[c.front().first].push_back(merged.size());
            merged.emplace_back(std::move(c), id);
          }
        }
        coarse[k].points[a] = id;
      }
    }
    const int n_coarse = n_others + 3 * n_coarse_points;
    std::vector<Eigen::Triplet<double>> t;
    for (int k = 0; k < n_others; ++k)
      t.emplace_back(out.empty() ? others[static_cast<std::size_t>(k)] : k, k, 1.0);
    // A fine point's row from the first of its control points only: the others give the same
    // values where the coarse points were merged (a shared row summed over its control points
    // was that many times the field).
    std::vector<bool> filled(static_cast<std::size_t>(n_points), false);
    for (std::size_t k = 0; k < level.size(); ++k) {
      std::vector<bool> mine(level[k].points.size(), false);
      for (std::size_t f = 0; f < mine.size(); ++f)
        if (const int p = level[k].points[f]; !filled[static_cast<std::size_t>(p)])
          filled[static_cast<std::size_t>(p)] = mine[f] = true;
      for (const Entry& e : entries[k]) {
        if (!mine[static_cast<std::size_t>(e.fine)]) continue;
        const int row0 = first_row(level[k].points[static_cast<std::size_t>(e.fine)]);
        const int col0 = n_others + 3 * coarse[k].points[static_cast<std::size_t>(e.coarse)];
        for (int c = 0; c < 3; ++c) t.emplace_back(row0 + c, col0 + c, e.value);
      }
    }
    SpMat Pl(n_fine, n_coarse);
    Pl.setFromTriplets(t.begin(), t.end());
    Pl.makeCompressed();
    out.push_back(std::move(Pl));
    level = std::move(coarse);
    n_fine = n_coarse;
    n_points = n_coarse_points;
  }
  return out;
}

}  // namespace isoflex::system
