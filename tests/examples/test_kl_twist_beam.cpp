// examples/kl_twist_beam (IGA-thesis §6.4.2.4, Fig. 6.26): a five-patch lipped channel read from
// the committed STEP file, twisted by a couple at mid-span, nonlinear. The file's AF-D run keeps
// the angle of every triple of its four kinked interfaces (the angle rows (5.37) with their
// Hessians); the bending strip approaches it at moderate β₁ and is stiffer at large β₁, because
// its rows also hold the flanges' lengths across the interface; AF-BS is stiffer than AF-D too
// (Remark 5.8, the thesis' AF-BS below AF-D) — README.md's table, bench/kl_multipatch_bench.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "isoflex/io/model_reader.hpp"
#include "support/examples.hpp"
#include "support/statics.hpp"

using namespace isoflex;

namespace {

struct Twist {
  double uz = 0.0;                  // the lip end at −y, at the full load
  double worst_angle_change = 0.0;  // over every triple of every interface, degrees
  int interfaces = 0;
};

double angle_of(const system::System& sys, const VecX& q, const std::vector<int>& T,
                std::size_t k) {
  const auto x = [&](std::size_t i) { return Vec3(q.segment<3>(sys.q_offset(T[k + i]))); };
  const Vec3 a = x(1) - x(0), b = x(2) - x(1);
  return std::acos(a.dot(b) / (a.norm() * b.norm())) * 180.0 / M_PI;
}

Twist twist(model::KLCoupling coupling, double beta) {
  const std::string dir = std::string(ISOFLEX_SOURCE_DIR) + "/examples/kl_twist_beam/";
  model::Model m = io::read_model(dir + "model.yaml");
  m.kl_interfaces.coupling = coupling;
  m.kl_interfaces.beta = beta;
  const auto sys = test::static_system(m);
  const test::StaticRun r = test::solve_static(sys, m);
  EXPECT_EQ(r.failure, "");
  Twist t;
  if (r.steps.empty()) return t;
  const VecX& q = r.steps.back().q;
  t.uz = (test::probe_at(sys, q, "lip_a_end") - test::probe_at(sys, sys.q0(), "lip_a_end")).z();
  t.interfaces = static_cast<int>(sys.kl_interfaces().size());
  for (const auto& I : sys.kl_interfaces()) {
    EXPECT_NEAR(I.geometry.angle_min, 105.0, 1e-6);
    for (std::size_t k = 0; k < I.triple_nodes.size(); k += 3)
      t.worst_angle_change =
          std::max(t.worst_angle_change, std::abs(angle_of(sys, q, I.triple_nodes, k) -
                                                  angle_of(sys, sys.q0(), I.triple_nodes, k)));
  }
  return t;
}

}  // namespace

TEST(KLTwistBeam, AngleRowsHoldTheKinksAndTheStripIsStifferAtLargeBeta) {
  using C = model::KLCoupling;
  const Twist af_d = twist(C::angle, 1.0), s2 = twist(C::bending_strip, 1e2),
              s5 = twist(C::bending_strip, 1e5), af_bs = twist(C::strip_constraints, 1.0);
  std::printf(
      "  lip end u_z: AF-D %.6f (worst angle change %.2e deg), AF-BS %.6f (%.2e deg), strip "
      "1e2 %.6f, 1e5 %.6f\n",
      af_d.uz, af_d.worst_angle_change, af_bs.uz, af_bs.worst_angle_change, s2.uz, s5.uz);
  EXPECT_EQ(af_d.interfaces, 4);
  EXPECT_LT(af_d.uz, -20.0);  // a large twist: a third of the flange height
  EXPECT_LT(af_d.worst_angle_change, 1e-8);
  EXPECT_NEAR(s2.uz / af_d.uz, 1.0, 0.01);
  EXPECT_GT(s2.worst_angle_change, 1e-4);  // a penalty: the angles move
  EXPECT_LT(s5.uz / af_d.uz, 0.95);        // stiffer than AF-D (Remark 5.8)
  // AF-BS: stiffer than AF-D (it holds the flanges' lengths too, Remark 5.8), where the strip is
  // at β₁ ≈ 10³…10⁴, and the angles kept to its rows' first order only (README.md).
  EXPECT_GT(af_bs.uz / af_d.uz, 0.9);
  EXPECT_LT(af_bs.uz / af_d.uz, 0.99);
  EXPECT_LT(af_bs.worst_angle_change, 1.0);
}
