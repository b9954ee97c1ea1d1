// The static Newton solver with load stepping (integrate/static_newton.hpp) on small nonlinear
// problems written here: a chain of hardening springs with a closed-form equilibrium, a moving
// arctan well that defeats full Newton steps, and a 3D truss net with prescribed displacements
// imposed by elimination and by Lagrange multipliers.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "isoflex/integrate/energy_momentum.hpp"  // NewtonFailure
#include "isoflex/integrate/static_newton.hpp"
#include "support/finite_difference.hpp"
#include "support/geometry.hpp"

using namespace isoflex;
using namespace isoflex::integrate;

namespace {

// 1D chain: nodes 0..N at X_i = i·L, spring i between nodes i−1 and i with force
// N(δ) = k_i δ + c_i δ³ (δ the elongation); a force P·t at node N. Node 0 is eliminated.
struct SpringChain {
  int N = 6;
  double L = 1.0, P = 40.0;
  std::vector<double> k, c;
  SpringChain() {
    for (int i = 0; i < N; ++i) {
      k.push_back(10.0 + 3.0 * i);
      c.push_back(50.0 + 20.0 * i);
    }
  }
  StaticProblem problem() const {
    StaticProblem pb;
    pb.reference = VecX::LinSpaced(N + 1, 0.0, N * L);
    const SpringChain self = *this;
    pb.evaluate = [self](const VecX& x, double t, bool with_tangent, ResidualEvaluation& out) {
      out.r = VecX::Zero(x.size());
      std::vector<Eigen::Triplet<double>> trip;
      for (int i = 1; i <= self.N; ++i) {
        const double d = x(i) - x(i - 1) - self.L;
        const double f = self.k[i - 1] * d + self.c[i - 1] * d * d * d;
        const double kt = self.k[i - 1] + 3.0 * self.c[i - 1] * d * d;
        out.r(i) += f;
        out.r(i - 1) -= f;
        trip.emplace_back(i, i, kt);
        trip.emplace_back(i - 1, i - 1, kt);
        trip.emplace_back(i, i - 1, -kt);
        trip.emplace_back(i - 1, i, -kt);
      }
      out.r(self.N) -= self.P * t;
      out.load_norm = std::abs(self.P * t);
      if (with_tangent) {
        out.K.resize(x.size(), x.size());
        out.K.setFromTriplets(trip.begin(), trip.end());
        out.K.makeCompressed();
      }
    };
    return pb;
  }
  // Every spring carries P: k δ + c δ³ = P (one real root, Newton on the scalar cubic).
  VecX exact() const {
    VecX x(N + 1);
    x(0) = 0.0;
    for (int i = 1; i <= N; ++i) {
      double d = P / k[i - 1];
      for (int it = 0; it < 100; ++it)
        d -= (k[i - 1] * d + c[i - 1] * d * d * d - P) / (k[i - 1] + 3.0 * c[i - 1] * d * d);
      x(i) = x(i - 1) + L + d;
    }
    return x;
  }
  LinearConstraints fixed_root() const {
    LinearConstraints lc;
    lc.eliminate(0);
    return lc;
  }
};

// r(x) = atan(x − g(t)), x = g(0) at the start: the root moves with t; Newton for atan from a
// start farther than ≈ 1.39 from the root diverges.
StaticProblem arctan_following(std::function<double(double)> g) {
  StaticProblem pb;
  pb.reference = VecX::Constant(1, g(0.0));
  pb.evaluate = [g](const VecX& x, double t, bool with_tangent, ResidualEvaluation& out) {
    const double y = x(0) - g(t);
    out.r = VecX::Constant(1, std::atan(y));
    out.load_norm = 0.0;
    if (with_tangent) {
      out.K.resize(1, 1);
      out.K.insert(0, 0) = 1.0 / (1.0 + y * y);
      out.K.makeCompressed();
    }
  };
  return pb;
}

// g = a t²: the full step from t = 0 to 1 starts too far away for a = 10.
StaticProblem moving_arctan(double a) {
  return arctan_following([a](double t) { return a * t * t; });
}

// A steep step g = 10 tanh(40 (t − 0.3)): hard only near t = 0.3, so the increments are halved
// there and grow back afterwards.
StaticProblem arctan_with_a_step() {
  return arctan_following([](double t) { return 10.0 * std::tanh(40.0 * (t - 0.3)); });
}

// A 3D truss net: nodes on a jittered grid in the plane z = 0, bars to the right and upper
// neighbours and diagonals, axial force N = EA/L₀ (l − L₀) (geometrically nonlinear); a
// force (0, 0, F t) at every node, on an elastic foundation. Dofs 3 per node.
struct TrussNet {
  int nx = 4, ny = 3;
  double EA = 100.0, F = 0.5, kg = 0.2;
  VecX X;
  std::vector<std::pair<int, int>> bars;
  std::vector<double> L0;
  TrussNet() {
    std::mt19937 g(3);
    std::uniform_real_distribution<double> J(-0.1, 0.1);
    X.resize(3 * nx * ny);
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) X.segment<3>(3 * (i + nx * j)) = Vec3(i + J(g), j + J(g), 0.0);
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const int a = i + nx * j;
        if (i + 1 < nx) bars.emplace_back(a, a + 1);
        if (j + 1 < ny) bars.emplace_back(a, a + nx);
        if (i + 1 < nx && j + 1 < ny) bars.emplace_back(a, a + nx + 1);
      }
    for (const auto& [a, b] : bars)
      L0.push_back((X.segment<3>(3 * b) - X.segment<3>(3 * a)).norm());
  }
  StaticProblem problem() const {
    StaticProblem pb;
    pb.reference = X;
    const TrussNet self = *this;
    pb.evaluate = [self](const VecX& x, double t, bool with_tangent, ResidualEvaluation& out) {
      out.r = VecX::Zero(x.size());
      std::vector<Eigen::Triplet<double>> trip;
      for (std::size_t e = 0; e < self.bars.size(); ++e) {
        const auto [a, b] = self.bars[e];
        const Vec3 d = x.segment<3>(3 * b) - x.segment<3>(3 * a);
        const double l = d.norm(), L0 = self.L0[e];
        const Vec3 n = d / l;
        const double N = self.EA / L0 * (l - L0);
        out.r.segment<3>(3 * b) += N * n;
        out.r.segment<3>(3 * a) -= N * n;
        const Mat3 k =
            self.EA / L0 * n * n.transpose() + N / l * (Mat3::Identity() - n * n.transpose());
        for (int p = 0; p < 3; ++p)
          for (int q = 0; q < 3; ++q) {
            trip.emplace_back(3 * a + p, 3 * a + q, k(p, q));
            trip.emplace_back(3 * b + p, 3 * b + q, k(p, q));
            trip.emplace_back(3 * a + p, 3 * b + q, -k(p, q));
            trip.emplace_back(3 * b + p, 3 * a + q, -k(p, q));
          }
      }
      // An elastic foundation kg (x − X) keeps the flat net stiff out of its plane.
      out.r += self.kg * (x - self.X);
      for (int i = 0; i < x.size(); ++i) trip.emplace_back(i, i, self.kg);
      for (int i = 0; i < x.size() / 3; ++i) out.r(3 * i + 2) -= self.F * t;
      out.load_norm = std::abs(self.F * t);
      if (with_tangent) {
        out.K.resize(x.size(), x.size());
        out.K.setFromTriplets(trip.begin(), trip.end());
        out.K.makeCompressed();
      }
    };
    return pb;
  }
  int node(int i, int j) const { return i + nx * j; }
};

