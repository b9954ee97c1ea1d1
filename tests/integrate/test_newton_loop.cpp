// The one Newton loop (integrate/newton_loop.hpp): how it reports a failure. A residual that
// grows by orders of magnitude is reported as diverged, with the scale of the start value (a
// diverged iterate's scale would be meaningless); one that merely runs out of iterations is not.
// Skipping the last Newton matrix by the quadratic-convergence prediction leaves the iterates
// unchanged; chord corrections near the root reach the same root with fewer matrices.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "isoflex/integrate/newton_loop.hpp"

using namespace isoflex;
using integrate::NewtonOptions;
using integrate::NewtonOutcome;

namespace {

// Newton on r(x) = ∛x (one unknown): every correction overshoots, x_{k+1} = −2 x_k, and |r|
// grows by 2^{1/3} per iteration; scale 2 (as the energy–momentum step's, fixed by the model).
NewtonOutcome cube_root(double x0, const NewtonOptions& opt) {
  double x = x0, slope = 1.0;
  return integrate::newton_loop(
      opt,
      [&](bool) {
        slope = 1.0 / (3.0 * std::cbrt(x * x));
        return VecX::Constant(1, std::cbrt(x));
      },
      [] { return 2.0; },
      [&](const VecX& R) {
        x -= R(0) / slope;
        return false;
      });
}

std::string failure(double x0, int max_iterations, bool stop_when_diverging = false) {
  NewtonOptions opt;
  opt.max_iterations = max_iterations;
  opt.residual_tolerance = 1e-14;
  opt.stop_when_diverging = stop_when_diverging;
  const NewtonOutcome o = cube_root(x0, opt);
  EXPECT_FALSE(o.converged);
  return integrate::failure_message("step 7", o, opt.residual_tolerance);
}

// Newton on r(x) = x³ − 8 from x = 3, counting the matrices it asks for; a correction uses the
// slope of the last matrix.
struct Cubic {
  double x = 3.0, slope = 0.0;
  int matrices = 0;
  std::vector<double> iterates;
  NewtonOutcome run(bool predict, double chord = 0.0) {
    NewtonOptions opt;
    opt.max_iterations = 50;
    opt.residual_tolerance = 1e-13;
    opt.predict_last_matrix = predict;
    opt.chord_contraction = chord;
    return integrate::newton_loop(
        opt,
        [&](bool matrix) {
          if (matrix) slope = 3.0 * x * x;
          matrices += matrix;
          return VecX::Constant(1, x * x * x - 8.0);
        },
        [] { return 8.0; },
        [&](const VecX& R) {
          x -= R(0) / slope;
          iterates.push_back(x);
          return false;
        });
  }
};

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
  EXPECT_NE(msg.find("step 7: Newton did not converge; residual 1.454e+01 after 10 iterations"),
            std::string::npos)
      << msg;
  EXPECT_EQ(msg.find("diverged"), std::string::npos) << msg;
}

TEST(NewtonLoop, LoadStepsStopAsSoonAsTheResidualGrewBySixOrders) {
  // 2^{k/3} > 10⁶ first at k = 60.
  const std::string msg = failure(3.0, 70, true);
  EXPECT_NE(msg.find("Newton diverged: the residual grew from 1.442e+00 to 1.5"), std::string::npos)
      << msg;
  EXPECT_NE(msg.find("in 60 iterations"), std::string::npos) << msg;
}

TEST(NewtonLoop, AModelErrorFailsTheIterationWithItsMessage) {
  NewtonOptions opt;
  int calls = 0;
  const NewtonOutcome o = integrate::newton_loop(
      opt,
      [&](bool) -> VecX {
        if (++calls == 2) throw std::runtime_error("element 3 inverted");
        return VecX::Constant(1, 1.0);
      },
      [] { return 1.0; }, [](const VecX&) { return false; });
  EXPECT_FALSE(o.converged);
  EXPECT_EQ(o.reason, "evaluation failed at Newton iteration 1: element 3 inverted");
}

TEST(NewtonLoop, PredictingTheLastMatrixKeepsTheIterates) {
  Cubic plain, predicted;
  const NewtonOutcome a = plain.run(false), b = predicted.run(true);
  ASSERT_TRUE(a.converged);
  ASSERT_TRUE(b.converged);
  EXPECT_EQ(a.iterations, b.iterations);
  EXPECT_EQ(plain.iterates, predicted.iterates);
  EXPECT_EQ(a.residual, b.residual);
  // The matrix at the converged iterate is never asked for: one matrix per correction.
  EXPECT_EQ(plain.matrices, a.iterations + 1);
  EXPECT_EQ(predicted.matrices, b.iterations);
}

TEST(NewtonLoop, ChordCorrectionsNearTheRootReachItWithFewerMatrices) {
  Cubic plain, chord;
  const NewtonOutcome a = plain.run(false), b = chord.run(false, 1e-2);
  ASSERT_TRUE(a.converged);
  ASSERT_TRUE(b.converged);
  // |r| = 19, 4.1, 0.45, 7.8e-3: that Newton correction's θ = 0.017 predicts θ² = 3·10⁻⁴ for a
  // chord, and the chords run 2.6e-6, 1.7e-9, 1.1e-12 (θ ≈ 7·10⁻⁴ each), 0; Newton's 2.6e-6,
  // 2.7e-13. Both stop at |r| ≤ 10⁻¹³ · 8, i.e. |x − 2| ≤ 8·10⁻¹³/12.
  EXPECT_NEAR(chord.x, 2.0, 7e-14);
  EXPECT_NEAR(plain.x, 2.0, 7e-14);
  EXPECT_EQ(plain.matrices, a.iterations + 1);
  EXPECT_EQ(a.iterations, 5);
  EXPECT_EQ(chord.matrices, 4);
  EXPECT_EQ(b.iterations, 7);
  // The corrections before the chord are Newton's.
  for (int k = 0; k < 4; ++k) EXPECT_EQ(chord.iterates[k], plain.iterates[k]) << k;
}
