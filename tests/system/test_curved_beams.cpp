// Curved beams (model::BeamArc, elements::helix_beam_nodes; docs/theory/beam.md §10): an arc or a
// helix as the stress-free reference centreline.
//
// The 45° bend (Bathe & Bolourchi 1979; Simo & Vu-Quoc 1986, §7.4): a cantilever on a 45° arc of
// radius R = 100 in a plane, unit square section (E = 10⁷, G = E/2, A = 1, I = 1/12, J = 1/6),
// clamped at one end, a tip force F out of the plane. Published tip positions (x along the
// radius at the clamp, y along the tangent there, z along F; undeformed tip (29.29, 70.71, 0)):
//   F = 300: Simo & Vu-Quoc (8 elements) (22.33, 58.84, 40.08), Bathe & Bolourchi
//   (22.5, 59.2, 39.5) F = 600: Simo & Vu-Quoc (8 elements) (15.79, 47.23, 53.37), Bathe &
//   Bolourchi (15.9, 47.2, 53.4)
//
// The helix: a close-coiled spring, one end clamped, an axial force P on its axis at the other
// (through a rigid arm), against Castigliano's linear theory with every section carrying the
// moment P R: torque P R cos α and bending P R sin α, shear force P cos α and axial force P sin α
// (α the pitch angle), so that δ = P L [R² (cos²α/GJ + sin²α/EI) + cos²α/GA + sin²α/EA].
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <string>

#include "isoflex/elements/beam_element.hpp"
#include "isoflex/elements/beam_mesh.hpp"
#include "isoflex/integrate/static_equilibrium.hpp"
#include "isoflex/io/model_error.hpp"
#include "isoflex/io/model_reader.hpp"
#include "isoflex/system/system.hpp"

using namespace isoflex;

namespace {

std::string bend(int elements) {
  std::ostringstream y;
  y.precision(17);
  const double E = 1e7, G = 0.5e7;
  y << "name: bend\nsolver: {analysis: static, dt: 0.0625, t_end: 1}\nbeams:\n"
    << "  - name: b\n"
    << "    arc: {axis_point: [100, 0, 0], axis: [0, 0, -1], start: [0, 0, 0], angle: 45}\n"
    << "    elements: " << elements << "\n    d1: [0, 0, 1]\n"
    << "    section: {EA: " << E << ", GA: " << G * 5.0 / 6.0 << ", EI: " << E / 12
    << ", GJ: " << G / 6 << ", A_rho: 1, M_rho: 0.1}\n"
    << "joints:\n  - {type: fixed, body_b: \"b[0]\"}\n"
    << "loads:\n  - {body: \"b[" << elements << "]\", force: [0, 0, \"600*t\"]}\n"
    << "probes:\n  - {name: tip, body: \"b[" << elements << "]\"}\n";
  return y.str();
}

// Tip positions at F = 300 and F = 600 (load factors 0.5 and 1).
std::array<Vec3, 2> bend_tip(int elements) {
  const model::Model m = io::read_model_string(bend(elements), "bend.yaml");
  const auto sys = system::System::compile(m);
  integrate::StaticEquilibrium eq(sys, m.solver);
  std::array<Vec3, 2> tip;
  eq.solve([&](const integrate::LoadStepStats& s, const VecX& x) {
    const Vec3 p = sys.probe_point(x.head(sys.n()), sys.probes()[0]);
    if (std::abs(s.t - 0.5) < 1e-12) tip[0] = p;
    if (std::abs(s.t - 1.0) < 1e-12) tip[1] = p;
  });
  return tip;
}

}  // namespace

