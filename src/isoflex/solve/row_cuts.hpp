#pragma once
// Where a matrix's rows may be cut into consecutive runs, for the multigrid's block Jacobi
// smoother and for the MPI ranks' rows (docs/theory/solvers.md §4, §6): not where the matrix
// entries across the cut are heavy. A stiff element that spans a band of unknowns (a bending
// strip, 1000 × the shell's modulus) cut by a block border leaves its coupling to the other
// block, where the smoother cannot relax it: on the two-patch roof with a bending strip the CG
// iterations jumped between 48 and 344 with the block count alone (bench/large_shells.md,
// "Smoother blocks that do not cut the strip"), and to 349 where the border of two ranks fell
// inside the strip ("The bending strip on two ranks"). Milder bands count too: AF-D's interface,
// whose cuts weigh up to 3.5 × the median, took 26 CG iterations at 6.3·10⁴ unknowns on one
// process and 31 on two ranks with the border of heavy at 10 × the median, 20 and 20 with 3 ×
// ("Heavy from 3 × the median cut"). The one-patch roofs and the pinched cylinder keep their
// blocks (the same results with the border at 2 ×, 3 × and 10 ×).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "isoflex/solve/krylov_backend.hpp"

namespace isoflex::solve {

// The weights of the cuts of n rows, w(b) = Σ |A_ij| over i < b ≤ j (the cut b lies between rows
// b − 1 and b), gathered entry by entry as differences: an entry (i, j > i) weighs on the cuts
// i + 1 … j. Entries with j ≤ i add nothing, so a symmetric matrix may give both triangles or its
// upper one.
class CutWeights {
 public:
  explicit CutWeights(int n) : d_(static_cast<std::size_t>(n) + 1, 0.0) {}
  void add(int i, int j, double a) {
    if (j <= i) return;
    d_[static_cast<std::size_t>(i) + 1] += std::abs(a);
    d_[static_cast<std::size_t>(j) + 1] -= std::abs(a);
  }
  void add(const CsrView& A) {
    for (int i = 0; i < A.n; ++i)
      for (int k = A.row_start[i]; k < A.row_start[i + 1]; ++k) add(i, A.columns[k], A.values[k]);
  }
  // The differences, to be summed over MPI's ranks before weights().
  std::vector<double>& differences() { return d_; }
  // w(0) … w(n).
  std::vector<double> weights() const {
    std::vector<double> w(d_);
    for (std::size_t b = 1; b < w.size(); ++b) w[b] += w[b - 1];
    return w;
  }

 private:
  std::vector<double> d_;
};

// `count` − 1 cuts of the n = w.size() − 1 rows into runs of about equal length (n / count, the
// first n mod count one row longer, as PETSc makes them), each cut that weighs more than 3 × the
// median cut moved to the nearest one within `reach` that does not, or dropped where there is
// none. `moved` tells whether any cut moved or was dropped. Cuts that the moves bring together
// merge, so fewer may come back; they ascend, all in (0, n).
inline std::vector<int> light_cuts(const std::vector<double>& w, int count, int reach,
                                   bool& moved) {
  const int n = static_cast<int>(w.size()) - 1;
  moved = false;
  if (count <= 1 || n < 2) return {};
  std::vector<double> sorted(w.begin() + 1, w.begin() + n);
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double heavy = 3.0 * sorted[sorted.size() / 2];
  std::vector<int> cuts;
  for (int k = 1, at = 0; k < count; ++k) {
    at += n / count + (k - 1 < n % count ? 1 : 0);
    int cut = at;
    if (w[static_cast<std::size_t>(at)] > heavy) {
      moved = true;
      cut = -1;
      for (int d = 1; d <= reach && cut < 0; ++d)
        for (const int b : {at - d, at + d})
          if (b > 0 && b < n && w[static_cast<std::size_t>(b)] <= heavy) {
            cut = b;
            break;
          }
    }
    if (cut > (cuts.empty() ? 0 : cuts.back())) cuts.push_back(cut);
  }
  return cuts;
}

// The lengths of the smoother's blocks of A's rows (about `size` each), in order, summing to A.n;
// empty where PETSc's equal blocks (n / size of them) cut nowhere heavy. A heavy cut moves
// within 8 × size.
inline std::vector<int> smoother_blocks(const CsrView& A, int size) {
  CutWeights weights(A.n);
  weights.add(A);
  bool moved = false;
  const std::vector<int> cuts =
      light_cuts(weights.weights(), std::max(1, A.n / size), 8 * size, moved);
  if (!moved) return {};
  std::vector<int> lengths;
  int start = 0;
  for (int c : cuts) lengths.push_back(c - start), start = c;
  lengths.push_back(A.n - start);
  return lengths;
}

// The first rows of `ranks` ranks and the end, borders[r] … borders[r + 1] − 1 being rank r's
// rows: equal shares of the n = w.size() − 1 rows (the first ranks the shorter), a border that
// weighs heavy moved within a quarter of a share. Every rank keeps rows: where a heavy border has
// no light one within reach, or moves would empty a rank, the shares stay equal.
inline std::vector<int> rank_borders(const std::vector<double>& w, int ranks) {
  const int n = static_cast<int>(w.size()) - 1;
  std::vector<int> borders{0};
  bool moved = false;
  const std::vector<int> cuts = light_cuts(w, ranks, std::max(1, n / ranks / 4), moved);
  if (moved && static_cast<int>(cuts.size()) == ranks - 1)
    borders.insert(borders.end(), cuts.begin(), cuts.end());
  else
    for (long long r = 1; r < ranks; ++r) borders.push_back(static_cast<int>(n * r / ranks));
  borders.push_back(n);
  return borders;
}

}  // namespace isoflex::solve
