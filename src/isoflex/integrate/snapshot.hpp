#pragma once
// What an integrator reports after the initial state and after every step: plain values, so that
// writers (io/) and the progress display (app/) need nothing from system/ or integrate/ internals.
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "isoflex/elements/kl_shell_patch.hpp"
#include "isoflex/math/types.hpp"

namespace isoflex::integrate {

struct BodyPose {
  std::string name;
  Vec3 position = Vec3::Zero();          // centre of mass φ
  Mat3 directors = Mat3::Identity();     // columns d₁, d₂, d₃
  Vec3 velocity = Vec3::Zero();          // φ̇
  Vec3 angular_velocity = Vec3::Zero();  // spatial ω
};

struct ProbeValue {
  std::string name;
  Vec3 position = Vec3::Zero();
  Vec3 displacement = Vec3::Zero();  // position − position at t = 0
  Vec3 velocity = Vec3::Zero();
};

// A spring–damper (model springs): the distance ζ of its points, the elongation ζ − L, the rate ζ̇
// and the force N = k (ζ − L) + c ζ̇ along the line (tension > 0).
struct SpringValue {
  std::string name;
  double length = 0.0, elongation = 0.0, rate = 0.0, force = 0.0;
};

// A joint's reaction on its body_b (system/joint_reactions.hpp): force and moment about the
// joint point, global and in body_b's joint frame.
struct ReactionValue {
  std::string joint;
  Vec3 point = Vec3::Zero();
  Vec3 force = Vec3::Zero(), moment = Vec3::Zero();
  Vec3 force_local = Vec3::Zero(), moment_local = Vec3::Zero();
  // A driven revolute (prismatic) joint: the driving torque about (force along) the axis on
  // body_b.
  std::optional<double> driver;
};

// Stress resultants of one beam element (DNSM-III (69)): n = ∂W/∂Γ (shear along d₁, d₂; axial
// force), m = ∂W/∂K (bending about d₁, d₂; torsion), components in the element's directors.
struct BeamElementValue {
  std::string beam;
  int element = 0;             // index along the beam, from 0
  int node_a = 0, node_b = 0;  // indices into Snapshot::bodies (the node poses)
  Vec3 n = Vec3::Zero(), m = Vec3::Zero();
};

// Stress resultants of one director-shell element at its centre (docs/theory/shell.md): membrane
// forces n^{αβ}, bending moments m^{αβ} and shear forces q^α per unit reference length, in the
// element's reference frame (columns e₁, e₂ tangent, e₃ the reference normal).
struct ShellElementValue {
  std::string shell;
  int element = 0;
  std::array<int, 4> nodes{};  // indices into Snapshot::bodies (the node poses)
  Mat3 frame = Mat3::Identity();
  Eigen::Matrix2d n = Eigen::Matrix2d::Zero(), m = Eigen::Matrix2d::Zero();
  Eigen::Vector2d q = Eigen::Vector2d::Zero();
};

// The control points of one Kirchhoff–Love patch (kl_shells entry `shell`), stacked in the
// surface's numbering as elements::KLShellPatch's x, with the system's patch and kinematics: the
// writers evaluate the deformed surface and recover the stresses with them.
struct KLPatchValue {
  std::string shell;
  VecX x;
  std::shared_ptr<const elements::KLShellPatch> patch;
  elements::KLKinematics kinematics = elements::KLKinematics::nonlinear;
};

struct Snapshot {
  int step = 0;  // 0 = initial state
  double t = 0.0;
  double kinetic_energy = 0.0;
  double potential_energy = 0.0;  // conservative potentials only (gravity, elastic)
  double total_energy = 0.0;
  double dissipated_energy = 0.0;  // work of the viscous forces since t = 0 (State::dissipated)
  double external_work = 0.0;  // work of the loads and actuators since t = 0 (State::external_work)
  double driver_work = 0.0;    // work of the prescribed motions since t = 0 (State::driver_work)
  Vec3 linear_momentum = Vec3::Zero();
  Vec3 angular_momentum = Vec3::Zero();  // about the global origin
  double constraint_violation = 0.0;     // max |Φ| over all constraints, internal and joints
  int newton_iterations = 0;             // of this step (0 for the initial state)
  double residual = 0.0;                 // final Newton residual norm of this step
  // Static path following: the arc length from the start or the control displacement
  // (LoadStepStats::path); 0 otherwise.
  double path = 0.0;
  // Every node: the bodies in model order, then the beam nodes, then the shell nodes (position φ,
  // directors (d₁, d₂, d) with d the shell director).
  std::vector<BodyPose> bodies;
  std::vector<ProbeValue> probes;
  std::vector<SpringValue> springs;
  // The joints between frame nodes, when the state has the multipliers (State::lambda: every step
  // of a model with such joints; not the initial state of the energy–momentum schemes).
  std::vector<ReactionValue> reactions;
  std::vector<BeamElementValue> beam_elements;
  std::vector<ShellElementValue> shell_elements;
  std::vector<KLPatchValue> kl_patches;
};

// Observers are called in order after the initial state and after every converged step.
class Observer {
 public:
  virtual ~Observer() = default;
  virtual void on_snapshot(const Snapshot& s) = 0;
  virtual void on_finish() {}
};

}  // namespace isoflex::integrate
