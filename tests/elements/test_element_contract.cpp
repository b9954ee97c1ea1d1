// The element contract (src/isoflex/elements/element.hpp) checked property by property over every
// kind of element, by one typed test suite: a rigid body, a beam, a director shell quad, a
// Kirchhoff–Love NURBS patch, a bending strip, a point spring–damper (linear and with nonlinear
// laws), a bushing, and the spring–dampers of prismatic and revolute joints. Each kind is described
// by a small "maker" (top of the file); every test runs for every maker. The properties are those
// an energy–momentum scheme relies on: gradients, the discrete gradient of DNSM-III (17)–(19)
// (directionality, consistency, its tangent), the fixed-pattern assembly interface, the momentum
// maps of DNSM-III §2 (translation and rotation invariance of V make DV orthogonal to the rigid
// motions at the midpoint), objectivity, and the constant mass matrix. Measured residuals are
// printed ("[contract] …") and recorded as properties.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <initializer_list>
#include <memory>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include "isoflex/elements/beam_element.hpp"
#include "isoflex/elements/beam_mesh.hpp"
#include "isoflex/elements/bending_strip.hpp"
#include "isoflex/elements/director_shell_element.hpp"
#include "isoflex/elements/element.hpp"
#include "isoflex/elements/frame_pair.hpp"
#include "isoflex/elements/invariant_spring_damper.hpp"
#include "isoflex/elements/kl_patch_element.hpp"
#include "isoflex/elements/kl_shell_patch.hpp"
#include "isoflex/elements/point_spring_damper.hpp"
#include "isoflex/elements/revolute_spring.hpp"
#include "isoflex/elements/rigid_body.hpp"
#include "isoflex/geometry/builders.hpp"
#include "isoflex/geometry/refinement.hpp"
#include "isoflex/math/frame_node.hpp"
#include "isoflex/math/node_kind.hpp"
#include "isoflex/math/rotation.hpp"
#include "support/finite_difference.hpp"
#include "support/geometry.hpp"

using namespace isoflex;
using namespace isoflex::test;
using elements::Element;
using elements::SpMat;