std::string failure_message(StaticNewtonSolver& s) {
  try {
    s.solve();
  } catch (const NewtonFailure& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(StaticNewton, SpringChainConvergesToClosedForm) {
  const SpringChain chain;
  StaticSettings set;
  set.steps = 4;
  std::vector<double> ts;
  StaticNewtonSolver solver(chain.problem(), chain.fixed_root(), set);
  const StaticResult res = solver.solve([&](const LoadStepStats& st, const VecX& x) {
    EXPECT_EQ(st.step, static_cast<int>(ts.size()) + 1);
    EXPECT_EQ(x.size(), chain.N + 1);
    ts.push_back(st.t);
  });
  ASSERT_EQ(res.steps.size(), 4u);
  EXPECT_DOUBLE_EQ(ts.back(), 1.0);
  EXPECT_NEAR(ts[1], 0.5, 1e-15);
  const VecX xe = chain.exact();
  EXPECT_LT((res.x - xe).lpNorm<Eigen::Infinity>(), 1e-12) << res.x.transpose() << "\n"
                                                           << xe.transpose();
  EXPECT_EQ(res.x(0), 0.0);
  EXPECT_EQ(solver.dofs().n_free(), chain.N);
  EXPECT_LE(res.analyses, 1);  // one pattern: the symbolic analysis is kept
  for (const auto& st : res.steps) {
    EXPECT_GT(st.iterations, 0);
    EXPECT_GE(st.wall_seconds, st.assembly_seconds + st.solve_seconds - 1e-6);
    EXPECT_EQ(st.residual_history.size(), static_cast<std::size_t>(st.iterations) + 1);
  }
}

// Newton's residuals fall quadratically: r_{k+1} ≈ C r_k², observed order → 2.
TEST(StaticNewton, QuadraticConvergence) {
  const SpringChain chain;
  StaticSettings set;
  set.steps = 1;
  set.residual_tolerance = 1e-14;
  set.increment_tolerance = 0.0;
  StaticNewtonSolver solver(chain.problem(), chain.fixed_root(), set);
  const StaticResult res = solver.solve();
  const auto& h = res.steps.at(0).residual_history;
  ASSERT_GE(h.size(), 5u);
  std::string hist;
  for (double r : h) hist += isoflex::test::sci(r) + " ";
  RecordProperty("residuals", hist);
  // The last ratios with r well above round-off: order log(r_{k+1}/r_k) / log(r_k/r_{k−1}).
  int checked = 0;
  for (std::size_t k = 1; k + 1 < h.size(); ++k) {
    if (h[k + 1] < 1e-11 * chain.P || h[k] > 1e-1 * chain.P) continue;
    const double order = std::log(h[k + 1] / h[k]) / std::log(h[k] / h[k - 1]);
    EXPECT_GT(order, 1.8) << "k = " << k << ": " << hist;
    ++checked;
  }
  EXPECT_GE(checked, 1) << hist;
}

TEST(StaticNewton, LinearProblemIsOneSolve) {
  SpringChain chain;
  for (double& c : chain.c) c = 0.0;
  StaticProblem pb = chain.problem();
  pb.linear = true;
  StaticSettings set;
  set.steps = 2;
  StaticNewtonSolver solver(pb, chain.fixed_root(), set);
  const StaticResult res = solver.solve();
  for (const auto& st : res.steps) EXPECT_EQ(st.iterations, 1);
  EXPECT_LT((res.x - chain.exact()).norm(), 1e-12);
  EXPECT_LT(res.steps.back().residual, 1e-11);
}

TEST(StaticNewton, AdaptiveHalvingRecoversWhereFullStepsFail) {
  StaticSettings set;
  set.steps = 1;
  set.force_floor = 1.0;
  set.max_iterations = 30;
  {
    StaticNewtonSolver fixed(moving_arctan(10.0), {}, set);
    const std::string msg = failure_message(fixed);
    EXPECT_NE(msg.find("load step 1"), std::string::npos) << msg;
    EXPECT_NE(msg.find("load factor 1 "), std::string::npos) << msg;
    EXPECT_NE(msg.find("load factor reached 0"), std::string::npos) << msg;
    EXPECT_NE(msg.find("residual"), std::string::npos) << msg;
  }
  set.adaptive = true;
  StaticNewtonSolver adaptive(moving_arctan(10.0), {}, set);
  const StaticResult res = adaptive.solve();
  EXPECT_NEAR(res.x(0), 10.0, 1e-10);
  int cuts = 0;
  double smallest = 1.0, largest = 0.0;
  for (const auto& st : res.steps) {
    cuts += st.cuts;
    smallest = std::min(smallest, st.dt);
    largest = std::max(largest, st.dt);
  }
  RecordProperty("steps", static_cast<int>(res.steps.size()));
  RecordProperty("cuts", cuts);
  EXPECT_GE(cuts, 3);  // 1 → 1/2 → 1/4 → 1/8 at least
  EXPECT_LE(smallest, 0.125);
  EXPECT_GT(largest, smallest);  // the increment grew again after easy steps
  EXPECT_NEAR(res.steps.back().t, 1.0, 0.0);
}

// After a halving the increments grow back onto the nominal load levels: every k/4 is an
// accepted load factor, so the outputs have a row at each level the user asked for (without the
// snap to the grid this run jumps from 0.47 over 0.5 and 0.75).
TEST(StaticNewton, AdaptiveStepsReturnToTheNominalLevels) {
  StaticSettings set;
  set.steps = 4;
  set.force_floor = 1.0;
  set.max_iterations = 30;
  set.adaptive = true;
  set.grow_after = 1;  // grows after one easy step, also from odd multiples of a halved one
  StaticNewtonSolver adaptive(arctan_with_a_step(), {}, set);
  const StaticResult res = adaptive.solve();
  EXPECT_NEAR(res.x(0), 10.0 * std::tanh(28.0), 1e-10);
  int cuts = 0;
  for (const auto& st : res.steps) cuts += st.cuts;
  EXPECT_GE(cuts, 4);  // the increments near t = 0.3 are halved
  for (int k = 1; k <= 4; ++k) {
    const bool hit = std::any_of(res.steps.begin(), res.steps.end(), [&](const LoadStepStats& st) {
      return std::abs(st.t - 0.25 * k) <= 1e-15;
    });
    EXPECT_TRUE(hit) << "no accepted load step at t = " << 0.25 * k;
  }
}

// The load levels are k·Δt computed as such: twenty steps of 0.05 end at 0.9 and 1 exactly, not
// at the sums 0.9000000000000002 and 1.0000000000000002 of their increments (with halvings too).
TEST(StaticNewton, LoadLevelsAreMultiplesOfTheIncrementNotSums) {
  for (const bool adaptive : {false, true}) {
    StaticSettings set;
    set.steps = 20;
    set.force_floor = 1.0;
    set.max_iterations = 30;
    set.adaptive = adaptive;
    StaticNewtonSolver solver(adaptive ? arctan_with_a_step() : moving_arctan(1.0), {}, set);
    const StaticResult res = solver.solve();
    int nominal = 0;
    for (const auto& st : res.steps) {
      const double k = std::round(st.t * 20.0);
      if (std::abs(st.t - k * 0.05) > 1e-12) continue;  // a halved level
      EXPECT_EQ(st.t, k / 20.0) << "step " << st.step << (adaptive ? " (adaptive)" : "");
      ++nominal;
    }
    EXPECT_EQ(nominal, 20);
    EXPECT_EQ(res.steps.back().t, 1.0);
  }
}

TEST(StaticNewton, FailureMessageNamesStepFactorAndResidual) {
  StaticSettings set;
  set.steps = 4;  // step 1 moves the root by 0.625, step 2 by 1.875: Newton diverges there
  set.force_floor = 1.0;
  set.max_iterations = 20;
  StaticNewtonSolver s(moving_arctan(10.0), {}, set);
  const std::string msg = failure_message(s);
  EXPECT_NE(msg.find("load step 2 did not converge at load factor 0.5"), std::string::npos) << msg;
  EXPECT_NE(msg.find("load factor reached 0.25"), std::string::npos) << msg;
  EXPECT_NE(msg.find("residual "), std::string::npos) << msg;
  EXPECT_NE(msg.find(" iterations"), std::string::npos) << msg;
  // Adaptive with a single halving allowed: names the halvings.
  set.adaptive = true;
  set.max_cuts = 1;
  set.steps = 1;
  StaticNewtonSolver s2(moving_arctan(10.0), {}, set);
  const std::string msg2 = failure_message(s2);
  EXPECT_NE(msg2.find("after 1 halvings"), std::string::npos) << msg2;
  EXPECT_NE(msg2.find("load factor 0.5"), std::string::npos) << msg2;
}

// A node displaced by ū(t) through elimination and through a multiplier row gives the same x,
// and the multiplier is the reaction.
TEST(StaticNewton, MultiplierMatchesElimination) {
  const TrussNet net;
  const StaticProblem pb = net.problem();
  const Vec3 ubar(0.2, -0.1, 0.4);
  LinearConstraints elim, mult;
  for (int j = 0; j < net.ny; ++j)
    for (int k = 0; k < 3; ++k) {
      elim.eliminate(3 * net.node(0, j) + k);
      mult.eliminate(3 * net.node(0, j) + k);
    }
  const int moved = net.node(net.nx - 1, net.ny - 1);
  for (int k = 0; k < 3; ++k) elim.eliminate(3 * moved + k, [=](double t) { return ubar(k) * t; });
  // Multiplier rows: one per component, plus a redundant-free mixed row on another node:
  // x_k − X_k = ū_k t.
  mult.C.resize(3, pb.reference.size());
  for (int k = 0; k < 3; ++k) mult.C.insert(k, 3 * moved + k) = 1.0;
  mult.rhs = [=](double t) -> VecX { return ubar * t; };
  StaticSettings set;
  set.steps = 3;
  StaticNewtonSolver a(pb, elim, set), b(pb, mult, set);
  const StaticResult ra = a.solve(), rb = b.solve();
  EXPECT_LT((ra.x - rb.x).lpNorm<Eigen::Infinity>(), 1e-10);
  EXPECT_LT((rb.x.segment<3>(3 * moved) - net.X.segment<3>(3 * moved) - ubar).norm(), 1e-12);
  ASSERT_EQ(rb.mu.size(), 3);
  // μ balances the internal minus external force at the moved node: r + Cᵀμ = 0 there.
  ResidualEvaluation ev;
  pb.evaluate(rb.x, 1.0, false, ev);
  EXPECT_LT((ev.r.segment<3>(3 * moved) + rb.mu).norm(), 1e-9);
  // Rigid-body sanity: the displacement is not trivial.
  EXPECT_GT((ra.x - net.X).norm(), 0.1);
}

// Tied rows (master–slave elimination, LinearConstraints::tied) give the equilibrium of the same
// rows as multipliers, with 2 unknowns fewer per row; a chain of rows through one node, a row
// on an eliminated node with a prescribed motion and a row implied by two others included.
TEST(StaticNewton, TiedRowsMatchMultiplierRows) {
  TrussNet net;
  net.F = 0.05;  // displacements of 0.1 the bars: one equilibrium (at 0.5 there are several)
  const StaticProblem pb = net.problem();
  const Vec3 ubar(0.02, -0.04, 0.06);
  using Row = std::vector<std::pair<int, double>>;
  std::vector<Row> rows;
  const auto dof = [&](int i, int j, int k) { return 3 * net.node(i, j) + k; };
  for (int k = 0; k < 3; ++k) {
    // u(1,1) = (u(0,1) + u(2,1)) / 2; then u(2,1) = 0.6 u(3,1) + 0.4 u(3,2): a chain through
    // (2,1).
    rows.push_back({{dof(1, 1, k), 1.0}, {dof(0, 1, k), -0.5}, {dof(2, 1, k), -0.5}});
    rows.push_back({{dof(2, 1, k), 1.0}, {dof(3, 1, k), -0.6}, {dof(3, 2, k), -0.4}});
    // Implied by the two above.
    rows.push_back(
        {{dof(1, 1, k), 2.0}, {dof(0, 1, k), -1.0}, {dof(3, 1, k), -0.6}, {dof(3, 2, k), -0.4}});
  }
  // z of (1,2) follows the prescribed corner (0,2): u_z(1,2) = 0.7 u_z(0,2).
  rows.push_back({{dof(1, 2, 2), 1.0}, {dof(0, 2, 2), -0.7}});
  LinearConstraints tied, mult;
  for (LinearConstraints* c : {&tied, &mult}) {
    for (int k = 0; k < 3; ++k) c->eliminate(dof(0, 0, k));
    for (int k = 0; k < 3; ++k) c->eliminate(dof(0, 2, k), [=](double t) { return ubar(k) * t; });
  }
  tied.tied = rows;
  // The independent rows as multipliers: each of the first two per component, and the last.
  std::vector<Eigen::Triplet<double>> trip;
  int m = 0;
  for (std::size_t r = 0; r < rows.size(); ++r) {
    if (r + 1 < rows.size() && r % 3 == 2) continue;
    for (const auto& [i, a] : rows[r]) trip.emplace_back(m, i, a);
    ++m;
  }
  mult.C.resize(m, pb.reference.size());
  mult.C.setFromTriplets(trip.begin(), trip.end());
  // The last row on a prescribed dof: C (x − X) = d with d = 0.7 ū_z t moved to the right.
  mult.C.coeffRef(m - 1, dof(0, 2, 2)) = 0.0;
  mult.C.prune(0.0);
  mult.rhs = [=](double t) {
    VecX d = VecX::Zero(m);
    d(m - 1) = 0.7 * ubar(2) * t;
    return d;
  };
  StaticSettings set;
  set.steps = 3;
  StaticNewtonSolver a(pb, tied, set), b(pb, mult, set);
  EXPECT_EQ(a.dofs().slaves.size(), 7u);
  EXPECT_EQ(a.dofs().dropped_tied_rows, 3);
  EXPECT_EQ(a.dofs().n_free() + 7, b.dofs().n_free());
  const StaticResult ra = a.solve(), rb = b.solve();
  EXPECT_LT((ra.x - rb.x).lpNorm<Eigen::Infinity>(), 1e-10);
  EXPECT_GT((ra.x - net.X).norm(), 0.05);
  for (const Row& r : rows) {
    double v = 0.0, w = 0.0;
    for (const auto& [i, c] : r) v += c * (ra.x(i) - net.X(i));
    for (const auto& [i, c] : r) w += c * (rb.x(i) - net.X(i));
    EXPECT_LT(std::abs(v), 1e-13);
    EXPECT_LT(std::abs(w), 1e-13);
  }
  // Equilibrium of the tied solution: the reduced residual Tᵀ r vanishes.
  ResidualEvaluation ev;
  pb.evaluate(ra.x, 1.0, false, ev);
  EXPECT_LT(a.dofs().reduce(ev.r).norm(), 1e-9);

  EXPECT_NEAR(ra.x(dof(1, 2, 2)) - net.X(dof(1, 2, 2)), 0.7 * ubar(2), 1e-14);
}

// The DofMap's T: reduce() is Tᵀ and expansion() its rows; set_slaves() satisfies the rows.
TEST(StaticNewton, DofMapTiedRows) {
  const std::vector<std::vector<std::pair<int, double>>> rows = {
      {{0, 1.0}, {1, -3.0}, {2, 1.0}}, {{1, 1.0}, {3, -1.0}, {5, 2.0}}, {{4, 1.0}, {5, -1.0}}};
  const DofMap m = DofMap::build(6, {5}, rows);
  ASSERT_EQ(m.slaves.size(), 3u);
  EXPECT_EQ(m.dropped_tied_rows, 0);
  EXPECT_EQ(m.n_free(), 2);
  MatX T = MatX::Zero(6, m.n_free());
  for (int i = 0; i < 6; ++i)
    for (const auto& [f, w] : m.expansion(i)) T(i, f) = w;
  std::mt19937 g(5);
  std::normal_distribution<double> N;
  VecX r(6), X(6), x(6);
  for (int i = 0; i < 6; ++i) {
    r(i) = N(g);
    X(i) = N(g);
    x(i) = N(g);
  }
  EXPECT_LT((m.reduce(r) - T.transpose() * r).norm(), 1e-14);
  m.set_slaves(x, X);
  for (const auto& row : rows) {
    double v = 0.0;
    for (const auto& [i, c] : row) v += c * (x(i) - X(i));
    EXPECT_LT(std::abs(v), 1e-14);
  }
  EXPECT_THROW(DofMap::build(3, {}, {{{3, 1.0}}}), std::invalid_argument);
}

TEST(StaticNewton, RejectsBadInput) {
  const SpringChain chain;
  StaticSettings set;
  set.steps = 0;
  EXPECT_THROW(StaticNewtonSolver(chain.problem(), chain.fixed_root(), set), std::invalid_argument);
  set.steps = 1;
  LinearConstraints lc = chain.fixed_root();
  lc.C.resize(1, chain.N + 1);
  lc.C.insert(0, 0) = 1.0;  // a row on the eliminated node only
  EXPECT_THROW(StaticNewtonSolver(chain.problem(), lc, set), std::invalid_argument);
}

TEST(StaticNewton, DofMap) {
  const DofMap m = DofMap::build(6, {1, 4});
  EXPECT_EQ(m.free, (std::vector<int>{0, 2, 3, 5}));
  EXPECT_EQ(m.full_to_free, (std::vector<int>{0, -1, 1, 2, -1, 3}));
  EXPECT_THROW(DofMap::build(3, {3}), std::invalid_argument);
  LinearConstraints lc;
  lc.eliminate(5);
  lc.eliminate(2, [](double t) { return t; });
  lc.eliminate(5, [](double t) { return 2 * t; });
  EXPECT_EQ(lc.eliminated, (std::vector<int>{2, 5}));
  EXPECT_DOUBLE_EQ(lc.eliminated_value[1](1.0), 2.0);
}

// A spring chain whose last spring is 10⁻²⁰ of the others: positive definite in floating point,
// so the factorization succeeds, but its correction is 10²⁰ times the model — a mechanism, which
// the step reports as a singular matrix instead of accepting.
TEST(StaticNewton, NearlySingularMatrixIsReportedNotAccepted) {
  SpringChain chain;
  chain.k.back() = 1e-20 * chain.k.front();
  chain.c.back() = 0.0;
  for (const bool linear : {false, true}) {
    StaticProblem pb = chain.problem();
    pb.linear = linear;
    StaticSettings s;
    StaticNewtonSolver solver(pb, chain.fixed_root(), s);
    try {
      solver.solve();
      ADD_FAILURE() << "no failure";
    } catch (const NewtonFailure& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("load step 1 did not converge"), std::string::npos) << what;
      EXPECT_NE(what.find("times the size of the model"), std::string::npos) << what;
    }
  }
}
