// Path following of the static Newton solver (integrate/static_newton.hpp, arc_length.hpp) on a
// chain of two springs whose first one softens and stiffens again, N(δ) = 2.5 δ − 3 δ² + δ³: the
// equilibrium path λ = N(u₁) has a load maximum at u₁ = 1 − √(1/6) and a minimum at 1 + √(1/6),
// which load control cannot pass and arc length and displacement control must.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "isoflex/integrate/arc_length.hpp"
#include "isoflex/integrate/newton_loop.hpp"
#include "isoflex/integrate/static_newton.hpp"

using namespace isoflex;
using namespace isoflex::integrate;

namespace {

double spring(double d) {
  return 2.5 * d - 3.0 * d * d + d * d * d;
}
double spring_stiffness(double d) {
  return 2.5 - 6.0 * d + 3.0 * d * d;
}
constexpr double kSecond = 4.0;  // the linear spring between nodes 1 and 2

// Nodes 0, 1, 2 on a line at 0, 1, 2; the load λ at node 2 (t_end = 2). Node 0 is held by
// elimination, or (by_row) by a multiplier row x₀ = 0.
StaticProblem chain() {
  StaticProblem pb;
  pb.reference = VecX::LinSpaced(3, 0.0, 2.0);
  pb.evaluate = [](const VecX& x, double t, bool with_tangent, ResidualEvaluation& out) {
    const double d1 = x(1) - x(0) - 1.0, d2 = x(2) - x(1) - 1.0;
    const double f1 = spring(d1), f2 = kSecond * d2;
    out.r = VecX(3);
    out.r << -f1, f1 - f2, f2 - t;
    out.load_norm = std::abs(t);
    if (!with_tangent) return;
    const double k1 = spring_stiffness(d1);
    std::vector<Eigen::Triplet<double>> trip = {
        {0, 0, k1},       {0, 1, -k1},      {1, 0, -k1},    {1, 1, k1 + kSecond},
        {1, 2, -kSecond}, {2, 1, -kSecond}, {2, 2, kSecond}};
    out.K.resize(3, 3);
    out.K.setFromTriplets(trip.begin(), trip.end());
    out.K.makeCompressed();
  };
  pb.symmetric = true;
  return pb;
}

LinearConstraints held(bool by_row) {
  LinearConstraints c;
  if (!by_row) {
    c.eliminate(0);
    return c;
  }
  c.C.resize(1, 3);
  c.C.insert(0, 0) = 1.0;
  c.C.makeCompressed();
  return c;
}

StaticSettings arc_settings(double dl) {
  StaticSettings s;
  s.t_end = 2.0;
  s.steps = 10;
  s.max_iterations = 30;
  s.residual_tolerance = 1e-12;
  s.path.control = PathControl::arc_length;
  s.path.arc_length = dl;
  s.path.max_arc_length = dl;
  return s;
}

struct PathPoint {
  double lambda, u1, u2, path;
};

std::vector<PathPoint> follow(StaticNewtonSolver& solver) {
  std::vector<PathPoint> pts;
  solver.solve([&](const LoadStepStats& st, const VecX& x) {
    pts.push_back({st.t, x(1) - x(0) - 1.0, x(2) - x(1) - 1.0, st.path});
  });
  return pts;
}

const double kMaxLoad = spring(1.0 - std::sqrt(1.0 / 6.0));  // 0.636…
const double kMinLoad = spring(1.0 + std::sqrt(1.0 / 6.0));  // 0.363…

}  // namespace

TEST(PathFollowing, ArcLengthPassesBothLimitPoints) {
  StaticNewtonSolver solver(chain(), held(false), arc_settings(0.1));
  const std::vector<PathPoint> pts = follow(solver);
  ASSERT_GT(pts.size(), 10u);
  double top = 0.0, bottom = 1e9;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const PathPoint& p = pts[i];
    // Equilibrium on the path: both springs carry λ.
    EXPECT_NEAR(spring(p.u1), p.lambda, 1e-11) << "step " << i + 1;
    EXPECT_NEAR(kSecond * p.u2, p.lambda, 1e-11) << "step " << i + 1;
    if (i > 0) {
      EXPECT_GT(p.u1, pts[i - 1].u1) << "the path turned back at step " << i + 1;
    }
    if (p.u1 < 1.0 && p.lambda > top) top = p.lambda;
    if (p.u1 > 1.0 && p.u1 < 2.0) bottom = std::min(bottom, p.lambda);
  }
  // Sampled at most 0.1 apart: the maximum is approached from below, the minimum from above.
  EXPECT_LE(top, kMaxLoad + 1e-12);
  EXPECT_GT(top, kMaxLoad - 0.02);
  EXPECT_GE(bottom, kMinLoad - 1e-12);
  EXPECT_LT(bottom, kMinLoad + 0.02);
  // It ends exactly at λ = t_end.
  EXPECT_EQ(pts.back().lambda, 2.0);
  EXPECT_NEAR(spring(pts.back().u1), 2.0, 1e-11);
}