namespace {

// --- Configurations on the nodes' manifolds ------------------------------------------------------

// For each 3-vector block of the stacked coordinates: true if it is a node's position φ (the first
// block of every node kind), false for a director.
std::vector<bool> position_blocks(const std::vector<NodeKind>& kinds) {
  std::vector<bool> phi;
  for (const NodeKind k : kinds)
    for (int b = 0; b < node_type(k).coordinates() / 3; ++b) phi.push_back(b == 0);
  return phi;
}

// The velocity of the rigid motion with angular velocity ω and translational velocity c at q:
// every block ω × q_b, positions also + c.
VecX rigid_velocity(const VecX& q, const std::vector<NodeKind>& kinds, const Vec3& w,
                    const Vec3& c) {
  const std::vector<bool> phi = position_blocks(kinds);
  VecX out(q.size());
  for (int b = 0; b < q.size() / 3; ++b) {
    out.segment<3>(3 * b) = w.cross(Vec3(q.segment<3>(3 * b)));
    if (phi[b]) out.segment<3>(3 * b) += c;
  }
  return out;
}

// The rigid motion q ↦ Q q + c: every block rotated by Q, positions also translated by c.
VecX rigid_motion(const VecX& q, const std::vector<NodeKind>& kinds, const Mat3& Q, const Vec3& c) {
  const std::vector<bool> phi = position_blocks(kinds);
  VecX out(q.size());
  for (int b = 0; b < q.size() / 3; ++b) {
    out.segment<3>(3 * b) = Q * q.segment<3>(3 * b);
    if (phi[b]) out.segment<3>(3 * b) += c;
  }
  return out;
}

// A random rigid motion of q0 plus a small deformation that stays on the nodes' manifolds: every
// position moved by up to `dx` per coordinate, every frame (frame node: d₁, d₂, d₃ together) and
// director (director node) turned by its own rotation of up to `angle` per component, so that
// frames stay orthonormal and directors unit vectors; point nodes are positions only.
VecX random_configuration(std::mt19937& g, const VecX& q0, const std::vector<NodeKind>& kinds,
                          double dx, double angle) {
  VecX q = q0;
  int at = 0;
  for (const NodeKind k : kinds) {
    const int n = node_type(k).coordinates();
    q.segment<3>(at) += random_vector(g, 3, dx);
    const Mat3 R = rodrigues(random_vector(g, 3, angle));
    for (int b = 1; b < n / 3; ++b) q.segment<3>(at + 3 * b) = R * q.segment<3>(at + 3 * b);
    at += n;
  }
  return rigid_motion(q, kinds, random_rotation(g), random_vector(g, 3, 1.0));
}

// --- Makers: one per element kind ----------------------------------------------------------------
// Each gives `element` (used by the tests only through the Element interface), its reference
// configuration `q0`, the kind of each of its nodes `kinds` (stacked in that order), `deformed(g)`
// (random_configuration with sizes suited to the element), a name, and kInvariant: whether the
// potential is invariant under rigid motions (true for all here: gravity is zero).

struct RigidBodyMaker {
  static constexpr const char* kName = "RigidBody";
  static constexpr bool kInvariant = true;
  std::vector<NodeKind> kinds{NodeKind::frame};
  elements::RigidBody element{0, 2.5, Vec3(0.6, 0.9, 1.2), Vec3::Zero()};
  VecX q0 = frame_node::make(Vec3(0.2, -0.1, 0.4), rodrigues(Vec3(0.3, -0.5, 0.2)));
  VecX deformed(std::mt19937& g) const { return random_configuration(g, q0, kinds, 0.05, 0.1); }
};

// A curved and twisted reference (the triads turn by (0.3, −0.2, 0.25) rad between the nodes,
// the chord is not along d₃), stiffnesses of DNSM-III §5.2's size, all different.
struct BeamMaker {
  static constexpr const char* kName = "Beam";
  static constexpr bool kInvariant = true;
  static elements::BeamSection section() {
    elements::BeamSection s;
    s.EA = 1.0e5;
    s.GA1 = 0.7e5;
    s.GA2 = 0.8e5;
    s.EI1 = 1.0e4;
    s.EI2 = 1.3e4;
    s.GJ = 0.9e4;
    s.A_rho = 20.0;
    s.M_rho1 = 10.0;
    s.M_rho2 = 7.0;
    s.eta = 0.01;  // Kelvin–Voigt damping: only the viscous-force tests see it
    return s;
  }
  static frame_node::Q node_a() {
    return frame_node::make(Vec3(0.1, -0.2, 0.3), rodrigues(Vec3(0.4, -0.3, 0.7)));
  }
  static frame_node::Q node_b() {
    const Mat3 Ra = rodrigues(Vec3(0.4, -0.3, 0.7));
    return frame_node::make(node_a().head<3>() + Ra * Vec3(0.05, -0.08, 1.0),
                            Ra * rodrigues(Vec3(0.3, -0.2, 0.25)));
  }
  std::vector<NodeKind> kinds{NodeKind::frame, NodeKind::frame};
  elements::BeamElement element{3, 7, node_a(), node_b(), section(), Vec3::Zero()};
  VecX q0 = (VecX(24) << node_a(), node_b()).finished();
  VecX deformed(std::mt19937& g) const { return random_configuration(g, q0, kinds, 0.05, 0.1); }
};

// The beam of BeamMaker with its own triads at both nodes (elements::BeamElement's triad_a,
// triad_b: the corner of a polyline), turned by 90° about d₂ at a and by 30° about a skew axis at b
// against the nodes' triads: the element's directors are constant combinations of the nodes'.
struct CornerBeamMaker : BeamMaker {
  static constexpr const char* kName = "CornerBeam";
  static Mat3 triad(const frame_node::Q& q, const Mat3& turn) {
    Mat3 D;
    for (int j = 0; j < 3; ++j) D.col(j) = q.segment<3>(3 + 3 * j);
    return D * turn;
  }
  elements::BeamElement element{3,
                                7,
                                node_a(),
                                node_b(),
                                section(),
                                Vec3::Zero(),
                                triad(node_a(), rodrigues(Vec3(0.0, 1.5707963267948966, 0.0))),
                                triad(node_b(), rodrigues(Vec3(0.3, 0.2, -0.4)))};
};

// One element of a helix (elements::helix_beam_nodes, the nodes of a curved beam): radius 0.8,
// pitch 0.5, a 40° step, d₁ from a skew hint — the reference the model file's `arc` builds.
struct HelixBeamMaker : BeamMaker {
  static constexpr const char* kName = "HelixBeam";
  static std::vector<frame_node::Q> nodes() {
    return elements::helix_beam_nodes(Vec3(0.1, 0.2, -0.3), Vec3(0.2, -0.1, 1.0),
                                      Vec3(0.9, 0.2, -0.2), 0.6981317007977318, 0.5,
                                      Vec3(0.3, 1.0, 0.2), 1);
  }
  elements::BeamElement element{3, 7, nodes()[0], nodes()[1], section(), Vec3::Zero()};
  VecX q0 = (VecX(24) << nodes()[0], nodes()[1]).finished();
  VecX deformed(std::mt19937& g) const { return random_configuration(g, q0, kinds, 0.05, 0.1); }
};

// The curved, skewed quad of test_director_shell_element.cpp: corners off a plane, directors the
// corner normals tilted by small rotations. Membrane (Eh = 10⁴), bending and shear stiffnesses of
// very different size; ANS transverse shear and assumed in-plane shear (the defaults).
struct DirectorShellMaker {
  static constexpr const char* kName = "DirectorShell";
  static constexpr bool kInvariant = true;
  static elements::ShellMaterial material() {
    elements::ShellMaterial m;
    m.E = 1.0e5;
    m.nu = 0.3;
    m.thickness = 0.1;
    m.density = 7.0;
    m.eta = 0.01;
    return m;
  }
  static Vec<24> reference() {
    const std::array<Vec3, 4> x = {Vec3(0.0, 0.0, 0.0), Vec3(1.1, 0.15, 0.08),
                                   Vec3(0.95, 1.05, -0.12), Vec3(-0.1, 0.9, 0.1)};
    const std::array<Vec3, 4> tilt = {Vec3(0.05, -0.1, 0.02), Vec3(-0.08, 0.03, 0.1),
                                      Vec3(0.1, 0.07, -0.05), Vec3(-0.02, -0.09, 0.04)};
    Vec<24> q;
    for (int a = 0; a < 4; ++a) {
      const Vec3 n = (x[(a + 1) % 4] - x[a]).cross(x[(a + 3) % 4] - x[a]).normalized();
      q.segment<3>(6 * a) = x[a];
      q.segment<3>(6 * a + 3) = rodrigues(tilt[a]) * n;
    }
    return q;
  }
  std::vector<NodeKind> kinds = std::vector<NodeKind>(4, NodeKind::director);
  elements::DirectorShellElement element{{2, 5, 9, 4}, reference(), material(), Vec3::Zero()};
  VecX q0 = reference();
  VecX deformed(std::mt19937& g) const { return random_configuration(g, q0, kinds, 0.05, 0.1); }
};

// A Kirchhoff–Love patch (IGA-thesis ch. 3–4): a rational cylinder sector (radius 1, length 1.2,
// 80°) k-refined to bicubic with 2 × 2 knot spans, 5 × 5 = 25 control points (point nodes).
struct KLPatchMaker {
  static constexpr const char* kName = "KLPatch";
  static constexpr bool kInvariant = true;
  static std::shared_ptr<const elements::KLShellPatch> patch() {
    const geometry::NurbsSurface s =
        geometry::k_refine(geometry::cylinder_sector(1.0, 1.2, 80.0 * kPi / 180.0), 1, 2, 1, 1);
    elements::KLShellSection section;
    section.young = 1.0e5;
    section.poisson = 0.3;
    section.thickness = 0.1;
    section.density = 7.0;
    section.eta = 0.01;
    return std::make_shared<const elements::KLShellPatch>(s, section);
  }
  static std::vector<int> node_numbers(int n) {
    std::vector<int> nodes(n);
    for (int i = 0; i < n; ++i) nodes[i] = 10 + i;
    return nodes;
  }
  elements::KLPatchElement element{patch(), elements::KLKinematics::nonlinear, node_numbers(25)};
  VecX q0 = element.patch().reference_positions();
  std::vector<NodeKind> kinds =
      std::vector<NodeKind>(static_cast<std::size_t>(q0.size() / 3), NodeKind::point);
  VecX deformed(std::mt19937& g) const { return random_configuration(g, q0, kinds, 0.03, 0.0); }
};

// A bending strip (IGA-thesis §4.4.2, elements/bending_strip.hpp) over 4 triples across a kinked,
// slightly curved interface (about 120° between the flanges): one quadratic element across, three
// linear ones along, 12 control points; no mass (kMassless).
struct BendingStripMaker {
  static constexpr const char* kName = "BendingStrip";
  static constexpr bool kInvariant = true;
  static constexpr bool kMassless = true;
  static std::vector<std::array<Vec3, 3>> triples() {
    std::vector<std::array<Vec3, 3>> t;
    for (int j = 0; j < 4; ++j) {
      const Vec3 s(0.02 * j, 0.4 * j + 0.05 * j * j, 0.01 * j * j);
      t.push_back({s + Vec3(-0.3, 0.02, 0.0), s, s + Vec3(0.15, -0.01, 0.26)});
    }
    return t;
  }
  elements::KLPatchElement element{elements::bending_strip(triples(), 1.0e5, 0.1),
                                   elements::KLKinematics::nonlinear,
                                   KLPatchMaker::node_numbers(12)};
  VecX q0 = element.patch().reference_positions();
  std::vector<NodeKind> kinds = std::vector<NodeKind>(12, NodeKind::point);
  VecX deformed(std::mt19937& g) const { return random_configuration(g, q0, kinds, 0.03, 0.0); }
};

// A spring–damper (elements/point_spring_damper.hpp) from a point of a rigid body's frame node
// (body coordinates (0.2, 0.1, −0.3)) to a point node, its free length the initial distance (the
// deformed configurations stretch and compress it), with a damper; no mass.
struct SpringDamperMaker {
  static constexpr const char* kName = "SpringDamper";
  static constexpr bool kInvariant = true;
  static constexpr bool kMassless = true;
  std::vector<NodeKind> kinds{NodeKind::frame, NodeKind::point};
  VecX q0 = reference();
  elements::PointSpringDamper element = make(q0);
  static VecX reference() {
    VecX q(15);
    q << frame_node::make(Vec3(0.2, -0.1, 0.4), rodrigues(Vec3(0.3, -0.5, 0.2))),
        Vec3(1.1, 0.7, -0.2);
    return q;
  }
  static elements::PointSpringDamper make(const VecX& q0) {
    const Vec3 X(0.2, 0.1, -0.3);
    elements::MaterialPointMap a, b;
    a.P = Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, 15);
    b.P = a.P;
    a.P.block<3, 3>(0, 0) = Mat3::Identity();
    for (int i = 0; i < 3; ++i) a.P.block<3, 3>(0, 3 + 3 * i) = X(i) * Mat3::Identity();
    b.P.block<3, 3>(0, 12) = Mat3::Identity();
    const double z0 = (a.P * q0 - b.P * q0).norm();
    return elements::PointSpringDamper({3, 8}, 15, a, b, {40.0, 0.7, z0, "", ""}, q0);
  }
  VecX deformed(std::mt19937& g) const { return random_configuration(g, q0, kinds, 0.05, 0.1); }
};

