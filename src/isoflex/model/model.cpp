#include "isoflex/model/model.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace isoflex::model {

namespace {
struct JointName {
  JointType type;
  const char* name;
  int m;
};
constexpr JointName kJoints[] = {
    {JointType::spherical, "spherical", 3}, {JointType::revolute, "revolute", 5},
    {JointType::prismatic, "prismatic", 5}, {JointType::cylindrical, "cylindrical", 4},
    {JointType::planar, "planar", 3},       {JointType::universal, "universal", 4},
    {JointType::rigid, "rigid", 6},         {JointType::point_on_line, "point_on_line", 2},
    {JointType::fixed, "fixed", 6},
};
}  // namespace

const char* to_string(JointType t) {
  for (const auto& j : kJoints)
    if (j.type == t) return j.name;
  return "?";
}

std::optional<JointType> joint_type_from_string(const std::string& s) {
  for (const auto& j : kJoints)
    if (s == j.name) return j.type;
  return std::nullopt;
}

int joint_constraint_count(JointType t) {
  for (const auto& j : kJoints)
    if (j.type == t) return j.m;
  return 0;
}

const char* to_string(Formulation f) {
  switch (f) {
    case Formulation::constrained:
      return "constrained";
    case Formulation::nullspace:
      return "nullspace";
    case Formulation::reparametrized:
      return "reparametrized";
  }
  return "?";
}

std::optional<Formulation> formulation_from_string(const std::string& s) {
  if (s == "constrained") return Formulation::constrained;
  if (s == "nullspace") return Formulation::nullspace;
  if (s == "reparametrized") return Formulation::reparametrized;
  return std::nullopt;
}

const char* to_string(LinearSolver s) {
  switch (s) {
    case LinearSolver::automatic:
      return "auto";
    case LinearSolver::direct:
      return "direct";
    case LinearSolver::cg_gamg:
      return "cg_gamg";
    case LinearSolver::cg_hypre:
      return "cg_hypre";
    case LinearSolver::mumps:
      return "mumps";
    case LinearSolver::cg_multigrid:
      return "cg_multigrid";
  }
  return "?";
}

std::optional<LinearSolver> linear_solver_from_string(const std::string& s) {
  for (LinearSolver k : {LinearSolver::automatic, LinearSolver::direct, LinearSolver::cg_gamg,
                         LinearSolver::cg_hypre, LinearSolver::mumps, LinearSolver::cg_multigrid})
    if (s == to_string(k)) return k;
  return std::nullopt;
}

const char* to_string(Integrator i) {
  switch (i) {
    case Integrator::energy_momentum:
      return "energy_momentum";
    case Integrator::generalized_alpha:
      return "generalized_alpha";
    case Integrator::bdf1:
      return "bdf1";
    case Integrator::bdf2:
      return "bdf2";
  }
  return "?";
}

std::optional<Integrator> integrator_from_string(const std::string& s) {
  for (const Integrator i : {Integrator::energy_momentum, Integrator::generalized_alpha,
                             Integrator::bdf1, Integrator::bdf2})
    if (s == to_string(i)) return i;
  return std::nullopt;
}

double BeamArc::radius() const {
  const Vec3 r = start - axis_point;
  return (r - r.dot(axis) * axis).norm();
}

double BeamArc::length() const {
  return angle * std::hypot(radius(), pitch / (2.0 * M_PI));
}

Vec3 BeamArc::end() const {
  const Vec3 r = start - axis_point;
  const Vec3 foot = axis_point + r.dot(axis) * axis;
  return foot + Eigen::AngleAxisd(angle, axis) * (start - foot) +
         pitch * angle / (2.0 * M_PI) * axis;
}

Vec3 BeamArc::start_tangent() const {
  const Vec3 r = start - axis_point;
  return (axis.cross(r - r.dot(axis) * axis) + pitch / (2.0 * M_PI) * axis).normalized();
}

double Beam::length() const {
  if (arc) return arc->length();
  double l = 0.0;
  for (std::size_t k = 1; k < points.size(); ++k) l += (points[k] - points[k - 1]).norm();
  return l;
}