TEST(CurvedBeams, ArcNodesLieOnTheCircleWithTangentTriads) {
  const Vec3 a(1, 2, 3), n = Vec3(1, 1, 1).normalized(), start(3, 2, 3);
  const auto q = elements::helix_beam_nodes(a, n, start, 2.0, 0.0, n, 12);
  ASSERT_EQ(q.size(), 13u);
  const Vec3 foot = a + (start - a).dot(n) * n;
  const double R = (start - foot).norm();
  for (std::size_t k = 0; k < q.size(); ++k) {
    const Vec3 x = q[k].head<3>();
    const Eigen::Map<const Mat3> D(q[k].data() + 3);
    EXPECT_NEAR((x - foot).norm(), R, 1e-14 * R) << k;
    EXPECT_NEAR((x - foot).dot(n), 0.0, 1e-14) << k;
    EXPECT_LT((D.transpose() * D - Mat3::Identity()).norm(), 1e-14) << k;
    EXPECT_NEAR(D.determinant(), 1.0, 1e-14) << k;
    // d₃ is the exact tangent n × (x − foot)/R and d₁ stays the axis (a plane arc: no twist).
    EXPECT_LT((D.col(2) - n.cross(x - foot) / R).norm(), 1e-14) << k;
    EXPECT_LT((D.col(0) - n).norm(), 1e-14) << k;
  }
  // Equal steps of 2/12 rad along the arc.
  const Vec3 x6 = q[6].head<3>();
  EXPECT_NEAR(std::acos((x6 - foot).dot(start - foot) / (R * R)), 1.0, 1e-13);
}

TEST(CurvedBeams, HelixNodesRiseByThePitchAndKeepTheirTriadsOnTheScrew) {
  const Vec3 a = Vec3::Zero(), n = Vec3::UnitZ(), start(2, 0, 0);
  const double pitch = 0.5;
  const auto q = elements::helix_beam_nodes(a, n, start, 4 * M_PI, pitch, Vec3::UnitX(), 32);
  const double alpha = std::atan(pitch / (2 * M_PI * 2));  // pitch angle
  for (std::size_t k = 0; k < q.size(); ++k) {
    const double theta = 4 * M_PI * static_cast<double>(k) / 32;
    const Vec3 x = q[k].head<3>();
    const Eigen::Map<const Mat3> D(q[k].data() + 3);
    EXPECT_LT(
        (x - Vec3(2 * std::cos(theta), 2 * std::sin(theta), pitch * theta / (2 * M_PI))).norm(),
        1e-14)
        << k;
    const Vec3 tangent(-std::sin(theta) * std::cos(alpha), std::cos(theta) * std::cos(alpha),
                       std::sin(alpha));
    EXPECT_LT((D.col(2) - tangent).norm(), 1e-14) << k;
    EXPECT_LT((D.col(0) - Vec3(std::cos(theta), std::sin(theta), 0)).norm(), 1e-14) << k;
  }
}

TEST(CurvedBeams, TheCurvedReferenceIsStressFree) {
  const model::Model m = io::read_model_string(
      "solver: {analysis: static, dt: 1, t_end: 1}\n"
      "beams:\n"
      "  - name: h\n"
      "    arc: {axis_point: [0, 0, 0], axis: [0, 0, 1], start: [1, 0, 0], angle: 540, "
      "pitch: 0.3}\n"
      "    elements: 20\n"
      "    section: {EA: 1e4, GA: 1e4, EI: 10, GJ: 10, A_rho: 1, M_rho: 0.01}\n",
      "helix.yaml");
  const auto sys = system::System::compile(m);
  ASSERT_EQ(sys.beams().size(), 1u);
  ASSERT_EQ(sys.beams()[0].elements.size(), 20u);
  for (const elements::BeamElement* e : sys.beams()[0].elements) {
    VecX q(24);
    q << sys.q0().segment<12>(12 * e->nodes()[0]), sys.q0().segment<12>(12 * e->nodes()[1]);
    EXPECT_EQ(e->potential(q), 0.0);
    EXPECT_LT(e->gradient(q).norm(), 1e-13);
  }
  EXPECT_NEAR(m.beams[0].length(), 3 * M_PI * std::hypot(1.0, 0.3 / (2 * M_PI)), 1e-14);
  const Vec3 end = sys.q0().segment<3>(12 * 20);
  EXPECT_LT((end - Vec3(-1, 0, 0.45)).norm(), 1e-14);
  EXPECT_LT((end - m.beams[0].arc->end()).norm(), 1e-14);
}

