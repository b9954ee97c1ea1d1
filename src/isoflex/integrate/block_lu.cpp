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
    if (inserted) blocks_.push_back(Block6::Zero());
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
  input_groups_ = blocks;
  std::vector<bool> is_input(blocks_.size(), false);
  for (int b : input_) is_input[b] = true;
  for (std::size_t b = 0; b < blocks_.size(); ++b)
    if (!is_input[b]) fill_.push_back(static_cast<int>(b));
  inverse_.resize(order_.size());
}

namespace {
using Mat6 = Mat<6, 6>;

// D⁻¹ of the leading n × n part of D (the rest of inv zero: D is zero outside it) by Gauss–Jordan
// elimination with partial pivoting, the pivots of an LU factorization with partial pivoting
// (rows at and below k do not see the eliminations above the diagonal). Each step is a rank-one
// update of the columns, 4 + 2 rows at a time: five times fewer instructions than LU and six
// triangular solves for the columns of D⁻¹ (callgrind, slider-crank). False if a pivot is zero
// or the ratio of the smallest to the largest is below 1e-12 (cheaper than rcond()).
bool invert(const Mat6& D, int n, Mat6& inv) {
  inv = D;
  int row_of[6];
  double smallest = std::numeric_limits<double>::infinity(), largest = 0.0;
  for (int k = 0; k < n; ++k) {
    int p = k;
    for (int r = k + 1; r < n; ++r)
      if (std::abs(inv(r, k)) > std::abs(inv(p, k))) p = r;
    row_of[k] = p;
    if (p != k) inv.row(p).swap(inv.row(k));
    const double pivot = inv(k, k);
    smallest = std::min(smallest, std::abs(pivot));
    largest = std::max(largest, std::abs(pivot));
    if (pivot == 0.0) return false;
    // Row k /= pivot, then every other row r −= c_r row k with c the old column k.
    Vec<6> c = inv.col(k);
    c(k) = 0.0;
    const double scale = 1.0 / pivot;
    for (int j = 0; j < n; ++j) {
      if (j == k) continue;
      const double a = inv(k, j) * scale;
      inv(k, j) = a;
      inv.col(j).head<4>().noalias() -= c.head<4>() * a;
      inv.col(j).tail<2>().noalias() -= c.tail<2>() * a;
    }
    inv.col(k) = -scale * c;
    inv(k, k) = scale;
  }
  if (!(smallest > 1e-12 * largest)) return false;
  // Row exchanges of D are column exchanges of D⁻¹, in reverse order.
  for (int k = n - 1; k >= 0; --k)
    if (row_of[k] != k) inv.col(row_of[k]).swap(inv.col(k));
  return true;
}
}  // namespace

bool BlockLU::factorize(const std::vector<Block6>& values) {
  if (values.size() != input_.size()) throw std::invalid_argument("BlockLU: wrong block count");
  for (int b : fill_) blocks_[b].setZero();
  for (std::size_t b = 0; b < values.size(); ++b) blocks_[input_[b]] = values[b];
  for (std::size_t k = 0; k < order_.size(); ++k) {
    const Pivot& p = order_[k];
    if (!invert(blocks_[p.diag], width_[p.group], inverse_[k])) return false;
    for (const auto& [i, li] : p.lower) {
      const Block6 L = blocks_[li].lazyProduct(inverse_[k]);
      blocks_[li] = L;
    }
    for (int u = p.first_update; u < p.last_update; ++u) {
      const Update& up = updates_[u];
      blocks_[up.target] -= blocks_[up.l].lazyProduct(blocks_[up.u]);
    }
  }
  return true;
}

void BlockLU::multiply(const std::vector<Block6>& values, const VecX& x, VecX& y) const {
  using Vec6 = Vec<6>;
  y.setZero(size_);
  for (std::size_t b = 0; b < values.size(); ++b) {
    const auto [g, h] = input_groups_[b];
    Vec6 xh = Vec6::Zero();
    xh.head(width_[h]) = x.segment(offset_[h], width_[h]);
    const Vec6 yg = values[b] * xh;
    y.segment(offset_[g], width_[g]) += yg.head(width_[g]);
  }
}

VecX BlockLU::solve(const VecX& b) const {
  VecX x;
  solve(b, x);
  return x;
}

void BlockLU::solve(const VecX& b, VecX& y) const {
  using Vec6 = Vec<6>;
  const int groups = static_cast<int>(width_.size());
  VecX& z = padded_;
  z.setZero(6 * groups);
  for (int g = 0; g < groups; ++g) z.segment(6 * g, width_[g]) = b.segment(offset_[g], width_[g]);
  for (const Pivot& p : order_) {
    const Vec6 zv = z.segment<6>(6 * p.group);
    for (const auto& [i, li] : p.lower) z.segment<6>(6 * i).noalias() -= blocks_[li] * zv;
  }
  for (std::size_t k = order_.size(); k-- > 0;) {
    const Pivot& p = order_[k];
    Vec6 s = z.segment<6>(6 * p.group);
    for (const auto& [j, uj] : p.upper) s.noalias() -= blocks_[uj] * z.segment<6>(6 * j);
    z.segment<6>(6 * p.group).noalias() = inverse_[k] * s;
  }
  y.resize(size_);
  for (int g = 0; g < groups; ++g) y.segment(offset_[g], width_[g]) = z.segment(6 * g, width_[g]);
}

}  // namespace isoflex::integrate
