#include "isoflex/solve/saddle_point.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "isoflex/math/sparse_pattern.hpp"
#include "isoflex/solve/linear_solver.hpp"

namespace isoflex::solve {

struct SaddlePointSolver::Impl {
  SaddlePointOptions options;
  SaddlePointStats stats;
  FixedPatternCholesky cholesky;
  SpMat Ahat, B;
  VecX w;                 // W's diagonal (header)
  std::vector<int> hard;  // rows with Z_ii = 0
  VecX z_diag;            // Z's diagonal
  int n = 0, p = 0;
  bool factorized = false;
  const SpMat* M = nullptr;  // the last factorized (the caller keeps it)
  double norm_M = 0.0;

  // For M's pattern (kept_outer, kept_inner at primal size kept_p and kept_nonzeros; or, for a
  // caller that names its patterns, kept_key alone): where the values of M go. The A block's
  // values go to Â by a merge of the sorted columns (Â's column j holds A's), no map: at 10⁶
  // unknowns a map of A's values to Â's was two int arrays of nnz(A), 1.2 GB.
  std::vector<int> kept_outer, kept_inner;
  int kept_p = -1, kept_n = -1;
  Eigen::Index kept_nonzeros = -1;
  std::optional<long> kept_key;
  std::vector<int> b_source;     // B's value k ← M's value b_source[k]
  std::vector<int> diag_source;  // M's value of A_jj per primal column (−1: none)
  std::vector<int> z_source;     // M's value of Z_ii per row (−1: none)
  // Row i of B: its entries row_entries[row_start[i] … row_start[i+1]) as (M's value, column),
  // and the values of Â that the products of pairs of them add to (row-major pairs).
  std::vector<int> row_start;
  std::vector<std::pair<int, int>> row_entries;
  std::vector<int> pair_target;

  bool same_pattern(const SpMat& Mref, std::optional<long> key) const {
    if (key || kept_key)
      return key == kept_key && kept_p == p && kept_n == n && kept_nonzeros == Mref.nonZeros();
    return kept_p == p && kept_outer.size() == static_cast<std::size_t>(n + 1) &&
           kept_inner.size() == static_cast<std::size_t>(Mref.nonZeros()) &&
           std::equal(kept_outer.begin(), kept_outer.end(), Mref.outerIndexPtr()) &&
           std::equal(kept_inner.begin(), kept_inner.end(), Mref.innerIndexPtr());
  }

