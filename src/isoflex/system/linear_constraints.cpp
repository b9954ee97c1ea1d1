#include "isoflex/system/linear_constraints.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>
#include <utility>

namespace isoflex::system {

void LinearConstraints::eliminate(int dof, std::function<double(double)> value) {
  const auto it = std::lower_bound(eliminated.begin(), eliminated.end(), dof);
  const auto pos = it - eliminated.begin();
  if (eliminated_value.size() < eliminated.size()) eliminated_value.resize(eliminated.size());
  if (it != eliminated.end() && *it == dof) {
    eliminated_value[static_cast<std::size_t>(pos)] = std::move(value);
    return;
  }
  eliminated.insert(it, dof);
  eliminated_value.insert(eliminated_value.begin() + pos, std::move(value));
}

DofMap DofMap::build(int n_full, const std::vector<int>& eliminated) {
  DofMap m;
  m.n_full = n_full;
  m.full_to_free.assign(static_cast<std::size_t>(n_full), 0);
  for (int i : eliminated) {
    if (i < 0 || i >= n_full)
      throw std::invalid_argument(
          fmt::format("DofMap: eliminated dof {} outside [0, {})", i, n_full));
    m.full_to_free[static_cast<std::size_t>(i)] = -1;
  }
  for (int i = 0; i < n_full; ++i)
    if (m.full_to_free[static_cast<std::size_t>(i)] == 0) {
      m.full_to_free[static_cast<std::size_t>(i)] = static_cast<int>(m.free.size());
      m.free.push_back(i);
    }
  return m;
}

}  // namespace isoflex::system
