#include "isoflex/loads/time_function.hpp"

#include <muParser.h>

#include <charconv>
#include <cmath>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <utility>

namespace isoflex::loads {

namespace {

// The value of `s` when it is a plain finite number (surrounding blanks and one leading '+'
// allowed), otherwise nullopt.
std::optional<double> plain_number(const std::string& s) {
  const char* first = s.data();
  const char* last = s.data() + s.size();
  auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; };
  while (first != last && blank(*first)) ++first;
  while (first != last && blank(last[-1])) --last;
  if (first != last && *first == '+') ++first;
  if (first == last) return std::nullopt;
  double value = 0.0;
  const auto [ptr, ec] = std::from_chars(first, last, value);
  if (ec != std::errc() || ptr != last || !std::isfinite(value)) return std::nullopt;
  return value;
}

std::string format_constant(double value) {
  char buf[64];
  const auto [ptr, ec] = std::to_chars(buf, buf + sizeof buf, value);
  return ec == std::errc() ? std::string(buf, ptr) : std::string("0");
}

}  // namespace

struct TimeFunction::Impl {
  double t = 0.0;  // the variable (t, or the one named), bound by address into `parser`
  mu::Parser parser;

  Impl(const std::string& expression, const std::string& variable) {
    try {
      parser.DefineConst("pi", std::numbers::pi);
      if (variable != "e") parser.DefineConst("e", std::numbers::e);
      parser.DefineVar(variable, &t);
      parser.SetExpr(expression);
      parser.Eval();  // parses: reports syntax errors and unknown variables
      if (parser.GetNumResults() != 1)
        throw std::invalid_argument("invalid expression \"" + expression +
                                    "\": must yield a single value");
    } catch (const mu::Parser::exception_type& e) {
      throw std::invalid_argument("invalid expression \"" + expression + "\": " + e.GetMsg());
    }
  }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;
};

TimeFunction::TimeFunction() : expression_("0") {}

TimeFunction::TimeFunction(double value) : expression_(format_constant(value)), constant_(value) {}

TimeFunction::TimeFunction(const std::string& expression) : TimeFunction(expression, "t") {}

TimeFunction::TimeFunction(const std::string& expression, const std::string& variable)
    : expression_(expression), variable_(variable) {
  if (const auto value = plain_number(expression)) {
    constant_ = *value;
  } else {
    impl_ = std::make_unique<Impl>(expression, variable_);
  }
}

TimeFunction::TimeFunction(const TimeFunction& other)
    : expression_(other.expression_),
      variable_(other.variable_),
      constant_(other.constant_),
      impl_(other.impl_ ? std::make_unique<Impl>(other.expression_, other.variable_) : nullptr) {}

TimeFunction& TimeFunction::operator=(const TimeFunction& other) {
  if (this != &other) {
    TimeFunction copy(other);
    *this = std::move(copy);
  }
  return *this;
}

TimeFunction::TimeFunction(TimeFunction&& other) noexcept = default;
TimeFunction& TimeFunction::operator=(TimeFunction&& other) noexcept = default;
TimeFunction::~TimeFunction() = default;

double TimeFunction::operator()(double t) const {
  if (!impl_) return constant_;
  impl_->t = t;
  return impl_->parser.Eval();
}

Vec3 evaluate(const std::optional<std::array<TimeFunction, 3>>& f, double t) {
  if (!f) return Vec3::Zero();
  return Vec3((*f)[0](t), (*f)[1](t), (*f)[2](t));
}

}  // namespace isoflex::loads