  // The maps above and the patterns of B and Â (Â: A's pattern and every pair of columns of a
  // row of B, whatever its values, so that it stays fixed); throws if Z is not diagonal. Â's
  // pattern is merged column by column from A's and the pairs' (no triplets: at 10⁶ unknowns
  // the triplets of A's pattern and setFromTriplets' transposed copy were 4 GB at once).
  void build_maps(const SpMat& Mref, std::optional<long> key) {
    const int m = n - p;
    const int* outer = Mref.outerIndexPtr();
    const int* inner = Mref.innerIndexPtr();
    std::vector<Eigen::Triplet<double>> b_trip;
    b_source.clear();
    diag_source.assign(static_cast<std::size_t>(p), -1);
    z_source.assign(static_cast<std::size_t>(m), -1);
    std::vector<std::vector<std::pair<int, int>>> rows(static_cast<std::size_t>(m));
    for (int j = 0; j < n; ++j)
      for (int k = outer[j]; k < outer[j + 1]; ++k) {
        const int i = inner[k];
        if (j >= p) {
          if (i < p) continue;  // Bᵀ: B is read from the primal columns
          if (i != j)
            throw std::runtime_error("saddle-point solver: the multiplier block is not diagonal");
          z_source[static_cast<std::size_t>(i - p)] = k;
        } else if (i < p) {
          if (i == j) diag_source[static_cast<std::size_t>(j)] = k;
        } else {
          b_source.push_back(k);
          b_trip.emplace_back(i - p, j, 0.0);
          rows[static_cast<std::size_t>(i - p)].emplace_back(k, j);
        }
      }
    B.resize(m, p);
    B.setFromTriplets(b_trip.begin(), b_trip.end());  // in M's order: column by column
    row_start.assign(1, 0);
    row_entries.clear();
    for (const auto& r : rows) {
      row_entries.insert(row_entries.end(), r.begin(), r.end());
      row_start.push_back(static_cast<int>(row_entries.size()));
    }
    // The rows of Â's column j that the pairs add: extra_rows[extra_start[j] … extra_start[j+1]),
    // sorted and unique.
    std::vector<int> extra_start(static_cast<std::size_t>(p) + 1, 0), extra_rows;
    for (const auto& r : rows)
      for (const auto& [ka, ja] : r)
        extra_start[static_cast<std::size_t>(ja) + 1] += static_cast<int>(r.size());
    for (int j = 0; j < p; ++j)
      extra_start[static_cast<std::size_t>(j) + 1] += extra_start[static_cast<std::size_t>(j)];
    extra_rows.resize(static_cast<std::size_t>(extra_start[static_cast<std::size_t>(p)]));
    {
      std::vector<int> fill(extra_start.begin(), extra_start.end() - 1);
      for (const auto& r : rows)
        for (const auto& [ka, ja] : r)
          for (const auto& [kb, jb] : r)
            extra_rows[static_cast<std::size_t>(fill[static_cast<std::size_t>(ja)]++)] = jb;
    }
    rows = {};
    std::vector<int> extra_end(static_cast<std::size_t>(p));
    for (int j = 0; j < p; ++j) {
      const auto begin = extra_rows.begin() + extra_start[static_cast<std::size_t>(j)];
      const auto end = extra_rows.begin() + extra_start[static_cast<std::size_t>(j) + 1];
      std::sort(begin, end);
      extra_end[static_cast<std::size_t>(j)] =
          static_cast<int>(std::unique(begin, end) - extra_rows.begin());
    }
    // Â's pattern: per column the union of A's rows (M's column j below p, sorted) and the
    // extra rows.
    const auto merge = [&](int j, std::vector<int>& column) {
      int k = outer[j];
      const int k_end = outer[j + 1];
      int e = extra_start[static_cast<std::size_t>(j)];
      const int e_end = extra_end[static_cast<std::size_t>(j)];
      while (true) {
        const int a = k < k_end && inner[k] < p ? inner[k] : p;
        const int b = e < e_end ? extra_rows[static_cast<std::size_t>(e)] : p;
        if (a == p && b == p) break;
        const int i = std::min(a, b);
        column.push_back(i);
        if (a == i) ++k;
        if (b == i) ++e;
      }
    };
    pattern_by_columns(p, p, merge, Ahat);
    const auto position = [&](int i, int j) {
      const int* begin = Ahat.innerIndexPtr() + Ahat.outerIndexPtr()[j];
      const int* end = Ahat.innerIndexPtr() + Ahat.outerIndexPtr()[j + 1];
      return static_cast<int>(std::lower_bound(begin, end, i) - Ahat.innerIndexPtr());
    };
    pair_target.clear();
    for (std::size_t r = 0; r + 1 < row_start.size(); ++r)
      for (int a = row_start[r]; a < row_start[r + 1]; ++a)
        for (int b = row_start[r]; b < row_start[r + 1]; ++b)
          pair_target.push_back(position(row_entries[static_cast<std::size_t>(a)].second,
                                         row_entries[static_cast<std::size_t>(b)].second));
    if (key) {  // the caller's name for the pattern: no copy of it (nnz(M) ints)
      std::vector<int>().swap(kept_outer);
      std::vector<int>().swap(kept_inner);
    } else {
      kept_outer.assign(outer, outer + n + 1);
      kept_inner.assign(inner, inner + Mref.nonZeros());
    }
    kept_key = key;
    kept_p = p;
    kept_n = n;
    kept_nonzeros = Mref.nonZeros();
  }