bool has_material_damping(const Model& m) {
  if (m.solver.analysis != Analysis::dynamic) return false;
  if (m.solver.numerical_dissipation > 0.0 && (!m.shells.empty() || !m.beams.empty())) return true;
  for (const KLShell& s : m.kl_shells)
    if (s.eta > 0) return true;
  for (const Beam& b : m.beams)
    if (b.section.eta > 0) return true;
  for (const Shell& s : m.shells)
    if (s.material.eta > 0) return true;
  for (const Spring& s : m.springs)
    if (s.damping > 0 || !s.damping_law.empty()) return true;
  for (const Bushing& b : m.bushings)
    if (b.damping.cwiseAbs().maxCoeff() > 0) return true;
  for (const Joint& j : m.joints)
    if (j.spring && j.spring->damping > 0) return true;
  return false;
}

bool has_actuators(const Model& m) {
  if (m.solver.analysis != Analysis::dynamic) return false;
  for (const Spring& s : m.springs)
    if (!s.actuator.empty()) return true;
  return false;
}

const char* to_string(CoSimulationHold h) {
  return h == CoSimulationHold::linear ? "linear" : "constant";
}

bool has_external_loads(const Model& m) {
  return m.solver.analysis == Analysis::dynamic &&
         (has_actuators(m) || !(m.loads.empty() && m.distributed_loads.empty() &&
                                m.shell_loads.empty() && m.kl_loads.empty()));
}

bool has_drivers(const Model& m) {
  if (m.solver.analysis != Analysis::dynamic) return false;
  for (const Joint& j : m.joints)
    if (!j.driver.empty()) return true;
  return false;
}

std::string step_count_problem(const Solver& s) {
  // snprintf, not fmt: the model room depends on math and geometry only.
  char text[256];
  const double steps = std::round(s.t_end / s.dt);
  const char* kind = s.analysis == Analysis::statics ? "load steps" : "time steps";
  if (!(steps <= kMaxSteps)) {
    std::snprintf(text, sizeof text,
                  "t_end / dt = %g / %g = %.3g %s, at most %.0e (history.csv has a row per step)",
                  s.t_end, s.dt, s.t_end / s.dt, kind, kMaxSteps);
    return text;
  }
  if (s.analysis == Analysis::dynamic && !(steps >= 1)) {
    std::snprintf(text, sizeof text,
                  "t_end = %g is shorter than half a time step (dt = %g): the run would take no "
                  "step",
                  s.t_end, s.dt);
    return text;
  }
  // A time integration takes steps of dt and ends at n dt: a t_end between two step times would
  // be cut short (or run over) without a word. Load steps divide t_end evenly whatever dt.
  const double ratio = s.t_end / s.dt;
  if (s.analysis == Analysis::dynamic && std::abs(ratio - steps) > 1e-9 * ratio) {
    const double below = std::floor(ratio) * s.dt, above = std::ceil(ratio) * s.dt;
    std::snprintf(text, sizeof text,
                  "t_end = %.10g is not a whole multiple of dt = %.10g (t_end / dt = %.10g): the "
                  "run takes steps of dt; use t_end = %.10g or %.10g, or a dt that divides t_end",
                  s.t_end, s.dt, ratio, below, above);
    return text;
  }
  return "";
}

std::vector<std::string> gravity_warnings(const Model& m) {
  std::vector<std::string> out;
  if (m.gravity.isZero(0.0)) return out;
  for (std::size_t k = 0; k < m.kl_shells.size(); ++k) {
    const KLShell& s = m.kl_shells[k];
    const bool weighed = std::any_of(m.kl_loads.begin(), m.kl_loads.end(), [&](const KLLoad& l) {
      return l.shell == s.name && l.kind == KLLoadKind::self_weight;
    });
    if (weighed) continue;
    out.push_back("kl_shells[" + std::to_string(k) + "] (" + s.name +
                  "): the model's gravity does not act on a Kirchhoff-Love shell without a "
                  "self_weight load (kl_loads: - {shell: " +
                  s.name + ", self_weight: 1}" +
                  (s.density > 0.0 ? "" : ", which needs the material's density") + ")");
  }
  return out;
}

}  // namespace isoflex::model