TEST(CurvedBeams, FortyFiveDegreeBendMatchesThePublishedTipPositions) {
  const std::array<Vec3, 2> simo = {Vec3(22.33, 58.84, 40.08), Vec3(15.79, 47.23, 53.37)};
  const std::array<Vec3, 2> bathe = {Vec3(22.5, 59.2, 39.5), Vec3(15.9, 47.2, 53.4)};
  const Vec3 undeformed(100 - 100 * std::cos(M_PI / 4), 100 * std::sin(M_PI / 4), 0);
  const std::array<Vec3, 2> tip = bend_tip(16);
  for (int i = 0; i < 2; ++i) {
    const double u = (simo[i] - undeformed).norm();  // the published tip displacement
    const double e_simo = (tip[i] - simo[i]).norm() / u, e_bathe = (tip[i] - bathe[i]).norm() / u;
    std::printf(
        "  [45 deg bend] F = %d, 16 elements: tip (%.4f, %.4f, %.4f); distance to Simo & Vu-Quoc "
        "%.3f %%, to Bathe & Bolourchi %.3f %% of the tip displacement\n",
        300 * (i + 1), tip[i].x(), tip[i].y(), tip[i].z(), 100 * e_simo, 100 * e_bathe);
    // Measured 0.64 % and 0.78 %. Bathe & Bolourchi's F = 300 position is 2.3 % away from this
    // one (and 1.7 % from Simo & Vu-Quoc's): only their F = 600 position is checked.
    EXPECT_LT(e_simo, 0.01) << "F = " << 300 * (i + 1);
    if (i == 1) {
      EXPECT_LT(e_bathe, 0.01) << "F = 600";
    }
    for (int c = 0; c < 3; ++c)  // every coordinate within 1 % of the tip displacement
      EXPECT_LT(std::abs(tip[i](c) - simo[i](c)), 0.01 * u) << "F = " << 300 * (i + 1) << " " << c;
  }
}

TEST(CurvedBeams, FortyFiveDegreeBendConvergesWithOrderTwo) {
  // Differences of successive meshes: e_h ≈ C h^p, so p = log₂(|x_h − x_{h/2}| / |x_{h/2} −
  // x_{h/4}|).
  std::map<int, Vec3> tip;
  for (const int n : {8, 16, 32, 64}) tip[n] = bend_tip(n)[1];
  const double d1 = (tip[8] - tip[16]).norm(), d2 = (tip[16] - tip[32]).norm(),
               d3 = (tip[32] - tip[64]).norm();
  const double p1 = std::log2(d1 / d2), p2 = std::log2(d2 / d3);
  std::printf(
      "  [45 deg bend] F = 600: |x8 - x16| = %.3e, |x16 - x32| = %.3e, |x32 - x64| = %.3e; "
      "observed orders %.3f, %.3f; 64 elements: (%.4f, %.4f, %.4f)\n",
      d1, d2, d3, p1, p2, tip[64].x(), tip[64].y(), tip[64].z());
  EXPECT_NEAR(p1, 2.0, 0.2);  // measured 2.137
  EXPECT_NEAR(p2, 2.0, 0.1);  // measured 2.031
}