TEST(PathFollowing, EveryArcStepHasTheArcLength) {
  // With ψ = 0 a step's increment of the free coordinates has length Δl (adapted per step): the
  // path parameter grows by exactly that, and the corrector keeps it to round-off.
  StaticSettings s = arc_settings(0.05);
  s.path.target_iterations = 100;  // Δl grows by 2 per step up to max_arc_length
  s.path.max_arc_length = 0.5;
  StaticNewtonSolver solver(chain(), held(false), s);
  const std::vector<PathPoint> pts = follow(solver);
  ASSERT_GT(pts.size(), 5u);
  double dl = 0.05;
  for (std::size_t i = 0; i + 1 < pts.size(); ++i) {
    const double du1 = pts[i].u1 - (i ? pts[i - 1].u1 : 0.0);
    const double dx2 = (pts[i].u1 + pts[i].u2) - (i ? pts[i - 1].u1 + pts[i - 1].u2 : 0.0);
    EXPECT_NEAR(std::hypot(du1, dx2), dl, 1e-12 * dl) << "step " << i + 1;
    EXPECT_NEAR(pts[i].path - (i ? pts[i - 1].path : 0.0), dl, 1e-12 * dl);
    dl = std::min(2.0 * dl, 0.5);
  }
}

TEST(PathFollowing, MultiplierRowsFollowTheSamePath) {
  // Node 0 held by a row and a multiplier (bordered LU) instead of elimination (Cholesky).
  StaticNewtonSolver a(chain(), held(false), arc_settings(0.1));
  StaticNewtonSolver b(chain(), held(true), arc_settings(0.1));
  const auto pa = follow(a), pb = follow(b);
  ASSERT_EQ(pa.size(), pb.size());
  for (std::size_t i = 0; i < pa.size(); ++i) {
    EXPECT_NEAR(pa[i].lambda, pb[i].lambda, 1e-10) << "step " << i + 1;
    EXPECT_NEAR(pa[i].u1, pb[i].u1, 1e-10) << "step " << i + 1;
  }
}

TEST(PathFollowing, LoadWeightChangesTheStepsNotThePath) {
  StaticSettings s = arc_settings(0.1);
  s.path.load_weight = 1.0;
  StaticNewtonSolver solver(chain(), held(false), s);
  const auto pts = follow(solver);
  for (const PathPoint& p : pts) EXPECT_NEAR(spring(p.u1), p.lambda, 1e-11);
  EXPECT_EQ(pts.back().lambda, 2.0);
}

TEST(PathFollowing, DisplacementControlPassesLimitPoints) {
  StaticSettings s;
  s.t_end = 1.0;
  s.steps = 23;
  s.residual_tolerance = 1e-12;
  s.path.control = PathControl::displacement;
  s.path.control_vector = {{1, 1.0}};  // x₁ − X₁ = u₁ (node 0 is held)
  s.path.displacement = 2.3;
  StaticNewtonSolver solver(chain(), held(false), s);
  const auto pts = follow(solver);
  ASSERT_EQ(pts.size(), 23u);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const double u = 2.3 * static_cast<double>(i + 1) / 23.0;
    EXPECT_NEAR(pts[i].u1, u, 1e-14) << "step " << i + 1;
    EXPECT_NEAR(pts[i].path, u, 1e-14);
    EXPECT_NEAR(pts[i].lambda, spring(u), 1e-11) << "step " << i + 1;
  }
}

TEST(PathFollowing, StopsAfterMaxSteps) {
  StaticSettings s = arc_settings(0.01);
  s.path.max_steps = 7;
  StaticNewtonSolver solver(chain(), held(false), s);
  const StaticResult r = solver.solve();
  EXPECT_EQ(r.steps.size(), 7u);
  EXPECT_NE(r.stopped.find("stopped after 7 steps"), std::string::npos) << r.stopped;
  EXPECT_LT(r.steps.back().t, 2.0);
}

TEST(PathFollowing, BadSettingsAreRejected) {
  StaticProblem linear = chain();
  linear.linear = true;
  EXPECT_THROW(StaticNewtonSolver(linear, held(false), arc_settings(0.1)), std::invalid_argument);
  StaticSettings s = arc_settings(0.1);
  s.path.control = PathControl::displacement;
  s.path.control_vector = {{0, 1.0}};  // the eliminated node only
  EXPECT_THROW(StaticNewtonSolver(chain(), held(false), s), std::invalid_argument);
  s.path.control_vector = {{5, 1.0}};
  EXPECT_THROW(StaticNewtonSolver(chain(), held(false), s), std::invalid_argument);
  s = arc_settings(0.1);
  s.path.target_iterations = 0;
  EXPECT_THROW(StaticNewtonSolver(chain(), held(false), s), std::invalid_argument);
}

TEST(ArcLengthCorrection, PicksTheRootThatKeepsTheDirection) {
  // Δu = (1, 0), Δλ = 0, δu_R = 0, δu_λ = (0, 1), w = 0, Δl = √2: δλ = ±1; both turn by 45°, the
  // larger inner product with Δu is equal, so take a case with a bias: δu_λ = (1, 1).
  VecX du(2), zero = VecX::Zero(2), dul(2);
  du << 1.0, 0.0;
  dul << 1.0, 1.0;
  // ‖(1 + δλ, δλ)‖² = 4 → 2δλ² + 2δλ − 3 = 0, δλ = (−1 ± √7)/2; the + root goes on.
  const double r = arc_length_correction(du, 0.0, zero, dul, 0.0, 2.0);
  EXPECT_NEAR(r, (-1.0 + std::sqrt(7.0)) / 2.0, 1e-15);
  // Δl too short to be reached along δu_λ from Δu + δu_R: no real root.
  VecX far(2);
  far << 0.0, 5.0;
  EXPECT_THROW(arc_length_correction(du, 0.0, far, dul, 0.0, 0.1), std::runtime_error);
}
