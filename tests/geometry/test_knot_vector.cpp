// Knot vectors: construction checks, find_span at the ends, at (repeated) interior knots and
// outside the domain, breakpoints, multiplicities and non-empty spans — all against values
// worked out by hand from the definitions of IGA-thesis §4.1.2.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "isoflex/geometry/knot_vector.hpp"
#include "support/geometry.hpp"

using namespace isoflex::geometry;
using namespace isoflex::test;

TEST(KnotVector, BasicQueriesOfThesisFigure42) {
  // Fig. 4.2: p = 2, (0,0,0,0.2,0.4,0.6,0.8,0.8,1,1,1): 11 knots, 8 functions, 5 elements.
  const KnotVector kv(2, {0, 0, 0, 0.2, 0.4, 0.6, 0.8, 0.8, 1, 1, 1});
  EXPECT_EQ(kv.degree(), 2);
  EXPECT_EQ(kv.n_basis(), 8);
  EXPECT_EQ(kv.front(), 0.0);
  EXPECT_EQ(kv.back(), 1.0);
  EXPECT_TRUE(kv.is_open());
  EXPECT_EQ(kv.breakpoints(), (std::vector<double>{0, 0.2, 0.4, 0.6, 0.8, 1}));
  EXPECT_EQ(kv.multiplicity(0.8), 2);
  EXPECT_EQ(kv.multiplicity(0.0), 3);
  EXPECT_EQ(kv.multiplicity(0.5), 0);
  EXPECT_EQ(kv.element_spans(), (std::vector<int>{2, 3, 4, 5, 7}));
}

TEST(KnotVector, FindSpanEdgeCases) {
  const KnotVector kv(2, {0, 0, 0, 0.2, 0.4, 0.6, 0.8, 0.8, 1, 1, 1});
  EXPECT_EQ(kv.find_span(0.0), 2);  // left end: first non-empty span
  EXPECT_EQ(kv.find_span(0.1), 2);
  EXPECT_EQ(kv.find_span(0.2), 3);  // at an interior knot: the span that starts there
  EXPECT_EQ(kv.find_span(0.79), 5);
  EXPECT_EQ(kv.find_span(0.8), 7);   // double knot: skip the empty span [0.8, 0.8)
  EXPECT_EQ(kv.find_span(1.0), 7);   // right end belongs to the last non-empty span
  EXPECT_EQ(kv.find_span(-5.0), 2);  // clamped
  EXPECT_EQ(kv.find_span(7.0), 7);   // clamped
  EXPECT_EQ(kv.find_span(std::nextafter(1.0, 0.0)), 7);
  EXPECT_THROW(kv.find_span(std::nan("")), std::invalid_argument);

  // Repeated knot of multiplicity p at the very end of the interior.
  const KnotVector kv3(3, {0, 0, 0, 0, 0.5, 0.5, 0.5, 1, 1, 1, 1});
  EXPECT_EQ(kv3.find_span(0.5), 6);
  EXPECT_EQ(kv3.find_span(std::nextafter(0.5, 0.0)), 3);
  EXPECT_EQ(kv3.find_span(1.0), 6);

  // Degree 0: spans are the knot intervals themselves.
  const KnotVector k0(0, {0, 1, 2, 3});
  EXPECT_EQ(k0.find_span(0.0), 0);
  EXPECT_EQ(k0.find_span(1.0), 1);
  EXPECT_EQ(k0.find_span(3.0), 2);

  // An end knot repeated more than p + 1 times is not open: its extra basis function vanishes on
  // the domain, and degree elevation wrote past its arrays on it (issue #15, found by
  // fuzz/cad_patch_fuzzer.cpp).
  EXPECT_FALSE(KnotVector(2, {0, 0, 0, 0, 0.5, 1, 1, 1}).is_open());
  EXPECT_FALSE(KnotVector(2, {0, 0, 0, 0.5, 1, 1, 1, 1}).is_open());
  EXPECT_FALSE(KnotVector(1, {0, 0, 0, 1, 1, 1}).is_open());
  EXPECT_TRUE(KnotVector(1, {0, 0, 1, 1}).is_open());
  EXPECT_TRUE(KnotVector(0, {0, 1}).is_open());

  // Non-open knot vector: domain [knots[p], knots[n]] = [2, 4].
  const KnotVector kn(2, {0, 1, 2, 3, 4, 5, 6});
  EXPECT_FALSE(kn.is_open());
  EXPECT_EQ(kn.front(), 2.0);
  EXPECT_EQ(kn.back(), 4.0);
  EXPECT_EQ(kn.find_span(0.0), 2);
  EXPECT_EQ(kn.find_span(3.0), 3);
  EXPECT_EQ(kn.find_span(4.0), 3);
}

TEST(KnotVector, FindSpanBracketsRandomParameters) {
  std::mt19937 g(11);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  const KnotVector kv(3, {0, 0, 0, 0, 0.1, 0.1, 0.35, 0.5, 0.5, 0.5, 0.9, 1, 1, 1, 1});
  for (int k = 0; k < 1000; ++k) {
    const double u = U(g);
    const int s = kv.find_span(u);
    ASSERT_GE(s, kv.degree());
    ASSERT_LT(s, kv.n_basis());
    EXPECT_LE(kv.knots()[s], u);
    EXPECT_LT(u, kv.knots()[s + 1]);
  }
}

TEST(KnotVector, OpenUniform) {
  const KnotVector kv = KnotVector::open_uniform(3, 4);
  EXPECT_EQ(kv.knots(), (std::vector<double>{0, 0, 0, 0, 0.25, 0.5, 0.75, 1, 1, 1, 1}));
  EXPECT_EQ(kv.n_basis(), 7);  // n_spans + p
  EXPECT_TRUE(kv.is_open());
  EXPECT_EQ(KnotVector::open_uniform(0, 2).knots(), (std::vector<double>{0, 0.5, 1}));
}

TEST(KnotVector, InvalidInputThrowsWithClearMessage) {
  EXPECT_NE(message_of([] {
              KnotVector(2, {0, 0, 0, 0.5, 0.4, 1, 1, 1});
            }).find("is smaller than knot"),
            std::string::npos);
  EXPECT_NE(message_of([] {
              KnotVector(2, {0, 0, 0, 1, 1});
            }).find("fewer than 2(p+1)"),
            std::string::npos);
  EXPECT_NE(message_of([] { KnotVector(-1, {0, 1}); }).find("degree -1"), std::string::npos);
  EXPECT_NE(message_of([] {
              KnotVector(kMaxDegree + 1, std::vector<double>(30, 0.0));
            }).find("degree 11"),
            std::string::npos);
  EXPECT_NE(message_of([] {
              KnotVector(1, {0, 0, 0, 0});
            }).find("empty parameter domain"),
            std::string::npos);
  EXPECT_NE(message_of([] {
              KnotVector(1, {0, 0, std::nan(""), 1, 1});
            }).find("not finite"),
            std::string::npos);
  EXPECT_NE(message_of([] { KnotVector::open_uniform(2, 0); }).find("at least one span"),
            std::string::npos);
  EXPECT_NE(message_of([] { KnotVector::open_uniform(-3, 2); }).find("degree -3"),
            std::string::npos);
}
