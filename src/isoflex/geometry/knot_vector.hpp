#pragma once
// Knot vectors of B-splines and NURBS (IGA-thesis §4.1): non-decreasing knots, degree p,
// n = size − p − 1 basis functions. Open (exactly p+1-fold end knots) vectors are what CAD writes
// and what analysis needs; non-open vectors are accepted by the kernel but reported by
// is_open() (a more than p+1-fold end knot gives a basis function that is zero on the domain).
#include <vector>

namespace isoflex::geometry {

class KnotVector {
 public:
  KnotVector() = default;
  // Throws std::invalid_argument if a knot is not finite, the knots decrease, the degree is < 0
  // or > kMaxDegree, there are fewer than 2(p+1) knots or the domain [front, back] is empty.
  KnotVector(int degree, std::vector<double> knots);

  int degree() const { return p_; }
  const std::vector<double>& knots() const { return knots_; }
  int n_basis() const { return static_cast<int>(knots_.size()) - p_ - 1; }
  double front() const { return knots_[p_]; }                     // start of the parameter domain
  double back() const { return knots_[knots_.size() - p_ - 1]; }  // end of the domain
  bool is_open() const;
  // Span index s with knots[s] <= u < knots[s+1], p <= s <= n−1; u = back() gives the last
  // non-empty span. u outside the domain is clamped; NaN throws std::invalid_argument.
  int find_span(double u) const;
  // Distinct knots in [front, back] and their multiplicities.
  std::vector<double> breakpoints() const;
  int multiplicity(double u) const;
  // Non-empty spans (knot spans of positive length): their span indices, in order.
  std::vector<int> element_spans() const;

  // Open uniform knot vector on [0, 1] with n_spans spans.
  static KnotVector open_uniform(int degree, int n_spans);

 private:
  int p_ = 0;
  std::vector<double> knots_;
};

constexpr int kMaxDegree = 10;

}  // namespace isoflex::geometry
