#include "isoflex/integrate/block_lu.hpp"

#include <Eigen/LU>
#include <algorithm>
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

// D⁻¹ by partial pivoting; false if the ratio of the smallest to the largest pivot is below
// 1e-12 (cheaper than rcond()).
template <class M>
bool invert_lu(const M& D, Small& inv) {
  const Eigen::PartialPivLU<M> lu(D);
  const auto d = lu.matrixLU().diagonal().cwiseAbs();
  if (!(d.minCoeff() > 1e-12 * d.maxCoeff())) return false;
  inv = lu.inverse();
  return true;
}

bool invert(const Small& D, Small& inv) {
  if (D.rows() == 6) return invert_lu(Mat6(Eigen::Map<const Mat6>(D.data())), inv);
  return invert_lu(D, inv);
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
