#include "isoflex/system/linear_constraints.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
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

DofMap DofMap::build(int n_full, const std::vector<int>& eliminated,
                     const std::vector<std::vector<std::pair<int, double>>>& tied) {
  DofMap m;
  m.n_full = n_full;
  const auto check = [&](int i, const char* what) {
    if (i < 0 || i >= n_full)
      throw std::invalid_argument(
          fmt::format("DofMap: {} dof {} outside [0, {})", what, i, n_full));
  };
  constexpr int is_free = 0, is_eliminated = -1, is_slave = -2;
  std::vector<int> status(static_cast<std::size_t>(n_full), is_free);
  for (int i : eliminated) {
    check(i, "eliminated");
    status[static_cast<std::size_t>(i)] = is_eliminated;
  }
  // Slave expressions over the dofs that are not slaves, kept so when a dof becomes a slave
  // (substituted into the expressions that use it, found by `users`).
  using Terms = std::map<int, double>;
  std::map<int, Terms> expr;
  std::map<int, std::vector<int>> users;
  for (const auto& row : tied) {
    Terms acc;
    double size = 0.0;
    for (const auto& [j, a] : row) {
      check(j, "tied");
      size = std::max(size, std::abs(a));
      if (status[static_cast<std::size_t>(j)] == is_slave)
        for (const auto& [k, c] : expr.at(j)) acc[k] += a * c;
      else
        acc[j] += a;
    }
    int pivot = -1;
    double best = 1e-12 * size;
    for (const auto& [j, a] : acc)
      if (status[static_cast<std::size_t>(j)] == is_free && std::abs(a) > best) {
        best = std::abs(a);
        pivot = j;
      }
    if (pivot < 0) {
      ++m.dropped_tied_rows;
      continue;
    }
    Terms e;
    const double ap = acc.at(pivot);
    for (const auto& [k, a] : acc)
      if (k != pivot && std::abs(a) > 1e-14 * size) e[k] = -a / ap;
    if (const auto u = users.find(pivot); u != users.end()) {
      for (int s : u->second) {
        Terms& t = expr.at(s);
        const auto it = t.find(pivot);
        if (it == t.end()) continue;
        const double c = it->second;
        t.erase(it);
        for (const auto& [k, ck] : e) {
          t[k] += c * ck;
          users[k].push_back(s);
        }
      }
      users.erase(u);
    }
    for (const auto& [k, ck] : e) users[k].push_back(pivot);
    status[static_cast<std::size_t>(pivot)] = is_slave;
    expr.emplace(pivot, std::move(e));
  }
  m.full_to_free.assign(static_cast<std::size_t>(n_full), -1);
  for (int i = 0; i < n_full; ++i)
    if (status[static_cast<std::size_t>(i)] == is_free) {
      m.full_to_free[static_cast<std::size_t>(i)] = static_cast<int>(m.free.size());
      m.free.push_back(i);
    }
  for (auto& [dof, terms] : expr) {
    Slave s{dof, {}};
    for (const auto& [k, c] : terms)
      if (c != 0.0) s.terms.emplace_back(k, c);
    m.slaves.push_back(std::move(s));
  }
  return m;
}

void DofMap::set_slaves(VecX& x, const VecX& X) const {
  for (const Slave& s : slaves) {
    double u = 0.0;
    for (const auto& [k, c] : s.terms) u += c * (x(k) - X(k));
    x(s.dof) = X(s.dof) + u;
  }
}

VecX DofMap::reduce(const VecX& r) const {
  VecX out(n_free());
  for (int f = 0; f < n_free(); ++f) out(f) = r(free[static_cast<std::size_t>(f)]);
  for (const Slave& s : slaves)
    for (const auto& [k, c] : s.terms)
      if (const int f = full_to_free[static_cast<std::size_t>(k)]; f >= 0) out(f) += c * r(s.dof);
  return out;
}

std::vector<std::pair<int, double>> DofMap::expansion(int i) const {
  if (const int f = full_to_free[static_cast<std::size_t>(i)]; f >= 0) return {{f, 1.0}};
  std::vector<std::pair<int, double>> out;
  const auto it = std::lower_bound(slaves.begin(), slaves.end(), i,
                                   [](const Slave& s, int dof) { return s.dof < dof; });
  if (it == slaves.end() || it->dof != i) return out;
  for (const auto& [k, c] : it->terms)
    if (const int f = full_to_free[static_cast<std::size_t>(k)]; f >= 0) out.emplace_back(f, c);
  return out;
}

}  // namespace isoflex::system