// The spring–damper with nonlinear laws (docs/theory/coupling.md §6): N(e) = 40 e + 900 e³ (its
// energy by Gauss–Legendre quadrature, exact for this polynomial) and a damper
// N_d(v) = 0.7 v + 0.3 v³, not linear in the velocity (kLinearViscous).
struct NonlinearSpringDamperMaker {
  static constexpr const char* kName = "NonlinearSpring";
  static constexpr bool kInvariant = true;
  static constexpr bool kMassless = true;
  static constexpr bool kLinearViscous = false;
  std::vector<NodeKind> kinds{NodeKind::frame, NodeKind::point};
  VecX q0 = SpringDamperMaker::reference();
  elements::PointSpringDamper element = make(q0);
  static elements::PointSpringDamper make(const VecX& q0) {
    const elements::PointSpringDamper linear = SpringDamperMaker::make(q0);
    const Vec3 X(0.2, 0.1, -0.3);
    elements::MaterialPointMap a, b;
    a.P = Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, 15);
    b.P = a.P;
    a.P.block<3, 3>(0, 0) = Mat3::Identity();
    for (int i = 0; i < 3; ++i) a.P.block<3, 3>(0, 3 + 3 * i) = X(i) * Mat3::Identity();
    b.P.block<3, 3>(0, 12) = Mat3::Identity();
    return elements::PointSpringDamper(
        {3, 8}, 15, a, b, {0.0, 0.0, linear.law().free_length, "40*e + 900*e^3", "0.7*v + 0.3*v^3"},
        q0);
  }
  VecX deformed(std::mt19937& g) const { return random_configuration(g, q0, kinds, 0.05, 0.1); }
};

// Two rigid bodies' frame nodes and the frames at a common point p with axes E at q0 (the joint
// frames of a bushing or a joint spring, elements/frame_pair.hpp).
struct TwoFrames {
  static VecX reference() {
    VecX q(24);
    q << frame_node::make(Vec3(0.2, -0.1, 0.4), rodrigues(Vec3(0.3, -0.5, 0.2))),
        frame_node::make(Vec3(0.9, 0.3, 0.1), rodrigues(Vec3(-0.2, 0.4, 0.6)));
    return q;
  }
  static elements::FramePair pair(const VecX& q0) {
    const Vec3 p(0.5, 0.2, 0.3);
    const Mat3 E = rodrigues(Vec3(0.1, 0.7, -0.4));
    elements::AttachedFrame f[2];
    for (int k = 0; k < 2; ++k) {
      const frame_node::Q qk = q0.segment<12>(12 * k);
      const Mat3 R = frame_node::directors(qk);
      f[k] = {R.transpose() * (p - frame_node::phi(qk)), R.transpose() * E, false};
    }
    return elements::FramePair(f[0], f[1]);
  }
};

// A bushing (elements/invariant_spring_damper.hpp): the six strains (u, θ) of two frames with a
// full symmetric positive definite stiffness and a damping matrix.
struct BushingMaker {
  static constexpr const char* kName = "Bushing";
  static constexpr bool kInvariant = true;
  static constexpr bool kMassless = true;
  std::vector<NodeKind> kinds{NodeKind::frame, NodeKind::frame};
  VecX q0 = TwoFrames::reference();
  elements::InvariantSpringDamper element = make(q0);
  static MatX spd(double scale, unsigned seed) {
    std::mt19937 g(seed);
    const MatX A = Eigen::Map<const MatX>(random_vector(g, 36).data(), 6, 6);
    return scale * (A * A.transpose() + MatX::Identity(6, 6));
  }
  static elements::InvariantSpringDamper make(const VecX& q0) {
    const elements::FramePair pair = TwoFrames::pair(q0);
    std::vector<elements::QuadraticInvariant> e;
    for (int i = 0; i < 3; ++i) e.push_back(pair.displacement(i));
    for (int i = 0; i < 3; ++i) e.push_back(pair.rotation(i));
    return elements::InvariantSpringDamper({4, 9}, e, spd(50.0, 7), spd(0.5, 8), q0);
  }
  VecX deformed(std::mt19937& g) const { return random_configuration(g, q0, kinds, 0.05, 0.1); }
};