  // B's, Z's and Â's values and W from M's values; throws if a hard row is empty.
  void fill_values(const SpMat& Mref) {
    const int m = n - p;
    const double* v = Mref.valuePtr();
    double* bv = B.valuePtr();
    for (std::size_t k = 0; k < b_source.size(); ++k) bv[k] = v[b_source[k]];
    z_diag.resize(m);
    for (int i = 0; i < m; ++i) {
      const int k = z_source[static_cast<std::size_t>(i)];
      z_diag(i) = k < 0 ? 0.0 : v[k];
    }
    w.resize(m);
    hard.clear();
    for (int i = 0; i < m; ++i) {
      if (z_diag(i) != 0.0) {
        w(i) = -1.0 / z_diag(i);
        continue;
      }
      double norm2 = 0.0, diag = 0.0;
      for (int e = row_start[static_cast<std::size_t>(i)];
           e < row_start[static_cast<std::size_t>(i) + 1]; ++e) {
        const auto [k, j] = row_entries[static_cast<std::size_t>(e)];
        norm2 += v[k] * v[k];
        const int d = diag_source[static_cast<std::size_t>(j)];
        if (d >= 0) diag = std::max(diag, std::abs(v[d]));
      }
      if (!(norm2 > 0.0) || !(diag > 0.0))
        throw std::runtime_error("saddle-point solver: a constraint row on no stiffness");
      w(i) = options.penalty_factor * diag / norm2;
      hard.push_back(i);
    }
    // A's values into Â's pattern (Â's column j holds A's rows, both sorted), zeros elsewhere.
    double* av = Ahat.valuePtr();
    const int* outer = Mref.outerIndexPtr();
    const int* inner = Mref.innerIndexPtr();
    const int* a_outer = Ahat.outerIndexPtr();
    const int* a_inner = Ahat.innerIndexPtr();
    for (int j = 0; j < p; ++j) {
      int k = outer[j];
      for (int t = a_outer[j]; t < a_outer[j + 1]; ++t)
        if (k < outer[j + 1] && inner[k] == a_inner[t])
          av[t] = 0.0 + v[k++];  // as the sum into zeros it replaces (−0 → +0)
        else
          av[t] = 0.0;
    }
    std::size_t pair = 0;
    for (int i = 0; i < m; ++i) {
      const int begin = row_start[static_cast<std::size_t>(i)];
      const int end = row_start[static_cast<std::size_t>(i) + 1];
      for (int a = begin; a < end; ++a) {
        const double wa = w(i) * v[row_entries[static_cast<std::size_t>(a)].first];
        for (int b = begin; b < end; ++b)
          av[pair_target[pair++]] += wa * v[row_entries[static_cast<std::size_t>(b)].first];
      }
    }
  }

  // The augmented operator on u = (x, λ_H) and the preconditioner P⁻¹ (header).
  VecX apply(const VecX& u) const {
    const int h = static_cast<int>(hard.size());
    VecX lambda = VecX::Zero(B.rows());
    for (int k = 0; k < h; ++k) lambda(hard[static_cast<std::size_t>(k)]) = u(p + k);
    VecX out(p + h);
    out.head(p) = Ahat * u.head(p) + B.transpose() * lambda;
    const VecX Bx = B * u.head(p);
    for (int k = 0; k < h; ++k) out(p + k) = Bx(hard[static_cast<std::size_t>(k)]);
    return out;
  }
  VecX precondition(const VecX& r) const {
    const int h = static_cast<int>(hard.size());
    VecX y = VecX::Zero(B.rows());
    VecX out(p + h);
    for (int k = 0; k < h; ++k) {
      const int i = hard[static_cast<std::size_t>(k)];
      y(i) = -w(i) * r(p + k);
      out(p + k) = y(i);
    }
    out.head(p) = cholesky.solve(VecX(r.head(p) - B.transpose() * y));
    return out;
  }

  // z = (x, λ) of M from u = (x, λ_H) of the augmented system (λ_S of the header).
  VecX expand(const VecX& u, const VecX& b) const {
    const int m = n - p, h = static_cast<int>(hard.size());
    VecX z(n);
    z.head(p) = u.head(p);
    const VecX Bx = B * z.head(p);
    for (int i = 0; i < m; ++i)
      if (z_diag(i) != 0.0) z(p + i) = (b(p + i) - Bx(i)) / z_diag(i);
    for (int k = 0; k < h; ++k) z(p + hard[static_cast<std::size_t>(k)]) = u(p + k);
    return z;
  }

