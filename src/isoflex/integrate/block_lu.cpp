#include "isoflex/integrate/block_lu.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

namespace isoflex::integrate {

BlockLU::BlockLU(std::vector<int> offset, std::vector<int> width,
                 const std::vector<std::pair<int, int>>& blocks)
    : offset_(std::move(offset)), width_(std::move(width)) {
  const int n = static_cast<int>(width_.size());
  for (int w : width_) size_ += w;
  std::vector<std::vector<int>> adj(n);
  for (const auto& [g, h] : blocks)
    if (g != h) adj[g].push_back(h);
  for (auto& a : adj) {
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
  }
  // Minimum degree on the block graph (explicit elimination graph; run once).
  std::vector<bool> done(n, false);
  std::map<std::pair<int, int>, int> index;
  auto block = [&](int i, int j) {
    const auto [it, inserted] = index.insert({{i, j}, static_cast<int>(blocks_.size())});
    if (inserted) blocks_.push_back(Small::Zero(width_[i], width_[j]));
    return it->second;
  };
  for (int step = 0; step < n; ++step) {
    int v = -1;
    for (int g = 0; g < n; ++g)
      if (!done[g] && (v < 0 || adj[g].size() < adj[v].size())) v = g;
    done[v] = true;
    Pivot p;
    p.group = v;
    p.diag = block(v, v);
    for (int i : adj[v]) {
      p.lower.push_back({i, block(i, v)});
      p.upper.push_back({i, block(v, i)});
    }
    // Eliminating v joins its remaining neighbours (fill).
    const std::vector<int> nb = adj[v];
    for (int i : nb) {
      auto& a = adj[i];
      a.erase(std::lower_bound(a.begin(), a.end(), v));
      std::vector<int> merged;
      std::set_union(a.begin(), a.end(), nb.begin(), nb.end(), std::back_inserter(merged));
      merged.erase(std::remove(merged.begin(), merged.end(), i), merged.end());
      a = std::move(merged);
    }
    adj[v].clear();
    order_.push_back(std::move(p));
  }
  // Schur complement updates A_ij −= L_iv U_vj, in elimination order.
  for (Pivot& p : order_) {
    p.first_update = static_cast<int>(updates_.size());
    for (const auto& [i, li] : p.lower)
      for (const auto& [j, uj] : p.upper) updates_.push_back({li, uj, block(i, j)});
    p.last_update = static_cast<int>(updates_.size());
  }
  for (const auto& [g, h] : blocks) input_.push_back(block(g, h));
  inverse_.resize(order_.size());
}

namespace {
using Small = BlockLU::Small;
using Mat6 = Mat<6, 6>;

// T −= A B (subtract) or T = A B, with fixed-size 6 × 6 products for full blocks (the common
// case: root twists) and coefficient-based ones otherwise.
void multiply_subtract(const Small& A, const Small& B, Small& T, bool subtract) {
  if (A.rows() == 6 && A.cols() == 6 && B.cols() == 6) {
    const Mat6 P = Eigen::Map<const Mat6>(A.data()).lazyProduct(Eigen::Map<const Mat6>(B.data()));
    if (subtract)
      Eigen::Map<Mat6>(T.data()) -= P;
    else
      T = P;
  } else if (subtract) {
    T -= A.lazyProduct(B);
  } else {
    T = A.lazyProduct(B);
  }
}

// D⁻¹ by Gauss–Jordan elimination with partial pivoting on fixed-size storage (Eigen's
// PartialPivLU and inverse() were 6 000 instructions a 6 × 6 block, half of the factorization);
// false if the ratio of the smallest to the largest pivot is below 1e-12 (the pivots are those of
// the LU with partial pivoting; cheaper than rcond()).
bool invert(const Small& D, Small& inv) {
  const int w = static_cast<int>(D.rows());
  Mat6 a, b = Mat6::Identity();
  a.topLeftCorner(w, w) = D;
  double largest = 0.0, smallest = std::numeric_limits<double>::infinity();
  for (int k = 0; k < w; ++k) {
    int p = k;
    for (int i = k + 1; i < w; ++i)
      if (std::abs(a(i, k)) > std::abs(a(p, k))) p = i;
    const double pivot = a(p, k);
    if (!std::isfinite(pivot) || pivot == 0.0) return false;
    largest = std::max(largest, std::abs(pivot));
    smallest = std::min(smallest, std::abs(pivot));
    if (p != k)
      for (int c = 0; c < w; ++c) {
        std::swap(a(p, c), a(k, c));
        std::swap(b(p, c), b(k, c));
      }
    const double s = 1.0 / pivot;
    for (int c = 0; c < w; ++c) {
      a(k, c) *= s;
      b(k, c) *= s;
    }
    for (int i = 0; i < w; ++i) {
      const double f = a(i, k);
      if (i == k || f == 0.0) continue;
      for (int c = k; c < w; ++c) a(i, c) -= f * a(k, c);
      for (int c = 0; c < w; ++c) b(i, c) -= f * b(k, c);
    }
  }
  if (!(smallest > 1e-12 * largest)) return false;
  inv = b.topLeftCorner(w, w);
  return true;
}
}  // namespace

bool BlockLU::factorize(const std::vector<Small>& values) {
  if (values.size() != input_.size()) throw std::invalid_argument("BlockLU: wrong block count");
  for (auto& B : blocks_) B.setZero();
  for (std::size_t b = 0; b < values.size(); ++b) blocks_[input_[b]] += values[b];
  for (std::size_t k = 0; k < order_.size(); ++k) {
    const Pivot& p = order_[k];
    if (!invert(blocks_[p.diag], inverse_[k])) return false;
    for (const auto& [i, li] : p.lower) {
      const Small L = blocks_[li];
      multiply_subtract(L, inverse_[k], blocks_[li], false);
    }
    for (int u = p.first_update; u < p.last_update; ++u) {
      const Update& up = updates_[u];
      multiply_subtract(blocks_[up.l], blocks_[up.u], blocks_[up.target], true);
    }
  }
  return true;
}

VecX BlockLU::solve(const VecX& b) const {
  VecX x;
  solve(b, x);
  return x;
}

void BlockLU::solve(const VecX& b, VecX& y) const {
  using Part = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1>;
  y = b;
  for (const Pivot& p : order_) {
    const Part yv = y.segment(offset_[p.group], width_[p.group]);
    for (const auto& [i, li] : p.lower)
      y.segment(offset_[i], width_[i]).noalias() -= blocks_[li] * yv;
  }
  for (std::size_t k = order_.size(); k-- > 0;) {
    const Pivot& p = order_[k];
    Part s = y.segment(offset_[p.group], width_[p.group]);
    for (const auto& [j, uj] : p.upper)
      s.noalias() -= blocks_[uj] * y.segment(offset_[j], width_[j]);
    y.segment(offset_[p.group], width_[p.group]) = inverse_[k] * s;
  }
}

}  // namespace isoflex::integrate