// The spring–damper of a prismatic joint: the slide u₃ along the joint axis, k = 70, c = 0.4.
struct SliderSpringMaker {
  static constexpr const char* kName = "SliderSpring";
  static constexpr bool kInvariant = true;
  static constexpr bool kMassless = true;
  std::vector<NodeKind> kinds{NodeKind::frame, NodeKind::frame};
  VecX q0 = TwoFrames::reference();
  elements::InvariantSpringDamper element{{4, 9},
                                          {TwoFrames::pair(q0).displacement(2)},
                                          MatX::Constant(1, 1, 70.0),
                                          MatX::Constant(1, 1, 0.4),
                                          q0};
  VecX deformed(std::mt19937& g) const { return random_configuration(g, q0, kinds, 0.05, 0.1); }
};

// The rotational spring–damper of a revolute joint (elements/revolute_spring.hpp), k = 30,
// c = 0.6, on frames that the deformed configurations turn apart about every axis.
struct RevoluteSpringMaker {
  static constexpr const char* kName = "RevoluteSpring";
  static constexpr bool kInvariant = true;
  static constexpr bool kMassless = true;
  std::vector<NodeKind> kinds{NodeKind::frame, NodeKind::frame};
  VecX q0 = TwoFrames::reference();
  elements::RevoluteSpring element{{4, 9}, TwoFrames::pair(q0), 30.0, 0.6, 0.0, q0};
  VecX deformed(std::mt19937& g) const { return random_configuration(g, q0, kinds, 0.05, 0.1); }
};

// Whether the maker's element has viscous forces linear in the velocity (all but a nonlinear
// damping law).
template <class Maker>
constexpr bool linear_viscous() {
  if constexpr (requires { Maker::kLinearViscous; })
    return Maker::kLinearViscous;
  else
    return true;
}

// Whether the maker's element has no mass at all (a bending strip): its mass matrix is zero.
template <class Maker>
constexpr bool massless() {
  if constexpr (requires { Maker::kMassless; })
    return Maker::kMassless;
  else
    return false;
}

// --- The fixture ---------------------------------------------------------------------------------

// Prints and records a measured residual (the worst over a test's trials, for one kind).
void report(const char* kind, const char* what, double v) {
  std::printf("  [contract] %-14s %-44s %.2e\n", kind, what, v);
  ::testing::Test::RecordProperty(what, sci(v));
}

// Σ over the position blocks of v (the linear momentum map applied to a force).
Vec3 position_sum(const VecX& v, const std::vector<bool>& phi) {
  Vec3 s = Vec3::Zero();
  for (int b = 0; b < v.size() / 3; ++b)
    if (phi[b]) s += v.segment<3>(3 * b);
  return s;
}

// Σ_k x_k × v_k over all 3-vector blocks (the angular momentum map applied to a force).
Vec3 moment(const VecX& x, const VecX& v) {
  Vec3 s = Vec3::Zero();
  for (int b = 0; b < v.size() / 3; ++b) s += x.segment<3>(3 * b).cross(v.segment<3>(3 * b));
  return s;
}

// Central differences of f at x with Richardson extrapolation, (4 J(h/2) − J(h))/3 with h =
// fd_step(xⱼ) per column: the O(h²) truncation error of central_jacobian cancels, the round-off
// stays ~ε|f|/h. The KL patch needs it for DV: its Gonzalez correction c w (c = N/(w·w),
// docs/theory/kl-shell.md §10) has large third derivatives in elements whose increment is close to
// rigid, and plain central differences missed the (correct) tangent by up to 1.4·10⁻⁶ there,
// falling exactly by 4 per halving of h.
MatX extrapolated_jacobian(const std::function<VecX(const VecX&)>& f, const VecX& x) {
  auto J = [&](double scale) {
    MatX out;
    for (int j = 0; j < x.size(); ++j) {
      const double h = scale * fd_step(x(j));
      VecX xp = x, xm = x;
      xp(j) += h;
      xm(j) -= h;
      const VecX col = (f(xp) - f(xm)) / (2.0 * h);
      if (j == 0) out.resize(col.size(), x.size());
      out.col(j) = col;
    }
    return out;
  };
  return (4.0 * J(0.5) - J(1.0)) / 3.0;
}

// Relative size of a scalar residual: |r| / max(scales…, 1).
double rel(double r, std::initializer_list<double> scales) {
  double s = 1.0;
  for (double v : scales) s = std::max(s, std::abs(v));
  return std::abs(r) / s;
}

template <class Maker>
class ElementContract : public ::testing::Test {
 protected:
  static constexpr const char* kind = Maker::kName;
  static constexpr int kTrials = 3;

  Maker maker;
  const Element& element = maker.element;
  const std::vector<bool> phi = position_blocks(maker.kinds);
  std::mt19937 g{2024};

  int size() const { return static_cast<int>(maker.q0.size()); }
  VecX deformed() { return maker.deformed(g); }
  VecX dv(const VecX& qn, const VecX& qn1) const {
    return element.discrete_gradient(qn, qn1, nullptr);
  }
};

struct MakerNames {
  template <class T>
  static std::string GetName(int) {
    return T::kName;
  }
};

using Makers =
    ::testing::Types<RigidBodyMaker, BeamMaker, CornerBeamMaker, HelixBeamMaker, DirectorShellMaker,
                     KLPatchMaker, BendingStripMaker, SpringDamperMaker, NonlinearSpringDamperMaker,
                     BushingMaker, SliderSpringMaker, RevoluteSpringMaker>;
TYPED_TEST_SUITE(ElementContract, Makers, MakerNames);

// The elements with numerical dissipation (Element::strain_dissipation; section 9 below).
template <class Maker>
class StrainDissipationContract : public ElementContract<Maker> {};
using DissipatingMakers =
    ::testing::Types<BeamMaker, CornerBeamMaker, HelixBeamMaker, DirectorShellMaker>;
