#include "isoflex/integrate/cosimulation.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "isoflex/elements/point_spring_damper.hpp"
#include "isoflex/integrate/energy_momentum.hpp"
#include "isoflex/integrate/newton_loop.hpp"
#include "isoflex/system/compile_error.hpp"

namespace isoflex::integrate {

namespace {

constexpr const char* kHidden = "__cosim_";

// Whether a body reference names a Kirchhoff–Love shell's control point "<shell>[A]".
bool control_point(const model::Model& m, const std::string& ref) {
  const auto open = ref.find('[');
  if (open == std::string::npos) return false;
  const std::string shell = ref.substr(0, open);
  return std::any_of(m.kl_shells.begin(), m.kl_shells.end(),
                     [&](const model::KLShell& s) { return s.name == shell; });
}

// The side of a material point: 1 shell, 0 multibody, −1 the ground.
int side(const model::Model& m, const model::Probe& p) {
  if (!p.kl_shell.empty() || control_point(m, p.body)) return 1;
  return p.body == "ground" ? -1 : 0;
}

model::Probe ground_at(const Vec3& x) {
  model::Probe g;
  g.body = "ground";
  g.point = x;
  return g;
}

int probe_index(const system::System& sys, const std::string& name) {
  const auto& p = sys.probes();
  const auto it = std::find_if(p.begin(), p.end(),
                               [&](const system::ProbeInstance& x) { return x.name == name; });
  return static_cast<int>(it - p.begin());
}

int spring_index(const system::System& sys, const std::string& name) {
  const auto& s = sys.springs();
  const auto it = std::find_if(s.begin(), s.end(),
                               [&](const system::SpringInstance& x) { return x.name == name; });
  return static_cast<int>(it - s.begin());
}

const elements::PointSpringDamper& spring_element(const system::System& sys, int s) {
  return dynamic_cast<const elements::PointSpringDamper&>(*sys.elements()[static_cast<std::size_t>(
      sys.springs()[static_cast<std::size_t>(s)].element_index)]);
}

// Probe `probe` of sys at x (a configuration q or, material points being linear, a velocity v).
Vec3 probe_at(const system::System& sys, const VecX& x, int probe) {
  return sys.probe_point(x, sys.probes()[static_cast<std::size_t>(probe)]);
}

bool hidden(const std::string& name) {
  return name.rfind(kHidden, 0) == 0;
}

}  // namespace

// A spring of the model between a shell point and a multibody point.
struct CoSimulation::Crossing {
  std::string name;
  int mbs_spring = -1, shell_spring = -1;             // in each part's System::springs()
  int mbs_probe = -1, shell_probe = -1;               // its ends, in each part's System::probes()
  bool shell_is_a = false;                            // the shell point is end a
  Vec3 mbs_x0, mbs_v0, shell_x0, shell_x1, shell_v1;  // at t_k, and the shell end at t_k + H
};

CoSimulation::CoSimulation(const model::Model& m)
    : H_(m.solver.cosimulation->macro_step), dt_(m.solver.dt), hold_(m.solver.cosimulation->hold) {
  const model::Source at{m.file, m.solver.cosimulation->line};
  const double ratio = H_ / dt_;
  micro_ = static_cast<int>(std::lround(ratio));
  if (micro_ < 1 || std::abs(ratio - micro_) > 1e-9 * ratio)
    system::compile_fail(at, "solver.cosimulation.macro_step",
                         fmt::format("{:g} is not a whole multiple of solver.dt = {:g}", H_, dt_));
  if (m.solver.initial_equilibrium > 0)
    system::compile_fail(at, "solver.cosimulation",
                         "a co-simulation starts from the model's state (no initial_equilibrium)");
  for (const model::Joint& J : m.kl_surface_joints)
    system::compile_fail(J.source, J.name,
                         "a joint at a shell point couples the shell to the multibody part by "
                         "constraint forces, which the co-simulation does not exchange: couple "
                         "them by springs, or run monolithic (remove solver.cosimulation)");
  for (const model::KLSupport& S : m.kl_supports)
    if (!S.body.empty())
      system::compile_fail(S.source, "kl_supports",
                           fmt::format("the support attaches '{}' to the body '{}': the "
                                       "co-simulation exchanges spring forces only (IGA-thesis "
                                       "(6.8)–(6.9)); run monolithic or couple by springs",
                                       S.shell, S.body));

  // The two parts.
  model::Model mbs = m, shell = m;
  mbs.solver.cosimulation.reset();
  shell.solver.cosimulation.reset();
  mbs.surfaces.clear();
  mbs.kl_shells.clear();
  mbs.kl_supports.clear();
  mbs.kl_loads.clear();
  mbs.kl_interfaces = {};
  mbs.joints.clear();
  mbs.probes.clear();
  mbs.springs.clear();
  shell.bodies.clear();
  shell.beams.clear();
  shell.joints.clear();
  shell.loads.clear();
  shell.distributed_loads.clear();
  shell.shells.clear();
  shell.shell_supports.clear();
  shell.shell_loads.clear();
  shell.probes.clear();
  shell.springs.clear();
  shell.bushings.clear();  // between frames: the multibody part's
  for (const model::Joint& J : m.joints) {
    const bool a = control_point(m, J.body_a), b = control_point(m, J.body_b);
    if (!a && !b) {
      mbs.joints.push_back(J);
    } else if ((a || J.body_a == "ground") && (b || J.body_b == "ground")) {
      shell.joints.push_back(J);
    } else {
      system::compile_fail(J.source, J.name,
                           "the joint ties a control point to the multibody part; the "
                           "co-simulation exchanges spring forces only: run monolithic or couple "
                           "by springs");
    }
  }
  for (const model::Probe& P : m.probes) (side(m, P) == 1 ? shell : mbs).probes.push_back(P);
  // The crossing springs: the exact ends at t = 0 from the monolithic system, then in each part
  // the other end a point of the ground there (moved by the exchange), the free length fixed.
  model::Model whole = m;
  whole.solver.cosimulation.reset();
  std::vector<std::size_t> crossing;
  for (std::size_t k = 0; k < m.springs.size(); ++k) {
    const model::Spring& S = m.springs[k];
    const int sa = side(m, S.a), sb = side(m, S.b);
    if (std::max(sa, sb) == 1 && std::min(sa, sb) == 0) {
      if (!S.actuator.empty())
        system::compile_fail(S.source, fmt::format("springs[{}].actuator", k),
                             "an actuator on a spring between a shell and the multibody part is "
                             "not exchanged by the co-simulation; run monolithic");
      crossing.push_back(k);
      model::Probe a = S.a, b = S.b;
      a.name = fmt::format("{}a{}", kHidden, k);
      b.name = fmt::format("{}b{}", kHidden, k);
      whole.probes.push_back(a);
      whole.probes.push_back(b);
    } else {
      (std::max(sa, sb) == 1 ? shell : mbs).springs.push_back(S);
    }
  }
  if (m.kl_shells.empty() || (m.bodies.empty() && m.beams.empty() && m.shells.empty()))
    system::compile_fail(at, "solver.cosimulation",
                         "the co-simulation needs Kirchhoff–Love shells and a multibody part "
                         "(bodies, beams or director shells)");
  {
    const system::System all = system::System::compile(whole);
    for (std::size_t k : crossing) {
      const model::Spring& S = m.springs[k];
      const bool shell_a = side(m, S.a) == 1;
      const auto point = [&](char end) {
        const auto& p = all.probes()[static_cast<std::size_t>(
            probe_index(all, fmt::format("{}{}{}", kHidden, end, k)))];
        return all.probe_point(all.q0(), p);
      };
      const Vec3 xa = point('a'), xb = point('b');
      model::Spring in_mbs = S, in_shell = S;
      in_mbs.free_length = in_shell.free_length = S.free_length.value_or((xa - xb).norm());
      (shell_a ? in_mbs.a : in_mbs.b) = ground_at(shell_a ? xa : xb);
      (shell_a ? in_shell.b : in_shell.a) = ground_at(shell_a ? xb : xa);
      mbs.springs.push_back(in_mbs);
      shell.springs.push_back(in_shell);
      model::Probe mp = shell_a ? S.b : S.a, sp = shell_a ? S.a : S.b;
      mp.name = sp.name = fmt::format("{}{}", kHidden, k);
      mbs.probes.push_back(mp);
      shell.probes.push_back(sp);
      crossing_.push_back({S.name, -1, -1, -1, -1, shell_a, {}, {}, {}, {}, {}});
    }
  }
  mbs_ = std::make_unique<system::System>(system::System::compile(mbs));
  shell_ = std::make_unique<system::System>(system::System::compile(shell));
  for (std::size_t i = 0; i < crossing_.size(); ++i) {
    Crossing& c = crossing_[i];
    const std::string probe = fmt::format("{}{}", kHidden, crossing[i]);
    c.mbs_spring = spring_index(*mbs_, c.name);
    c.shell_spring = spring_index(*shell_, c.name);
    c.mbs_probe = probe_index(*mbs_, probe);
    c.shell_probe = probe_index(*shell_, probe);
  }
  for (const model::Body& b : m.bodies) mbs_bodies_.push_back(b.name);
  mbs_integ_ = make_time_integrator(*mbs_, mbs.solver);
  shell_integ_ = make_time_integrator(*shell_, shell.solver);
  mbs_integ_->set_joint_reactions(m.output.reactions && !m.joints.empty());
  mbs_state_ = mbs_integ_->initial_state();
  shell_state_ = shell_integ_->initial_state();
}

CoSimulation::~CoSimulation() = default;

int CoSimulation::crossing_springs() const {
  return static_cast<int>(crossing_.size());
}
int CoSimulation::mbs_unknowns() const {
  return mbs_integ_->unknowns();
}
int CoSimulation::shell_unknowns() const {
  return shell_integ_->unknowns();
}

void CoSimulation::anchor_shell_side(double t) {
  for (const Crossing& c : crossing_) {
    const Vec3 y =
        hold_ == model::CoSimulationHold::linear ? Vec3(c.mbs_x0 + (t - t_) * c.mbs_v0) : c.mbs_x0;
    shell_->move_spring_anchor(c.shell_spring, y, c.mbs_v0);
  }
}

void CoSimulation::anchor_mbs_side(double t) {
  const double s = (t - t_) / H_;
  for (const Crossing& c : crossing_) {
    if (hold_ == model::CoSimulationHold::linear)
      mbs_->move_spring_anchor(c.mbs_spring, (1.0 - s) * c.shell_x0 + s * c.shell_x1,
                               (c.shell_x1 - c.shell_x0) / H_);
    else
      mbs_->move_spring_anchor(c.mbs_spring, c.shell_x1, c.shell_v1);
  }
}

StepStats CoSimulation::advance() {
  for (Crossing& c : crossing_) {
    c.mbs_x0 = probe_at(*mbs_, mbs_state_.q, c.mbs_probe);
    c.mbs_v0 = probe_at(*mbs_, mbs_state_.v, c.mbs_probe);
    c.shell_x0 = probe_at(*shell_, shell_state_.q, c.shell_probe);
  }
  StepStats out;
  const auto micro = [&](const char* part, auto&& anchor, TimeIntegrator& integ, State& state) {
    for (int j = 0; j < micro_; ++j) {
      anchor(t_ + (j + 0.5) * dt_);
      try {
        const StepStats st = integ.step(state);
        out.iterations += st.iterations;
        out.failed_starts += st.failed_starts;
        out.residual = std::max(out.residual, st.residual);
      } catch (const NewtonFailure& e) {
        throw NewtonFailure(fmt::format("co-simulation macro step {} (t = {:.6g}), {} part: {}",
                                        k_ + 1, t_ + H_, part, e.what()));
      }
    }
  };
  micro(
      "shell", [&](double t) { anchor_shell_side(t); }, *shell_integ_, shell_state_);
  for (Crossing& c : crossing_) {
    c.shell_x1 = probe_at(*shell_, shell_state_.q, c.shell_probe);
    c.shell_v1 = probe_at(*shell_, shell_state_.v, c.shell_probe);
  }
  micro(
      "multibody", [&](double t) { anchor_mbs_side(t); }, *mbs_integ_, mbs_state_);
  ++k_;
  t_ = k_ * H_;
  return out;
}

Snapshot CoSimulation::snapshot(const StepStats& st) const {
  const Snapshot a = integrate::snapshot(*mbs_, mbs_state_, st, mbs_bodies_);
  const Snapshot b = integrate::snapshot(*shell_, shell_state_, st, {});
  Snapshot out = a;
  out.step = k_;
  out.t = t_;
  out.kinetic_energy += b.kinetic_energy;
  out.potential_energy += b.potential_energy;
  out.dissipated_energy += b.dissipated_energy;
  out.external_work += b.external_work;
  out.driver_work += b.driver_work;
  out.linear_momentum += b.linear_momentum;
  out.angular_momentum += b.angular_momentum;
  out.constraint_violation = std::max(a.constraint_violation, b.constraint_violation);
  out.kl_patches = b.kl_patches;
  out.probes.clear();
  for (const auto* part : {&a, &b})
    for (const ProbeValue& p : part->probes)
      if (!hidden(p.name)) out.probes.push_back(p);
  out.springs.clear();
  for (const auto* part : {&a, &b})
    for (const SpringValue& s : part->springs)
      if (std::none_of(crossing_.begin(), crossing_.end(),
                       [&](const Crossing& c) { return c.name == s.name; }))
        out.springs.push_back(s);
  // The crossing springs between their true ends: their energy replaces what each part counts
  // with its anchor.
  for (const Crossing& c : crossing_) {
    const auto& e_mbs = spring_element(*mbs_, c.mbs_spring);
    const auto& e_shell = spring_element(*shell_, c.shell_spring);
    out.potential_energy -= e_mbs.potential(mbs_->stacked(mbs_state_.q, e_mbs.nodes())) +
                            e_shell.potential(shell_->stacked(shell_state_.q, e_shell.nodes()));
    const Vec3 xm = probe_at(*mbs_, mbs_state_.q, c.mbs_probe),
               vm = probe_at(*mbs_, mbs_state_.v, c.mbs_probe);
    const Vec3 xs = probe_at(*shell_, shell_state_.q, c.shell_probe),
               vs = probe_at(*shell_, shell_state_.v, c.shell_probe);
    const Vec3 d = c.shell_is_a ? Vec3(xs - xm) : Vec3(xm - xs);
    const Vec3 dv = c.shell_is_a ? Vec3(vs - vm) : Vec3(vm - vs);
    const double z = d.norm(), rate = z > 0.0 ? d.dot(dv) / z : 0.0;
    out.potential_energy += e_mbs.energy_at(z);
    out.springs.push_back({c.name, z, z - e_mbs.law().free_length, rate, e_mbs.force_at(z, rate)});
  }
  out.total_energy = out.kinetic_energy + out.potential_energy;
  return out;
}

}  // namespace isoflex::integrate
