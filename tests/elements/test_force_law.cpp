// The force laws of the spring–dampers (elements/force_law.hpp, docs/theory/coupling.md §6):
// linear and expression laws, the energy by quadrature, the mean force of an increment
// (N̄ Δx = ΔV, the discrete gradient of one variable), the derivative and its tangent.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "isoflex/elements/force_law.hpp"

using isoflex::elements::ForceLaw;

TEST(ForceLaw, LinearLawInClosedForm) {
  const ForceLaw k(3.0);
  EXPECT_TRUE(k.linear());
  EXPECT_EQ(k.force(2.0), 6.0);
  EXPECT_EQ(k.derivative(-1.0), 3.0);
  EXPECT_EQ(k.energy(2.0), 6.0);
  double d = 0.0;
  EXPECT_EQ(k.mean(1.0, 3.0, &d), 6.0);
  EXPECT_EQ(d, 1.5);
}

// N = 100 e + 2000 e³: V = 50 e² + 500 e⁴ exactly (16 Gauss points integrate degree 31),
// N̄ (e₁ − e₀) = ΔV to round-off, N̄(e, e) = N(e), N′ from differences to 1e-9.
TEST(ForceLaw, CubicLawEnergyMeanAndDerivative) {
  const ForceLaw law("100*e + 2000*e^3", "e");
  EXPECT_FALSE(law.linear());
  for (const double e : {-0.3, 0.0, 0.05, 0.7}) {
    EXPECT_NEAR(law.energy(e), 50 * e * e + 500 * std::pow(e, 4),
                1e-14 * std::max(1.0, law.energy(e)));
    EXPECT_NEAR(law.derivative(e), 100 + 6000 * e * e, 1e-9 * (100 + 6000 * e * e));
  }
  for (const auto& [e0, e1] : {std::pair{0.1, 0.4}, {-0.2, 0.3}, {0.5, 0.5 + 1e-7}, {0.2, 0.2}}) {
    double d = 0.0;
    const double m = law.mean(e0, e1, &d);
    if (e1 != e0)
      EXPECT_NEAR(m * (e1 - e0), law.energy(e1) - law.energy(e0),
                  1e-14 * std::abs(law.energy(e1)) + 1e-16);
    else
      EXPECT_EQ(m, law.force(e0));
    // ∂N̄/∂e₁ against a central difference of N̄ (away from the midpoint switch).
    if (std::abs(e1 - e0) > 1e-3) {
      const double h = 1e-6;
      const double fd = (law.mean(e0, e1 + h, nullptr) - law.mean(e0, e1 - h, nullptr)) / (2 * h);
      EXPECT_NEAR(d, fd, 1e-6 * std::abs(fd));
    }
  }
}

// A law that is no polynomial: the quadrature is accurate, and N̄ Δx = ΔV holds for the V it
// gives, which is what the energy balance of a run uses.
TEST(ForceLaw, SmoothLawIsConsistentWithItsQuadratureEnergy) {
  const ForceLaw law("50*tanh(4*e)", "e");
  const double e = 0.6;
  EXPECT_NEAR(law.energy(e), 50.0 / 4.0 * std::log(std::cosh(4 * e)), 1e-13);
  const double m = law.mean(0.2, 0.6, nullptr);
  EXPECT_NEAR(m * 0.4, law.energy(0.6) - law.energy(0.2), 1e-14);
}

TEST(ForceLaw, ExpressionErrors) {
  EXPECT_THROW(ForceLaw("2*x", "e"), std::invalid_argument);
  EXPECT_THROW(ForceLaw("2*t", "v"), std::invalid_argument);  // another variable
  // In a law of v, e is Euler's number; in a law of e, the elongation.
  EXPECT_NEAR(ForceLaw("e*v", "v").force(2.0), 2.0 * std::exp(1.0), 1e-15);
  EXPECT_EQ(ForceLaw("e*e", "e").force(3.0), 9.0);
}