TYPED_TEST_SUITE(StrainDissipationContract, DissipatingMakers, MakerNames);

}  // namespace

// The maker is consistent with the element: one node kind per node, stacked sizes adding up, and
// the reference configuration on the nodes' manifolds is stress free (V(q₀) = 0, ∇V(q₀) = 0).
TYPED_TEST(ElementContract, SizesAndStressFreeReference) {
  const auto& e = this->element;
  ASSERT_EQ(e.nodes().size(), this->maker.kinds.size());
  int n = 0;
  for (const NodeKind k : this->maker.kinds) n += node_type(k).coordinates();
  ASSERT_EQ(n, this->size());
  EXPECT_EQ(e.gradient(this->maker.q0).size(), n);
  EXPECT_EQ(e.mass().rows(), n);
  EXPECT_EQ(e.mass().cols(), n);
  const double V0 = e.potential(this->maker.q0);
  const double G0 = e.gradient(this->maker.q0).norm();
  report(this->kind, "|V(q0)|, |grad V(q0)|", std::max(std::abs(V0), G0));
  EXPECT_LT(std::abs(V0), 1e-10);
  EXPECT_LT(G0, 1e-8);
  // The deformed configurations are deformed: the tests below are not about zero forces (except
  // for the rigid body, whose potential is zero without gravity).
  const VecX q = this->deformed();
  std::printf("  [contract] %-14s V(deformed) = %.3e, |grad V| = %.3e\n", this->kind,
              e.potential(q), e.gradient(q).norm());
}

// 1. ∇V is the derivative of V: central finite differences (step ∛ε, truncation O(h²)).
TYPED_TEST(ElementContract, GradientIsTheDerivativeOfThePotential) {
  const auto& e = this->element;
  auto V = [&](const VecX& q) -> VecX { return VecX::Constant(1, e.potential(q)); };
  double worst = 0.0;
  for (int t = 0; t < this->kTrials; ++t) {
    const VecX q = this->deformed();
    const double r = rel_diff(e.gradient(q).transpose(), central_jacobian(V, q));
    EXPECT_LT(r, 1e-6) << "trial " << t;
    worst = std::max(worst, r);
  }
  report(this->kind, "gradient vs FD (rel)", worst);
}

// 2a. Directionality of the discrete gradient, DNSM-III (17): DV(qₙ, qₙ₊₁)·(qₙ₊₁ − qₙ) =
// V(qₙ₊₁) − V(qₙ) to round-off, between two configurations that differ by a finite rigid motion
// as well as a deformation (what makes the energy of the midpoint rule conserved exactly).
TYPED_TEST(ElementContract, DiscreteGradientIsDirectional) {
  const auto& e = this->element;
  double worst = 0.0;
  for (int t = 0; t < this->kTrials; ++t) {
    const VecX qa = this->deformed(), qb = this->deformed();
    const double Va = e.potential(qa), Vb = e.potential(qb);
    const double r = rel(this->dv(qa, qb).dot(qb - qa) - (Vb - Va), {Va, Vb, Vb - Va});
    EXPECT_LT(r, 1e-11) << "trial " << t << ": V = " << Va << ", " << Vb;
    worst = std::max(worst, r);
  }
  report(this->kind, "DV.dq - dV (rel)", worst);
}

// 2b. Consistency of the discrete gradient, DNSM-III (18): DV(q, q) = ∇V(q).
TYPED_TEST(ElementContract, DiscreteGradientOnTheDiagonalIsTheGradient) {
  const auto& e = this->element;
  double worst = 0.0;
  for (int t = 0; t < this->kTrials; ++t) {
    const VecX q = this->deformed();
    const double r = rel_diff(this->dv(q, q), e.gradient(q));
    EXPECT_LT(r, 1e-10) << "trial " << t;
    worst = std::max(worst, r);
  }
  report(this->kind, "DV(q,q) - grad V(q) (rel)", worst);
}

// 2c. The iteration matrix of the energy–momentum step: ∂DV/∂qₙ₊₁ (DNSM-III (19) linearized) is
// the derivative of DV in its second argument (central finite differences, extrapolated).
TYPED_TEST(ElementContract, DiscreteGradientTangentMatchesFiniteDifference) {
  const auto& e = this->element;
  double worst = 0.0;
  for (int t = 0; t < this->kTrials; ++t) {
    const VecX qa = this->deformed(), qb = this->deformed();
    MatX K;
    e.discrete_gradient(qa, qb, &K);
    ASSERT_EQ(K.rows(), this->size());
    ASSERT_EQ(K.cols(), this->size());
    const MatX K_fd = extrapolated_jacobian([&](const VecX& q) { return this->dv(qa, q); }, qb);
    const double r = rel_diff(K, K_fd);
    EXPECT_LT(r, 1e-6) << "trial " << t;
    worst = std::max(worst, r);
  }
  report(this->kind, "dDV/dq1 vs FD (rel)", worst);
}

// 2d. The tangent at one configuration (statics, the DAE integrators): gradient_in_pattern gives
// ∇V(q) and, at pattern()'s positions, ∇²V(q) — the central finite-difference derivative of the
// gradient, with nothing outside the pattern.
TYPED_TEST(ElementContract, TangentAtOneConfigurationMatchesFiniteDifference) {
  const auto& e = this->element;
  const SpMat P = e.pattern();
  double worst_g = 0.0, worst_k = 0.0;
  for (int t = 0; t < this->kTrials; ++t) {
    const VecX q = this->deformed();
    std::vector<double> values(P.nonZeros(), std::nan(""));
    const VecX g = e.gradient_in_pattern(q, values.data());
    const double r_g = std::max(rel_diff(g, e.gradient(q)),
                                rel_diff(e.gradient_in_pattern(q, nullptr), e.gradient(q)));
    SpMat K = P;
    std::copy(values.begin(), values.end(), K.valuePtr());
    const MatX K_fd = extrapolated_jacobian([&](const VecX& x) { return e.gradient(x); }, q);
    const double r_k =
        (MatX(K) - K_fd).cwiseAbs().maxCoeff() / std::max(K_fd.cwiseAbs().maxCoeff(), 1.0);
    EXPECT_LT(r_g, 1e-10) << "trial " << t;
    EXPECT_LT(r_k, 1e-6) << "trial " << t;
    worst_g = std::max(worst_g, r_g);
    worst_k = std::max(worst_k, r_k);
  }
  report(this->kind, "gradient_in_pattern vs gradient (rel)", worst_g);
  report(this->kind, "tangent vs FD of the gradient (rel max)", worst_k);
}

