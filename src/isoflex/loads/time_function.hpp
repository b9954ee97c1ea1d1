#pragma once
// A scalar function of time f(t), written as a muParser expression in the variable `t`
// (e.g. "1000*sin(pi*t)*(t<=2)"). Used for the components of prescribed forces and moments, and,
// with another variable name, for the force laws of springs (N(e) in the elongation `e`, N_d(v) in
// the rate `v`: elements/force_law.hpp).
//
// The constants `pi` and `e` are defined; every muParser built-in (sin, cos, tan, exp, log, sqrt,
// abs, min, max, sign, the comparisons <, <=, ==, !=, >=, >, &&, ||, and the ternary c ? a : b)
// is available. A string that is a plain number (e.g. "0", "-9.81", "1e3") is recognised at
// construction and evaluated without the parser.
//
// muParser binds the *address* of `t`, so the variable and the parser live together in a heap
// object owned by the TimeFunction; moving keeps that object, copying compiles the expression
// anew. Copies are therefore independent and may be evaluated on different threads; a single
// object must not be evaluated concurrently (evaluation writes its variable).
#include <array>
#include <memory>
#include <optional>
#include <string>

#include "isoflex/math/types.hpp"

namespace isoflex::loads {

class TimeFunction {
 public:
  // The constant 0.
  TimeFunction();
  // The constant `value`.
  explicit TimeFunction(double value);
  // Compiles `expression`; throws std::invalid_argument (with muParser's message and the
  // expression) when it is malformed, uses a variable other than `t`, or yields more than one
  // value. The expression is evaluated once (at t = 0) to detect these errors.
  explicit TimeFunction(const std::string& expression);
  // The same in the variable `variable` instead of `t` (a name muParser accepts, not pi or e).
  TimeFunction(const std::string& expression, const std::string& variable);

  TimeFunction(const TimeFunction& other);
  TimeFunction& operator=(const TimeFunction& other);
  TimeFunction(TimeFunction&& other) noexcept;
  TimeFunction& operator=(TimeFunction&& other) noexcept;
  ~TimeFunction();

  double operator()(double t) const;

  // True when the expression is a plain number (evaluated without the parser).
  bool is_constant() const { return impl_ == nullptr; }
  const std::string& expression() const { return expression_; }
  const std::string& variable() const { return variable_; }

 private:
  struct Impl;
  std::string expression_;
  std::string variable_ = "t";
  double constant_ = 0.0;  // the value when is_constant()
  std::unique_ptr<Impl> impl_;
};

// The vector of three time functions at t; zero when there are none (an optional force or
// moment of a load).
Vec3 evaluate(const std::optional<std::array<TimeFunction, 3>>& f, double t);

}  // namespace isoflex::loads