namespace {

// (axial deflection − Castigliano) / Castigliano of the spring with `per_turn` elements per turn.
double helical_spring_error(int per_turn) {
  const double R = 0.05, pitch = 0.02, turns = 5, P = 1e-3;
  const double EA = 1e6, GA = 4e5, EI = 2.0, GJ = 1.5;
  const int elements = per_turn * 5;
  std::ostringstream y;
  y.precision(17);
  y << "solver: {analysis: static, dt: 1, t_end: 1}\n"
    << "beams:\n  - name: spring\n"
    << "    arc: {axis_point: [0, 0, 0], axis: [0, 0, 1], start: [" << R
    << ", 0, 0], angle: " << 360 * turns << ", pitch: " << pitch << "}\n"
    << "    elements: " << elements << "\n"
    << "    section: {EA: " << EA << ", GA: " << GA << ", EI: " << EI << ", GJ: " << GJ
    << ", A_rho: 1, M_rho: 0.01}\n"
    << "bodies:\n  - {name: arm, mass: 1, inertia: [1, 1, 1], position: [0, 0, " << pitch * turns
    << "]}\n"
    << "joints:\n  - {type: fixed, body_b: \"spring[0]\"}\n"
    << "  - {type: rigid, body_a: \"spring[" << elements << "]\", body_b: arm}\n"
    << "loads:\n  - {body: arm, force: [0, 0, " << P << "]}\n"
    << "probes:\n  - {name: end, body: arm}\n";
  const model::Model m = io::read_model_string(y.str(), "spring.yaml");
  const auto sys = system::System::compile(m);
  integrate::StaticEquilibrium eq(sys, m.solver);
  const VecX q = eq.solve().x.head(sys.n());
  const Vec3 u = sys.probe_point(q, sys.probes()[0]) - sys.probe_point(sys.q0(), sys.probes()[0]);
  const double alpha = std::atan(pitch / (2 * M_PI * R)), c = std::cos(alpha), s = std::sin(alpha);
  const double theory =
      P * m.beams[0].length() * (R * R * (c * c / GJ + s * s / EI) + c * c / GA + s * s / EA);
  std::printf(
      "  [helical spring] %d elements per turn: axial deflection %.8g, Castigliano %.8g "
      "(%+.3f %%), lateral %.2e\n",
      per_turn, u.z(), theory, 100 * (u.z() - theory) / theory, std::hypot(u.x(), u.y()));
  return (u.z() - theory) / theory;
}

}  // namespace

TEST(CurvedBeams, HelicalSpringConvergesToCastigliano) {
  const double e16 = helical_spring_error(16), e32 = helical_spring_error(32);
  EXPECT_LT(std::abs(e32), 2e-3);                // measured −0.160 % (−0.639 % with 16)
  EXPECT_NEAR(std::log2(e16 / e32), 2.0, 0.05);  // measured 2.00
}

TEST(CurvedBeams, ReaderLocatesBadArcs) {
  const std::string head =
      "beams:\n  - name: b\n    elements: 4\n"
      "    section: {EA: 1, GA: 1, EI: 1, GJ: 1, A_rho: 1, M_rho: 1}\n";
  const auto message = [&](const std::string& extra) {
    try {
      io::read_model_string(head + extra, "arc.yaml");
    } catch (const io::ModelError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("    arc: {axis_point: [0, 0, 0], axis: [0, 0, 1], start: [0, 0, 2], "
                    "angle: 90}\n")
                .find("beams[0].arc.start: lies on the axis"),
            std::string::npos);
  EXPECT_NE(message("    arc: {axis_point: [0, 0, 0], axis: [0, 0, 1], start: [1, 0, 0], "
                    "angle: 400}\n")
                .find("beams[0].arc.angle: an arc without pitch turns at most 360 degrees"),
            std::string::npos);
  EXPECT_NE(message("    arc: {axis_point: [0, 0, 0], axis: [0, 0, 1], start: [1, 0, 0], "
                    "angle: 90}\n    points: [[0, 0, 0], [1, 0, 0]]\n")
                .find("beams[0].arc: give either points"),
            std::string::npos);
  EXPECT_NE(message("    arc: {axis_point: [0, 0, 0], axis: [0, 0, 1], start: [1, 0, 0], "
                    "angle: 90}\n    d1: [0, 1, 0]\n")
                .find("beams[0].d1: must not be parallel to the arc's tangent"),
            std::string::npos);
  EXPECT_NE(message("    arc: {axis_point: [0, 0, 0], axis: [0, 0, 1], start: [1, 0, 0], "
                    "angle: 90, radius: 2}\n")
                .find("beams[0].arc.radius"),
            std::string::npos);
  EXPECT_NE(message("").find("beams[0].points: missing required key"), std::string::npos);
}