// 3. Second-order consistency, DNSM-III (18) with the midpoint rule: DV(q̄ − h d, q̄ + h d) =
// ∇V(q̄) + O(h²) (the expansion is even in h, so the error falls by 4 per halving of h). An
// element whose discrete gradient is exact for its potential (here the rigid body: V is linear in
// q, zero without gravity) has a difference of round-off at every h: that case is told apart by
// the size of the difference at the largest h, and then held to round-off instead.
TYPED_TEST(ElementContract, DiscreteGradientIsSecondOrderConsistent) {
  const auto& e = this->element;
  double worst_ratio_miss = -1.0, largest_exact = -1.0;  // −1: no trial of that case
  for (int t = 0; t < this->kTrials; ++t) {
    const VecX q = this->deformed();
    const VecX d = random_vector(this->g, this->size(), 1.0);
    const VecX grad = e.gradient(q);
    const double scale = std::max(grad.norm(), 1.0);
    std::array<double, 3> err{};
    for (int k = 0; k < 3; ++k) {
      const double h = 1e-2 / (1 << k);
      err[k] = (this->dv(q - h * d, q + h * d) - grad).norm() / scale;
    }
    if (err[0] < 1e-10) {  // exact for this potential: round-off only
      for (int k = 0; k < 3; ++k) EXPECT_LT(err[k], 1e-10) << "trial " << t << ", h index " << k;
      largest_exact = std::max(largest_exact, err[0]);
      continue;
    }
    for (int k = 0; k < 2; ++k) {
      const double ratio = err[k] / err[k + 1];
      EXPECT_GE(ratio, 3.5) << "trial " << t << ": errors " << err[0] << " " << err[1] << " "
                            << err[2];
      EXPECT_LE(ratio, 4.5) << "trial " << t << ": errors " << err[0] << " " << err[1] << " "
                            << err[2];
      worst_ratio_miss = std::max(worst_ratio_miss, std::abs(ratio - 4.0));
    }
    std::printf("  [contract] %-14s |DV - grad V|/|grad V| at h = 1e-2: %.2e\n", this->kind,
                err[0]);
  }
  if (worst_ratio_miss >= 0.0) report(this->kind, "|ratio - 4| per halving of h", worst_ratio_miss);
  if (largest_exact >= 0.0) report(this->kind, "exact case: |DV - grad V| (rel)", largest_exact);
}

// 4. The fixed-pattern interface (element.hpp, "Assembly into a fixed global pattern") gives what
// the dense one gives: pattern() square of the stacked size and compressed,
// discrete_gradient_in_pattern the same DV, its values at pattern()'s positions the dense
// ∂DV/∂qₙ₊₁ (which has nothing outside the pattern), and sparse_mass() the mass().
TYPED_TEST(ElementContract, FixedPatternAgreesWithDense) {
  const auto& e = this->element;
  const int n = this->size();
  const SpMat P = e.pattern();
  ASSERT_EQ(P.rows(), n);
  ASSERT_EQ(P.cols(), n);
  ASSERT_TRUE(P.isCompressed());
  double worst_dv = 0.0, worst_in = 0.0, worst_out = 0.0;
  for (int t = 0; t < this->kTrials; ++t) {
    const VecX qa = this->deformed(), qb = this->deformed();
    MatX K;
    const VecX dv = e.discrete_gradient(qa, qb, &K);
    std::vector<double> values(P.nonZeros(), std::nan(""));
    const VecX dv_p = e.discrete_gradient_in_pattern(qa, qb, values.data());
    const VecX dv_0 = e.discrete_gradient_in_pattern(qa, qb, nullptr);
    const double r_dv = std::max(rel_diff(dv_p, dv), rel_diff(dv_0, dv));
    EXPECT_LT(r_dv, 1e-14) << "trial " << t;
    SpMat Kp = P;
    std::copy(values.begin(), values.end(), Kp.valuePtr());
    SpMat mask = P;
    std::fill(mask.valuePtr(), mask.valuePtr() + mask.nonZeros(), 1.0);
    const MatX in = MatX(mask).cwiseProduct(K);  // the dense entries inside the pattern
    const double scale = std::max(K.cwiseAbs().maxCoeff(), 1.0);
    const double r_in = (MatX(Kp) - in).cwiseAbs().maxCoeff() / scale;
    const double r_out = (K - in).cwiseAbs().maxCoeff() / scale;
    EXPECT_LT(r_in, 1e-14) << "trial " << t;
    EXPECT_LT(r_out, 1e-14) << "trial " << t << ": dense entries outside the pattern";
    worst_dv = std::max(worst_dv, r_dv);
    worst_in = std::max(worst_in, r_in);
    worst_out = std::max(worst_out, r_out);
  }
  const MatX M = e.mass();
  const double r_m = massless<TypeParam>() ? MatX(e.sparse_mass()).cwiseAbs().maxCoeff()
                                           : (MatX(e.sparse_mass()) - M).cwiseAbs().maxCoeff() /
                                                 M.cwiseAbs().maxCoeff();
  EXPECT_LT(r_m, 1e-15);
  report(this->kind, "in-pattern DV vs dense (rel)", worst_dv);
  report(this->kind, "in-pattern values vs dense K (rel max)", worst_in);
  report(this->kind, "dense K outside the pattern (rel max)", worst_out);
  report(this->kind, "sparse_mass vs mass (rel max)", r_m);
}

// 5. Momentum maps (DNSM-III §2): V invariant under translations makes the forces DV(qₙ, qₙ₊₁)
// sum to zero over the positions (linear momentum conserved by the midpoint rule); V invariant
// under rotations makes their moment about the origin at the midpoint vanish, Σ_k q̄_k × DV_k = 0
// over all 3-vector blocks k (positions and directors alike; angular momentum conserved).
TYPED_TEST(ElementContract, DiscreteGradientIsOrthogonalToRigidMotionsAtTheMidpoint) {
  const auto& e = this->element;
  double worst_lin = 0.0, worst_ang = 0.0;
  for (int t = 0; t < this->kTrials; ++t) {
    const VecX qa = this->deformed(), qb = this->deformed();
    const VecX mid = 0.5 * (qa + qb);
    const VecX dv = e.discrete_gradient(qa, qb, nullptr);
    const double scale = std::max(dv.norm(), 1.0);
    const double r_lin = position_sum(dv, this->phi).norm() / scale;
    EXPECT_LT(r_lin, 1e-12) << "trial " << t;
    worst_lin = std::max(worst_lin, r_lin);
    if (!TypeParam::kInvariant) continue;
    const double r_ang = moment(mid, dv).norm() / (scale * std::max(mid.norm(), 1.0));
    EXPECT_LT(r_ang, 1e-12) << "trial " << t;
    worst_ang = std::max(worst_ang, r_ang);
  }
  report(this->kind, "sum of position forces / |DV|", worst_lin);
  if (TypeParam::kInvariant) report(this->kind, "sum q_mid x DV / (|DV| |q_mid|)", worst_ang);
}

