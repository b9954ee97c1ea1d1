#include "isoflex/system/global_matrix.hpp"

#include <algorithm>
#include <cassert>
#include <stdexcept>

#include "isoflex/math/sparse_pattern.hpp"

namespace isoflex::system {

int GlobalMatrix::add(SpMat local, std::vector<int> coords) {
  assert(local.rows() == static_cast<int>(coords.size()) && local.cols() == local.rows());
  local.makeCompressed();
  parts_.emplace_back();
  parts_.back().local.swap(local);
  parts_.back().coords = std::move(coords);
  return static_cast<int>(parts_.size()) - 1;
}

int GlobalMatrix::add_dense(std::vector<int> coords) {
  parts_.push_back({SpMat(), std::move(coords)});
  return static_cast<int>(parts_.size()) - 1;
}

void GlobalMatrix::finalize(int n) {
  // The global rows of contributor c's local column j, appended to `rows`.
  auto append_rows = [](const Contributor& c, int j, std::vector<int>& rows) {
    if (c.local.size() == 0) {
      rows.insert(rows.end(), c.coords.begin(), c.coords.end());
      return;
    }
    for (int k = c.local.outerIndexPtr()[j]; k < c.local.outerIndexPtr()[j + 1]; ++k)
      rows.push_back(c.coords[static_cast<std::size_t>(c.local.innerIndexPtr()[k])]);
  };
  // The (contributor, local column) pairs of every global column, grouped by column.
  std::vector<int> start(static_cast<std::size_t>(n) + 1, 0);
  for (const Contributor& c : parts_)
    for (int g : c.coords) ++start[static_cast<std::size_t>(g) + 1];
  for (int j = 0; j < n; ++j) start[j + 1] += start[j];
  std::vector<std::pair<int, int>> sources(static_cast<std::size_t>(start[n]));
  {
    std::vector<int> next(start.begin(), start.end() - 1);
    for (std::size_t p = 0; p < parts_.size(); ++p)
      for (std::size_t j = 0; j < parts_[p].coords.size(); ++j)
        sources[static_cast<std::size_t>(next[parts_[p].coords[j]]++)] = {static_cast<int>(p),
                                                                          static_cast<int>(j)};
  }
  // A column's rows: the union of its sources' rows. The values are not written: reset() copies
  // the structure alone (at 10⁶ unknowns a gigabyte never touched).
  pattern_by_columns(
      n, n,
      [&](int g, std::vector<int>& rows) {
        for (int s = start[g]; s < start[g + 1]; ++s) {
          const auto [p, j] = sources[static_cast<std::size_t>(s)];
          append_rows(parts_[static_cast<std::size_t>(p)], j, rows);
        }
      },
      pattern_, /*zero_values=*/false);

  maps_.assign(parts_.size(), {});
  std::vector<int> rows;
  entries_.clear();
  for (std::size_t p = 0; p < parts_.size(); ++p) {
    const Contributor& c = parts_[p];
    const int size = static_cast<int>(c.coords.size());
    const long long count = c.local.size() == 0 ? static_cast<long long>(size) * size
                                                : static_cast<long long>(c.local.nonZeros());
    entries_.push_back(static_cast<int>(count));
    // The whole pattern in its own storage order (one patch alone): no map.
    if (count > 0 && count == pattern_.nonZeros() && size == n && c.local.size() != 0) {
      bool same = true;
      for (int i = 0; same && i < n; ++i) same = c.coords[static_cast<std::size_t>(i)] == i;
      same = same && std::equal(c.local.innerIndexPtr(), c.local.innerIndexPtr() + count,
                                pattern_.innerIndexPtr());
      if (same) continue;
    }
    std::vector<int>& m = maps_[p];
    m.resize(static_cast<std::size_t>(count));
    std::size_t k = 0;
    for (int j = 0; j < size; ++j) {
      rows.clear();
      append_rows(c, j, rows);
      const int g = c.coords[static_cast<std::size_t>(j)];
      const int* b = pattern_.innerIndexPtr() + pattern_.outerIndexPtr()[g];
      const int* e = pattern_.innerIndexPtr() + pattern_.outerIndexPtr()[g + 1];
      for (int r : rows) {
        const int* at = std::lower_bound(b, e, r);
        assert(at != e && *at == r);
        m[k++] = static_cast<int>(at - pattern_.innerIndexPtr());
      }
    }
  }
  parts_.clear();  // the maps are all that is needed from here on
}

void GlobalMatrix::reset(SpMat& K) const {
  if (!has_pattern(K, pattern_)) copy_structure(pattern_, K);
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
