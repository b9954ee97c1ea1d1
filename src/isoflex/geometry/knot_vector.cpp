#include "isoflex/geometry/knot_vector.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace isoflex::geometry {

KnotVector::KnotVector(int degree, std::vector<double> knots)
    : p_(degree), knots_(std::move(knots)) {
  if (p_ < 0 || p_ > kMaxDegree)
    throw std::invalid_argument("knot vector: degree " + std::to_string(p_) + " outside [0, " +
                                std::to_string(kMaxDegree) + "]");
  if (knots_.size() < 2 * static_cast<std::size_t>(p_ + 1))
    throw std::invalid_argument("knot vector: " + std::to_string(knots_.size()) +
                                " knots are fewer than 2(p+1) = " + std::to_string(2 * (p_ + 1)));
  for (std::size_t i = 0; i < knots_.size(); ++i)
    if (!std::isfinite(knots_[i]))
      throw std::invalid_argument("knot vector: knot " + std::to_string(i) + " is not finite");
  for (std::size_t i = 1; i < knots_.size(); ++i)
    if (knots_[i] < knots_[i - 1])
      throw std::invalid_argument("knot vector: knot " + std::to_string(i) + " = " +
                                  std::to_string(knots_[i]) + " is smaller than knot " +
                                  std::to_string(i - 1) + " = " + std::to_string(knots_[i - 1]));
  if (!(back() > front())) throw std::invalid_argument("knot vector: empty parameter domain");
}

bool KnotVector::is_open() const {
  const auto n = knots_.size();
  for (int i = 0; i < p_; ++i)
    if (knots_[i] != knots_[p_] || knots_[n - 1 - i] != knots_[n - 1 - p_]) return false;
  // Exactly p + 1: a (p + 2)-fold end knot adds a basis function that vanishes on the whole
  // domain, and degree elevation (The NURBS Book A5.9) assumes p + 1 (it wrote past its arrays
  // on 0, 0, 0, 0, … with p = 2; found by fuzz/cad_patch_fuzzer.cpp). knots_[p + 1] and
  // knots_[n − p − 2] exist: there are at least 2(p + 1) knots.
  return knots_[p_ + 1] > knots_[p_] && knots_[n - 2 - p_] < knots_[n - 1 - p_];
}

int KnotVector::find_span(double u) const {
  // A NaN would fail every comparison below and bisect to the out-of-range span n.
  if (std::isnan(u)) throw std::invalid_argument("knot vector: find_span of NaN");
  const int n = n_basis();
  if (u >= knots_[n]) {
    // Last non-empty span (u = back() belongs to it).
    int s = n - 1;
    while (s > p_ && knots_[s] == knots_[s + 1]) --s;
    return s;
  }
  if (u <= knots_[p_]) {
    int s = p_;
    while (s < n - 1 && knots_[s] == knots_[s + 1]) ++s;
    return s;
  }
  // knots_[s] <= u < knots_[s+1] by bisection on [p, n).
  const auto first = knots_.begin() + p_;
  const auto last = knots_.begin() + n + 1;
  return static_cast<int>(std::upper_bound(first, last, u) - knots_.begin()) - 1;
}

std::vector<double> KnotVector::breakpoints() const {
  std::vector<double> b;
  for (int i = p_; i <= n_basis(); ++i)
    if (b.empty() || knots_[i] != b.back()) b.push_back(knots_[i]);
  return b;
}

int KnotVector::multiplicity(double u) const {
  return static_cast<int>(std::count(knots_.begin(), knots_.end(), u));
}

std::vector<int> KnotVector::element_spans() const {
  std::vector<int> spans;
  for (int s = p_; s < n_basis(); ++s)
    if (knots_[s + 1] > knots_[s]) spans.push_back(s);
  return spans;
}

KnotVector KnotVector::open_uniform(int degree, int n_spans) {
  if (n_spans < 1) throw std::invalid_argument("knot vector: need at least one span");
  // Checked here too: a negative degree would otherwise size the vector below.
  if (degree < 0 || degree > kMaxDegree)
    throw std::invalid_argument("knot vector: degree " + std::to_string(degree) + " outside [0, " +
                                std::to_string(kMaxDegree) + "]");
  std::vector<double> k(degree, 0.0);
  for (int i = 0; i <= n_spans; ++i) k.push_back(static_cast<double>(i) / n_spans);
  k.insert(k.end(), degree, 1.0);
  return KnotVector(degree, std::move(k));
}

}  // namespace isoflex::geometry
