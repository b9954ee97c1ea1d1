#pragma once
// The blocks of the multigrid's block Jacobi smoother (docs/theory/solvers.md §4): runs of about
// `size` consecutive unknowns, none cut where the matrix entries across the cut are heavy. A
// stiff element that spans a band of unknowns (a bending strip, 1000 × the shell's modulus) cut
// by a block border leaves its coupling to the other block, where the smoother cannot relax it:
// on the two-patch roof with a bending strip the CG iterations jumped between 48 and 344 with the
// block count alone (bench/large_shells.md, "Smoother blocks that do not cut the strip").
#include <algorithm>
#include <cmath>
#include <vector>

#include "isoflex/solve/krylov_backend.hpp"

namespace isoflex::solve {

// The lengths of the blocks of A's rows (a symmetric matrix in CSR, both triangles or the upper
// one), in order, summing to A.n; empty where equal blocks (n / size of them, the first n mod
// blocks one row longer, as PETSc makes them) cut nowhere heavy. The weight of the cut b (between
// rows b − 1 and b) is w(b) = Σ |A_ij| over i < b ≤ j; an equal cut that weighs more than 10 × the
// median cut moves to the nearest cut that does not (within 8 × size), and blocks that the move
// empties merge.
inline std::vector<int> smoother_blocks(const CsrView& A, int size) {
  const int n = A.n, count = std::max(1, n / size);
  if (count == 1) return {};
  // w(b) by a difference array: an entry (i, j > i) weighs on the cuts i + 1 … j.
  std::vector<double> w(static_cast<std::size_t>(n) + 1, 0.0);
  for (int i = 0; i < n; ++i)
    for (int k = A.row_start[i]; k < A.row_start[i + 1]; ++k)
      if (const int j = A.columns[k]; j > i) {
        const double a = std::abs(A.values[k]);
        w[static_cast<std::size_t>(i) + 1] += a;
        w[static_cast<std::size_t>(j) + 1] -= a;
      }
  for (int b = 1; b <= n; ++b) w[b] += w[b - 1];
  std::vector<double> sorted(w.begin() + 1, w.begin() + n);
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double heavy = 10.0 * sorted[sorted.size() / 2];
  std::vector<int> cuts;
  bool moved = false;
  for (int k = 1, at = 0; k < count; ++k) {
    at += n / count + (k - 1 < n % count ? 1 : 0);
    int cut = at;
    if (w[at] > heavy) {
      moved = true;
      cut = -1;
      for (int d = 1; d <= 8 * size && cut < 0; ++d)
        for (const int b : {at - d, at + d})
          if (b > 0 && b < n && w[b] <= heavy) {
            cut = b;
            break;
          }
    }
    if (cut > (cuts.empty() ? 0 : cuts.back())) cuts.push_back(cut);
  }
  if (!moved) return {};
  std::vector<int> lengths;
  int start = 0;
  for (int c : cuts) lengths.push_back(c - start), start = c;
  lengths.push_back(n - start);
  return lengths;
}

}  // namespace isoflex::solve
