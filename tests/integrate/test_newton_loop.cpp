// The shared Newton loop (integrate/newton_loop.hpp): how it reports a failure. A residual that
// grows by orders of magnitude is reported as diverged, with the scale of the start value (a
// diverged iterate's scale would be meaningless); one that merely runs out of iterations is not.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "isoflex/integrate/newton_loop.hpp"

using namespace isoflex;

namespace {

// Newton on r(x) = ∛x (one unknown): every correction overshoots, x_{k+1} = −2 x_k, and |r|
// grows by 2^{1/3} per iteration; scale 2 (as the energy–momentum step's, fixed by the model).
std::string failure(double x0, int max_iterations) {
  model::Solver settings;
  settings.max_iterations = max_iterations;
  settings.residual_tolerance = 1e-14;
  settings.increment_tolerance = 1e-300;
  VecX x = VecX::Constant(1, x0);
  double slope = 1.0;
  try {
    integrate::newton_loop(
        x, settings, 1.0, "step 7",
        [&](const VecX& y, bool) {
          slope = 1.0 / (3.0 * std::cbrt(y(0) * y(0)));
          return VecX::Constant(1, std::cbrt(y(0)));
        },
        [&](const VecX& R) { return VecX::Constant(1, -R(0) / slope); },
        [&](const VecX&) { return 2.0; }, [&](const VecX& dx) { return std::abs(dx(0)); });
  } catch (const integrate::NewtonFailure& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(NewtonLoop, ADivergingIterationSaysSo) {
  // 70 iterations: the residual grows by 2^{70/3} ≈ 1.1·10⁷ from ∛3 = 1.442.
  const std::string msg = failure(3.0, 70);
  EXPECT_NE(msg.find("step 7: Newton diverged: the residual grew from 1.442e+00 to 1.5"),
            std::string::npos)
      << msg;
  EXPECT_NE(msg.find("in 70 iterations (tolerance 1.0e-14 x scale 2.000e+00 at the start)"),
            std::string::npos)
      << msg;
}

TEST(NewtonLoop, RunningOutOfIterationsIsNotDivergence) {
  // 10 iterations: the residual grows by 2^{10/3} ≈ 10 only (1.442 → 14.54): not diverged.
  const std::string msg = failure(3.0, 10);
  EXPECT_NE(msg.find("step 7: Newton did not converge in 10 iterations; residual 1.454e+01"),
            std::string::npos)
      << msg;
  EXPECT_EQ(msg.find("diverged"), std::string::npos) << msg;
}