  // GMRES cycles, each from the augmented system's true residual, until the normwise backward
  // error of z in M z = b, ‖b − M z‖∞ / (‖M‖∞ ‖z‖∞ + ‖b‖∞), is at the tolerance (the recurrence's
  // estimate runs ahead of the true residual by the round-off of Â's factorization, cond(Â) ε).
  VecX solve_iteratively(const VecX& f, const VecX& b) {
    VecX u = VecX::Zero(f.size()), z = VecX::Zero(n);
    stats.iterations = 0;
    stats.backward_error = 0.0;
    if (b.lpNorm<Eigen::Infinity>() == 0.0) return z;
    VecX r = f;
    for (int cycle = 0; cycle < 4 && stats.iterations < options.max_iterations; ++cycle) {
      u += gmres(r, options.gmres_tolerance);
      z = expand(u, b);
      stats.backward_error = (b - *M * z).lpNorm<Eigen::Infinity>() /
                             (norm_M * z.lpNorm<Eigen::Infinity>() + b.lpNorm<Eigen::Infinity>());
      if (stats.backward_error <= options.backward_error) break;
      r = f - apply(u);
    }
    return z;
  }

  // Right-preconditioned GMRES (Saad & Schultz 1986) from u = 0 to ‖f − K u‖ ≤ tol ‖f‖ by the
  // recurrence, Givens rotations on the Hessenberg matrix, no restart within.
  VecX gmres(const VecX& f, double tolerance) {
    const int k_max = options.max_iterations - stats.iterations;
    const double beta = f.norm();
    VecX u = VecX::Zero(f.size());
    if (beta == 0.0 || k_max <= 0) return u;
    std::vector<VecX> V{f / beta}, Zp;
    MatX H = MatX::Zero(k_max + 1, k_max);
    VecX cs = VecX::Zero(k_max), sn = VecX::Zero(k_max), g = VecX::Zero(k_max + 1);
    g(0) = beta;
    int k = 0;
    double residual = beta;
    for (; k < k_max && residual > tolerance * beta; ++k) {
      Zp.push_back(precondition(V[static_cast<std::size_t>(k)]));
      VecX v = apply(Zp.back());
      for (int i = 0; i <= k; ++i) {  // modified Gram–Schmidt
        H(i, k) = V[static_cast<std::size_t>(i)].dot(v);
        v -= H(i, k) * V[static_cast<std::size_t>(i)];
      }
      H(k + 1, k) = v.norm();
      const bool breakdown = !(H(k + 1, k) > 0.0);  // the Krylov space holds the solution
      if (!breakdown) V.push_back(v / H(k + 1, k));
      for (int i = 0; i < k; ++i) {
        const double a = cs(i) * H(i, k) + sn(i) * H(i + 1, k);
        H(i + 1, k) = -sn(i) * H(i, k) + cs(i) * H(i + 1, k);
        H(i, k) = a;
      }
      const double d = std::hypot(H(k, k), H(k + 1, k));
      cs(k) = H(k, k) / d;
      sn(k) = H(k + 1, k) / d;
      H(k, k) = d;
      H(k + 1, k) = 0.0;
      g(k + 1) = -sn(k) * g(k);
      g(k) *= cs(k);
      residual = std::abs(g(k + 1));
      if (breakdown) {
        ++k;
        break;
      }
    }
    const VecX y = H.topLeftCorner(k, k).triangularView<Eigen::Upper>().solve(g.head(k));
    for (int i = 0; i < k; ++i) u += y(i) * Zp[static_cast<std::size_t>(i)];
    stats.iterations += k;
    return u;
  }
};

SaddlePointSolver::SaddlePointSolver(SaddlePointOptions options) : impl_(std::make_unique<Impl>()) {
  impl_->options = options;
}
SaddlePointSolver::~SaddlePointSolver() = default;
SaddlePointSolver::SaddlePointSolver(SaddlePointSolver&&) noexcept = default;
SaddlePointSolver& SaddlePointSolver::operator=(SaddlePointSolver&&) noexcept = default;
const SaddlePointStats& SaddlePointSolver::last() const {
  return impl_->stats;
}
int SaddlePointSolver::analyses() const {
  return impl_->cholesky.analyses();
}

void SaddlePointSolver::factorize(const SpMat& M, int p) {
  augment(M, p);
  impl_->cholesky.factorize(impl_->Ahat);
  impl_->factorized = true;
}

void SaddlePointSolver::augment(const SpMat& M, int p) {
  augment(M, p, std::nullopt);
}

void SaddlePointSolver::augment(const SpMat& M, int p, std::optional<long> pattern_key) {
  Impl& s = *impl_;
  const int n = static_cast<int>(M.rows());
  if (M.cols() != n || p < 0 || p > n || !M.isCompressed())
    throw std::invalid_argument("saddle-point solver: inconsistent sizes or uncompressed matrix");
  s.factorized = false;
  s.n = n;
  s.p = p;
  s.M = &M;
  if (!s.same_pattern(M, pattern_key)) s.build_maps(M, pattern_key);
  s.fill_values(M);
  s.stats.hard_rows = static_cast<int>(s.hard.size());
  s.norm_M = 0.0;
  for (int j = 0; j < n; ++j) {  // symmetric: the largest column sum is ‖M‖∞
    double sum = 0.0;
    for (SpMat::InnerIterator it(M, j); it; ++it) sum += std::abs(it.value());
    s.norm_M = std::max(s.norm_M, sum);
  }
}

const SpMat& SaddlePointSolver::augmented_matrix() const {
  return impl_->Ahat;
}

Eigen::SparseMatrix<double, Eigen::RowMajor> SaddlePointSolver::hard_rows() const {
  const Impl& s = *impl_;
  std::vector<int> position(static_cast<std::size_t>(s.B.rows()), -1);
  for (std::size_t k = 0; k < s.hard.size(); ++k)
    position[static_cast<std::size_t>(s.hard[k])] = static_cast<int>(k);
  std::vector<Eigen::Triplet<double>> trip;
  for (int j = 0; j < s.B.outerSize(); ++j)
    for (SpMat::InnerIterator it(s.B, j); it; ++it)
      if (const int r = position[static_cast<std::size_t>(it.row())]; r >= 0)
        trip.emplace_back(r, j, it.value());
  Eigen::SparseMatrix<double, Eigen::RowMajor> BH(static_cast<Eigen::Index>(s.hard.size()), s.p);
  BH.setFromTriplets(trip.begin(), trip.end());
  BH.makeCompressed();
  return BH;
}

VecX SaddlePointSolver::hard_weights() const {
  const Impl& s = *impl_;
  VecX w(static_cast<Eigen::Index>(s.hard.size()));
  for (std::size_t k = 0; k < s.hard.size(); ++k) w(static_cast<Eigen::Index>(k)) = s.w(s.hard[k]);
  return w;
}

VecX SaddlePointSolver::augmented_rhs(const VecX& b) const {
  const Impl& s = *impl_;
  if (b.size() != s.n) throw std::invalid_argument("saddle-point solver: inconsistent sizes");
  const int p = s.p, m = s.n - p, h = static_cast<int>(s.hard.size());
  const VecX b_lambda = b.tail(m);
  VecX f(p + h);
  f.head(p) = b.head(p) + s.B.transpose() * s.w.cwiseProduct(b_lambda);
  for (int k = 0; k < h; ++k) f(p + k) = b_lambda(s.hard[static_cast<std::size_t>(k)]);
  return f;
}

VecX SaddlePointSolver::expand(const VecX& u, const VecX& b) const {
  return impl_->expand(u, b);
}

VecX SaddlePointSolver::solve(const VecX& b) {
  Impl& s = *impl_;
  if (!s.factorized) throw std::logic_error("saddle-point solver: solve before factorize");
  if (b.size() != s.n) throw std::invalid_argument("saddle-point solver: inconsistent sizes");
  const int p = s.p, h = static_cast<int>(s.hard.size());
  const VecX f = augmented_rhs(b);
  s.stats.iterations = 0;
  s.stats.backward_error = 0.0;
  const VecX z =
      h > 0 ? s.solve_iteratively(f, b) : s.expand(VecX(s.cholesky.solve(VecX(f.head(p)))), b);
  if (!(s.stats.backward_error <= s.options.backward_error))
    throw std::runtime_error(
        fmt::format("saddle-point solver: GMRES reached a backward error of {:.3g} in {} "
                    "iterations",
                    s.stats.backward_error, s.stats.iterations));
  if (!z.allFinite()) throw std::runtime_error("saddle-point solver: non-finite solution");
  return z;
}

}  // namespace isoflex::solve
