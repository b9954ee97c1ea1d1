#include "isoflex/system/global_matrix.hpp"

#include <algorithm>
#include <cassert>
#include <stdexcept>

#include "isoflex/math/sparse_pattern.hpp"

namespace isoflex::system {

int GlobalMatrix::add(const SpMat& local, std::vector<int> coords) {
  assert(local.rows() == static_cast<int>(coords.size()) && local.cols() == local.rows());
  SpMat l = local;
  l.makeCompressed();
  parts_.push_back({std::move(l), std::move(coords)});
  return static_cast<int>(parts_.size()) - 1;
}

int GlobalMatrix::add_dense(std::vector<int> coords) {
  parts_.push_back({SpMat(), std::move(coords)});
  return static_cast<int>(parts_.size()) - 1;
}

void GlobalMatrix::finalize(int n) {
  // Visits every local entry of a contributor in its storage order: f(local index, row, col).
  auto each = [](const Contributor& c, auto&& f) {
    const int size = static_cast<int>(c.coords.size());
    if (c.local.size() == 0) {
      for (int j = 0, k = 0; j < size; ++j)
        for (int i = 0; i < size; ++i, ++k) f(k, c.coords[i], c.coords[j]);
      return;
    }
    for (int j = 0; j < c.local.outerSize(); ++j)
      for (int k = c.local.outerIndexPtr()[j]; k < c.local.outerIndexPtr()[j + 1]; ++k)
        f(k, c.coords[c.local.innerIndexPtr()[k]], c.coords[j]);
  };
  std::vector<Eigen::Triplet<double>> t;
  for (const Contributor& c : parts_)
    each(c, [&](int, int r, int col) { t.emplace_back(r, col, 0.0); });
  pattern_.resize(n, n);
  pattern_.setFromTriplets(t.begin(), t.end());
  pattern_.makeCompressed();
  maps_.assign(parts_.size(), {});
  entries_.clear();
  for (std::size_t p = 0; p < parts_.size(); ++p) {
    const Contributor& c = parts_[p];
    std::vector<int>& m = maps_[p];
    m.resize(c.local.size() == 0 ? c.coords.size() * c.coords.size()
                                 : static_cast<std::size_t>(c.local.nonZeros()));
    each(c, [&](int k, int r, int col) {
      const int* b = pattern_.innerIndexPtr() + pattern_.outerIndexPtr()[col];
      const int* e = pattern_.innerIndexPtr() + pattern_.outerIndexPtr()[col + 1];
      const int* at = std::lower_bound(b, e, r);
      assert(at != e && *at == r);
      m[k] = static_cast<int>(at - pattern_.innerIndexPtr());
    });
    entries_.push_back(static_cast<int>(m.size()));
    bool identity = static_cast<Eigen::Index>(m.size()) == pattern_.nonZeros();
    for (std::size_t k = 0; identity && k < m.size(); ++k) identity = m[k] == static_cast<int>(k);
    if (identity && !m.empty()) std::vector<int>().swap(m);
  }
  parts_.clear();  // the maps are all that is needed from here on
}

void GlobalMatrix::reset(SpMat& K) const {
  if (!has_pattern(K, pattern_)) K = pattern_;
  std::fill_n(K.valuePtr(), K.nonZeros(), 0.0);
}

void GlobalMatrix::scatter(int id, const double* local, SpMat& K) const {
  double* v = K.valuePtr();
  const std::vector<int>& m = maps_[id];
  if (whole(id)) {
    for (int k = 0; k < entries_[id]; ++k) v[k] += local[k];
    return;
  }
  for (std::size_t k = 0; k < m.size(); ++k) v[m[k]] += local[k];
}

}  // namespace isoflex::system