// 6. Objectivity (DNSM-III §2, the invariance behind the momentum maps, for finite motions):
// V(Q q + c) = V(q), and DV(Q qₙ + c, Q qₙ₊₁ + c) = Q DV(qₙ, qₙ₊₁) block by block.
TYPED_TEST(ElementContract, RigidMotionInvariance) {
  if (!TypeParam::kInvariant) GTEST_SKIP() << "potential not invariant under rigid motions";
  const auto& e = this->element;
  const auto& kinds = this->maker.kinds;
  double worst_v = 0.0, worst_dv = 0.0;
  for (int t = 0; t < this->kTrials; ++t) {
    const VecX qa = this->deformed(), qb = this->deformed();
    const Mat3 Q = random_rotation(this->g);
    const Vec3 c = random_vector(this->g, 3, 1.0);
    const double Va = e.potential(qa);
    const double r_v = rel(e.potential(rigid_motion(qa, kinds, Q, c)) - Va, {Va});
    EXPECT_LT(r_v, 1e-12) << "trial " << t;
    const VecX dv = this->dv(qa, qb);
    const VecX dv_moved = this->dv(rigid_motion(qa, kinds, Q, c), rigid_motion(qb, kinds, Q, c));
    // Q·DV block by block: rigid_motion with c = 0 rotates every block.
    const double r_dv = rel_diff(dv_moved, rigid_motion(dv, kinds, Q, Vec3::Zero()));
    EXPECT_LT(r_dv, 1e-11) << "trial " << t;
    worst_v = std::max(worst_v, r_v);
    worst_dv = std::max(worst_dv, r_dv);
  }
  report(this->kind, "V(Qq+c) - V(q) (rel)", worst_v);
  report(this->kind, "DV(Qqa+c, Qqb+c) - Q DV (rel)", worst_dv);
}

// 7. The mass matrix (kinetic energy ½ q̇ᵀ M q̇, DNSM-III (16)/(17); IGA-thesis (4.24) for the
// patch) is symmetric, positive semi-definite and constant.
TYPED_TEST(ElementContract, MassIsSymmetricPositiveSemiDefiniteAndConstant) {
  const auto& e = this->element;
  const MatX M = e.mass();
  ASSERT_EQ(M.rows(), this->size());
  ASSERT_EQ(M.cols(), this->size());
  if (massless<TypeParam>()) {
    EXPECT_EQ(M.cwiseAbs().maxCoeff(), 0.0);
    return;
  }
  const double r_sym = (M - M.transpose()).norm() / M.norm();
  EXPECT_LE(r_sym, 1e-14);
  const Eigen::SelfAdjointEigenSolver<MatX> eig(0.5 * (M + M.transpose()), Eigen::EigenvaluesOnly);
  const double lo = eig.eigenvalues().minCoeff(), hi = eig.eigenvalues().maxCoeff();
  EXPECT_GT(hi, 0.0);
  EXPECT_GE(lo, -1e-12 * hi);
  EXPECT_EQ(e.mass(), M);  // constant: the same on every call
  report(this->kind, "mass asymmetry (rel)", r_sym);
  report(this->kind, "mass smallest / largest eigenvalue", lo / hi);
}

// 8. Kelvin–Voigt viscous forces (IGA-thesis §3.5; docs/theory/kl-shell.md §11, beam.md §9,
// shell.md §11): f_v(q, q̇) = Bᵀ η C B q̇. Both derivatives against central differences, in the
// element's pattern; f_v linear in q̇.
TYPED_TEST(ElementContract, ViscousForceTangentsMatchFiniteDifference) {
  const auto& e = this->element;
  if (!e.viscous()) GTEST_SKIP() << "no viscous forces";
  const SpMat pattern = e.pattern();
  auto matrix = [&](const VecX& q, const VecX& v, double cq, double cv) {
    SpMat K = pattern;
    std::fill_n(K.valuePtr(), K.nonZeros(), 0.0);
    e.viscous_force_in_pattern(q, v, cq, cv, K.valuePtr());
    return MatX(K);
  };
  double worst_q = 0.0, worst_v = 0.0;
  for (int t = 0; t < this->kTrials; ++t) {
    const VecX q = this->deformed(), v = random_vector(this->g, this->size(), 1.0);
    auto in_q = [&](const VecX& y) -> VecX {
      return e.viscous_force_in_pattern(y, v, 0, 0, nullptr);
    };
    auto in_v = [&](const VecX& w) -> VecX {
      return e.viscous_force_in_pattern(q, w, 0, 0, nullptr);
    };
    const MatX Kq = matrix(q, v, 1, 0), Kv = matrix(q, v, 0, 1);
    const double eq = rel_diff(Kq, central_jacobian(in_q, q)),
                 ev = rel_diff(Kv, central_jacobian(in_v, v));
    EXPECT_LT(eq, 1e-6) << "trial " << t;
    EXPECT_LT(ev, 1e-6) << "trial " << t;
    if (linear_viscous<TypeParam>()) {
      EXPECT_LT((Kv * v - in_v(v)).norm(), 1e-12 * std::max(1.0, in_v(v).norm()));
    }
    EXPECT_LT((matrix(q, v, 0.5, 3.0) - 0.5 * Kq - 3.0 * Kv).norm(),
              1e-13 * (Kq.norm() + 3.0 * Kv.norm()));
    worst_q = std::max(worst_q, eq);
    worst_v = std::max(worst_v, ev);
  }
  report(this->kind, "viscous df_v/dq vs central FD (rel)", worst_q);
  report(this->kind, "viscous df_v/dqdot vs central FD (rel)", worst_v);
}

