#pragma once
// A force law of one variable for the spring–dampers (docs/theory/coupling.md §6): the force
// N(x) of a spring in its elongation x = e (tension > 0), or of a damper in its rate x = v. Either
// linear, N = k x, or a muParser expression in the variable (loads::TimeFunction with its own
// variable name), e.g. "2e3*e + 5e5*e^3".
//
// For a spring the law has an energy V(x) = ∫₀ˣ N, evaluated by a 16-point Gauss–Legendre rule
// on [0, x] (exact for polynomial laws up to degree 31, to the rule's accuracy otherwise), and a
// mean force over an increment, N̄(x₀, x₁) = (V(x₁) − V(x₀)) / (x₁ − x₀), for which
// N̄ Δx = ΔV holds with the V reported: the discrete gradient of a function of one variable
// (DNSM-III (17)). Below a relative increment of 1e-5 the quotient (which loses digits there)
// is replaced by the midpoint force N(x̄), whose energy error is O(N″ Δx³), below round-off.
// N′ (the tangents) is a five-point central difference of the expression.
//
// An expression law evaluates its parser, which writes its variable: one object must not be
// evaluated on two threads at once (elements are evaluated on one thread, elements/element.hpp).
#include <array>
#include <optional>
#include <string>

#include "isoflex/loads/time_function.hpp"

namespace isoflex::elements {

class ForceLaw {
 public:
  // The linear law N = k x (k = 0: no force).
  explicit ForceLaw(double k = 0.0);
  // An expression in `variable`; throws std::invalid_argument (muParser's message) for a
  // malformed expression or another variable.
  ForceLaw(const std::string& expression, const std::string& variable);

  bool linear() const { return !expression_; }
  double slope() const { return k_; }  // k of a linear law
  // The expression, empty for a linear law.
  std::string expression() const { return expression_ ? expression_->expression() : ""; }

  double force(double x) const;       // N(x)
  double derivative(double x) const;  // N′(x)
  double energy(double x) const;      // V(x) = ∫₀ˣ N
  // N̄(x₀, x₁) with V(x₁) − V(x₀) = N̄ (x₁ − x₀); d_dx1 (if not null) receives ∂N̄/∂x₁.
  double mean(double x0, double x1, double* d_dx1) const;

 private:
  static constexpr int kPoints = 16;  // Gauss–Legendre points of V(x) = ∫₀ˣ N
  double k_ = 0.0;
  std::array<double, kPoints> s_{}, w_{};  // the rule on [0, 1]
  std::optional<loads::TimeFunction> expression_;
};

}  // namespace isoflex::elements
