#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "isoflex/loads/time_function.hpp"

using isoflex::loads::TimeFunction;

TEST(TimeFunction, DefaultIsZero) {
  const TimeFunction f;
  EXPECT_TRUE(f.is_constant());
  EXPECT_EQ(f(3.0), 0.0);
}

TEST(TimeFunction, PlainNumbersSkipTheParser) {
  for (const auto& [text, value] : std::vector<std::pair<std::string, double>>{
           {"0", 0.0}, {"-9.81", -9.81}, {" 1e3 ", 1000.0}, {"+2.5", 2.5}, {"1.5E-2", 0.015}}) {
    const TimeFunction f(text);
    EXPECT_TRUE(f.is_constant()) << text;
    EXPECT_EQ(f(0.0), value) << text;
    EXPECT_EQ(f(7.0), value) << text;
    EXPECT_EQ(f.expression(), text);
  }
  const TimeFunction c(4.25);
  EXPECT_TRUE(c.is_constant());
  EXPECT_EQ(c(1.0), 4.25);
  EXPECT_EQ(c.expression(), "4.25");
}

TEST(TimeFunction, EvaluatesExpressionsInT) {
  const TimeFunction f("1000*sin(pi*t)*(t<=2)");
  EXPECT_FALSE(f.is_constant());
  EXPECT_NEAR(f(0.5), 1000.0, 1e-12);
  EXPECT_NEAR(f(1.5), -1000.0, 1e-12);
  EXPECT_EQ(f(2.5), 0.0);
  EXPECT_NEAR(TimeFunction("2*t")(3.0), 6.0, 0.0);
  EXPECT_NEAR(TimeFunction("e")(0.0), std::numbers::e, 0.0);
  EXPECT_NEAR(TimeFunction("exp(-t)*cos(t) + abs(t-3) + min(t,1) + max(t,1)")(2.0),
              std::exp(-2.0) * std::cos(2.0) + 1.0 + 1.0 + 2.0, 1e-15);
  EXPECT_EQ(TimeFunction("t > 1 ? 5 : -5")(2.0), 5.0);
  EXPECT_EQ(TimeFunction("t > 1 ? 5 : -5")(0.0), -5.0);
  // An expression that only looks numeric is still compiled.
  EXPECT_EQ(TimeFunction("2*3")(0.0), 6.0);
}

TEST(TimeFunction, MalformedExpressionThrowsWithMessageAndExpression) {
  for (const std::string bad : {"sin(t", "2*x", "t +* 3", "", "foo(t)", "1,2", "nan", "inf"}) {
    try {
      TimeFunction f(bad);
      ADD_FAILURE() << "no exception for \"" << bad << "\"";
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("\"" + bad + "\""), std::string::npos) << what;
      EXPECT_GT(what.size(), bad.size() + 25) << what;  // carries muParser's message
    }
  }
  try {
    TimeFunction f("2*x");
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("\"x\""), std::string::npos) << e.what();
  }
}

TEST(TimeFunction, CopiesAndMovesStayBoundToTheirOwnVariable) {
  TimeFunction a("3*t+1");
  TimeFunction b = a;  // copy compiles anew
  EXPECT_EQ(a(1.0), 4.0);
  EXPECT_EQ(b(2.0), 7.0);
  EXPECT_EQ(a(0.0), 1.0);

  std::vector<TimeFunction> v;
  for (int k = 0; k < 20; ++k) v.emplace_back("t*" + std::to_string(k));  // reallocations move
  for (int k = 0; k < 20; ++k) EXPECT_EQ(v[k](2.0), 2.0 * k);

  TimeFunction c(std::move(b));
  EXPECT_EQ(c(5.0), 16.0);
  TimeFunction d;
  d = c;
  EXPECT_EQ(d(1.0), 4.0);
  d = TimeFunction("t*t");
  EXPECT_EQ(d(3.0), 9.0);
  d = TimeFunction("7");
  EXPECT_TRUE(d.is_constant());
  EXPECT_EQ(d(3.0), 7.0);
  {
    TimeFunction tmp("t-1");
    d = tmp;
  }
  EXPECT_EQ(d(3.0), 2.0);
  d = d;  // self-assignment
  EXPECT_EQ(d(4.0), 3.0);
}

TEST(TimeFunction, CopiesCanBeEvaluatedOnDifferentThreads) {
  const TimeFunction f("sin(t)*t");
  std::vector<TimeFunction> copies(4, f);
  std::vector<double> err(copies.size(), 0.0);
  std::vector<std::thread> threads;
  for (std::size_t i = 0; i < copies.size(); ++i)
    threads.emplace_back([&, i] {
      for (int k = 0; k < 20000; ++k) {
        const double t = 1e-3 * k + static_cast<double>(i);
        err[i] = std::max(err[i], std::abs(copies[i](t) - std::sin(t) * t));
      }
    });
  for (auto& th : threads) th.join();
  for (double e : err) EXPECT_LT(e, 1e-12);
}