// The viscous power q̇·f_v = η Ėᵀ C Ė ≥ 0; a rigid velocity (Ė = 0) meets no viscous force; for
// any q̇ the force has no resultant on the positions and no moment (the strains are invariant):
// viscosity conserves momenta.
TYPED_TEST(ElementContract, ViscousForceDissipatesAndSparesRigidVelocitiesAndMomenta) {
  const auto& e = this->element;
  if (!e.viscous()) GTEST_SKIP() << "no viscous forces";
  double worst_rigid = 0.0, worst_lin = 0.0, worst_ang = 0.0;
  for (int t = 0; t < this->kTrials; ++t) {
    const VecX q = this->deformed(), v = random_vector(this->g, this->size(), 1.0);
    const VecX f = e.viscous_force_in_pattern(q, v, 0, 0, nullptr);
    EXPECT_GT(v.dot(f), 0.0) << "trial " << t;
    const double scale = std::max(f.norm(), 1e-300);
    worst_lin = std::max(worst_lin, position_sum(f, this->phi).norm() / scale);
    worst_ang = std::max(worst_ang, moment(q, f).norm() / (scale * std::max(q.norm(), 1.0)));
    const VecX rigid = rigid_velocity(q, this->maker.kinds, random_vector(this->g, 3, 1.0),
                                      random_vector(this->g, 3, 1.0));
    worst_rigid =
        std::max(worst_rigid, e.viscous_force_in_pattern(q, rigid, 0, 0, nullptr).norm() / scale);
  }
  EXPECT_LT(worst_lin, 1e-13);
  EXPECT_LT(worst_ang, 1e-13);
  EXPECT_LT(worst_rigid, 1e-13);
  report(this->kind, "viscous: sum of position forces / |f_v|", worst_lin);
  report(this->kind, "viscous: sum q x f_v / (|f_v| |q|)", worst_ang);
  report(this->kind, "viscous: |f_v(rigid velocity)| / |f_v|", worst_rigid);
}

// 9. Numerical dissipation of the energy–momentum step. Only beams and director shells have it
// (StrainDissipationContract below); every other element says so.
TYPED_TEST(ElementContract, StrainDissipationOnlyWhereTheElementHasStrainForms) {
  const bool listed =
      std::is_same_v<TypeParam, BeamMaker> || std::is_same_v<TypeParam, CornerBeamMaker> ||
      std::is_same_v<TypeParam, HelixBeamMaker> || std::is_same_v<TypeParam, DirectorShellMaker>;
  EXPECT_EQ(this->element.strain_dissipation(), listed);
}

// Numerical dissipation of the energy–momentum step (docs/theory/schemes.md §10): the
// algorithmic force f_d(qₙ₋₁, qₙ, qₙ₊₁) = B(q_{n+½})ᵀ χ C (ΔEₙ₊₁ − r ΔEₙ). Its derivative in
// qₙ₊₁ against central differences, added into the element's pattern.
TYPED_TEST(StrainDissipationContract, TangentMatchesFiniteDifference) {
  const auto& e = this->element;
  ASSERT_TRUE(e.strain_dissipation());
  const SpMat pattern = e.pattern();
  double worst = 0.0;
  for (int t = 0; t < this->kTrials; ++t) {
    const VecX qp = this->deformed(), qn = this->deformed(), qn1 = this->deformed();
    auto force = [&](const VecX& y) -> VecX {
      return e.strain_dissipation_force_in_pattern(qp, qn, y, 0.05, 0.7, nullptr);
    };
    SpMat K = pattern;
    std::fill_n(K.valuePtr(), K.nonZeros(), 1.0);  // the kernel adds to what it is given
    const VecX f = e.strain_dissipation_force_in_pattern(qp, qn, qn1, 0.05, 0.7, K.valuePtr());
    std::for_each(K.valuePtr(), K.valuePtr() + K.nonZeros(), [](double& v) { v -= 1.0; });
    EXPECT_GT(f.norm(), 0.0) << "trial " << t;
    const double err = rel_diff(MatX(K), central_jacobian(force, qn1));
    EXPECT_LT(err, 1e-6) << "trial " << t;
    worst = std::max(worst, err);
  }
  report(this->kind, "dissipation df_d/dqn1 vs central FD (rel)", worst);
}

// Momenta: no resultant on the positions and no moment about the origin at the midpoint (the
// force is B(q_{n+½})ᵀ times stresses, as DV); objectivity: configurations that differ by rigid
// motions have the same strains and meet no force; with r = 0 its work Δq·f_d = χ ΔEᵀ C ΔE ≥ 0.
TYPED_TEST(StrainDissipationContract, ConservesMomentaAndDissipates) {
  const auto& e = this->element;
  ASSERT_TRUE(e.strain_dissipation());
  const auto& kinds = this->maker.kinds;
  double worst_lin = 0.0, worst_ang = 0.0, worst_rigid = 0.0;
  for (int t = 0; t < this->kTrials; ++t) {
    const VecX qp = this->deformed(), qn = this->deformed(), qn1 = this->deformed();
    const VecX f = e.strain_dissipation_force_in_pattern(qp, qn, qn1, 0.05, 1.0, nullptr);
    const VecX mid = 0.5 * (qn + qn1);
    const double scale = std::max(f.norm(), 1e-300);
    worst_lin = std::max(worst_lin, position_sum(f, this->phi).norm() / scale);
    worst_ang = std::max(worst_ang, moment(mid, f).norm() / (scale * std::max(mid.norm(), 1.0)));
    const VecX work = e.strain_dissipation_force_in_pattern(qp, qn, qn1, 0.05, 0.0, nullptr);
    EXPECT_GT(work.dot(qn1 - qn), 0.0) << "trial " << t;
    const VecX moved = e.strain_dissipation_force_in_pattern(
        qn, rigid_motion(qn, kinds, random_rotation(this->g), random_vector(this->g, 3, 1.0)),
        rigid_motion(qn, kinds, random_rotation(this->g), random_vector(this->g, 3, 1.0)), 0.05,
        1.0, nullptr);
    worst_rigid = std::max(worst_rigid, moved.norm() / scale);
  }
  EXPECT_LT(worst_lin, 1e-13);
  EXPECT_LT(worst_ang, 1e-13);
  EXPECT_LT(worst_rigid, 1e-12);
  report(this->kind, "dissipation: sum of position forces / |f_d|", worst_lin);
  report(this->kind, "dissipation: sum q_mid x f_d / (|f_d| |q_mid|)", worst_ang);
  report(this->kind, "dissipation: |f_d(rigidly moved)| / |f_d|", worst_rigid);
}
