#include "isoflex/io/model_reader.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "isoflex/elements/force_law.hpp"
#include "isoflex/io/kl_shell_reader.hpp"
#include "isoflex/io/shell_reader.hpp"
#include "isoflex/io/surface_reader.hpp"
#include "isoflex/io/yaml_fields.hpp"
#include "isoflex/loads/time_function.hpp"
#include "isoflex/solve/krylov_solver.hpp"

namespace isoflex::io {

namespace {

using model::Body;
using model::Joint;
using model::JointType;
using model::Load;
using model::Model;
using model::Probe;
using model::Shape;
using model::ShapeKind;
using model::Spring;

constexpr double kPerpendicularTolerance = 1e-9;  // |cos| of axis and axis2 (universal)
constexpr double kTriangleTolerance = 1e-12;      // relative slack in the triangle inequalities
constexpr double kParallelTolerance = 1e-6;       // d1 of a beam: |cos| with a segment < 1 − this
constexpr int kMaxBeamElements = 10'000'000;      // per beam; keeps node counts within int

constexpr const char* kBracketMessage =
    "must not contain '[' or ']' (they mark beam nodes, as in crank[3])";

constexpr std::initializer_list<const char*> kJointTypeNames = {
    "spherical", "revolute", "prismatic",     "cylindrical", "planar",
    "universal", "rigid",    "point_on_line", "fixed"};

bool needs_axis(JointType t) {
  switch (t) {
    case JointType::revolute:
    case JointType::prismatic:
    case JointType::cylindrical:
    case JointType::planar:
    case JointType::universal:
    case JointType::point_on_line:
      return true;
    default:
      return false;
  }
}

bool needs_point(JointType t) {
  return t != JointType::rigid && t != JointType::fixed;
}

class Reader : YamlFields {
 public:
  Reader(std::string file, ReadOptions options)
      : YamlFields(std::move(file)), options_(std::move(options)) {}

  Model read(const YAML::Node& root) {
    if (!root.IsMap())
      fail(root, "", "a model file must be a YAML mapping with the keys name, gravity, ...");
    expect_map(root, "");
    check_keys(root, "",
               {"name",
                "gravity",
                "solver",
                "output",
                "bodies",
                "beams",
                "joints",
                "loads",
                "distributed_loads",
                "probes",
                "surfaces",
                "shells",
                "shell_supports",
                "shell_connections",
                "shell_loads",
                "kl_shells",
                "kl_supports",
                "kl_loads",
                "kl_interfaces",
                "springs",
                "bushings"});
    Model m;
    m.file = file();
    if (const auto n = root["name"]) m.name = string(n, "name");
    if (const auto n = root["gravity"]) m.gravity = vec3(n, "gravity");
    if (const auto n = root["solver"]) read_solver(n, m.solver);
    if (const auto n = root["output"]) read_output(n, m.output);

    // Bodies and beams first, wherever they stand in the file, so that joints, loads and probes
    // may name bodies and beam nodes defined further down.
    if (const auto list = optional_list(root, "bodies"))
      for (std::size_t i = 0; i < list.size(); ++i)
        m.bodies.push_back(read_body(list[i], indexed("bodies", i)));
    if (const auto list = optional_list(root, "beams"))
      for (std::size_t i = 0; i < list.size(); ++i)
        m.beams.push_back(read_beam(list[i], indexed("beams", i)));
    m.surfaces = read_surfaces(root["surfaces"], file());  // surface_reader.cpp
    const ShellReader shells(file(), options_.memory_limit,
                             options_.memory_limit_text);  // shell_reader.cpp
    m.shells = shells.shells(root["shells"], m.surfaces);
    for (const auto& s : m.shells) {
      if (body_lines_.contains(s.name) || beams_.contains(s.name))
        fail(root["shells"], "shells", "\"" + s.name + "\" names a body or beam already");
      beams_.emplace(s.name, BeamInfo{s.source.line, s.node_count(), true});
    }
    const KLShellReader kl(file());  // kl_shell_reader.cpp
    m.kl_shells = kl.shells(root["kl_shells"], m.surfaces);
    for (const auto& s : m.kl_shells) {
      if (body_lines_.contains(s.name) || beams_.contains(s.name))
        fail(root["kl_shells"], "kl_shells",
             "\"" + s.name + "\" names a body, beam or shell already");
      // Its control points are nodes "<shell>[A]" (dynamic runs).
      const auto surface =
          std::find_if(m.surfaces.begin(), m.surfaces.end(),
                       [&](const model::Surface& f) { return f.name == s.surface; });
      if (surface != m.surfaces.end())
        beams_.emplace(
            s.name,
            BeamInfo{s.source.line, static_cast<int>(surface->surface.points.size()), true, true});
    }
    if (m.solver.numerical_dissipation > 0.0 && m.shells.empty() && m.beams.empty())
      fail(root["solver"]["numerical_dissipation"], "solver.numerical_dissipation",
           "acts on the strains of beams and director shells, and the model has none");
    if (m.solver.linear_solver == model::LinearSolver::cg_multigrid && m.kl_shells.empty())
      fail(root["solver"]["linear_solver"], "solver.linear_solver",
           "cg_multigrid coarsens the knot vectors of Kirchhoff–Love patches, and the model has "
           "none (cg_gamg is the algebraic multigrid)");
    if (m.bodies.empty() && m.beams.empty() && m.shells.empty() && m.kl_shells.empty()) {
      const YAML::Node bodies = root["bodies"];
      const YAML::Node beams = root["beams"];
      if (!bodies && beams) fail(beams, "beams", "at least one body, beam or shell is required");
      fail(bodies ? bodies : root, "bodies", "at least one body, beam or shell is required");
    }

    if (const auto list = optional_list(root, "joints"))
      for (std::size_t i = 0; i < list.size(); ++i) {
        Joint j = read_joint(list[i], indexed("joints", i), i, m, kl);
        (j.kl_shell.empty() ? m.joints : m.kl_surface_joints).push_back(std::move(j));
      }
    if (const auto list = optional_list(root, "loads"))
      for (std::size_t i = 0; i < list.size(); ++i)
        m.loads.push_back(read_load(list[i], indexed("loads", i), i));
    if (const auto list = optional_list(root, "distributed_loads"))
      for (std::size_t i = 0; i < list.size(); ++i)
        m.distributed_loads.push_back(
            read_distributed_load(list[i], indexed("distributed_loads", i), i));
    if (const auto list = optional_list(root, "probes"))
      for (std::size_t i = 0; i < list.size(); ++i)
        m.probes.push_back(read_probe(list[i], indexed("probes", i), m, kl));
    if (const auto list = optional_list(root, "springs"))
      for (std::size_t i = 0; i < list.size(); ++i)
        m.springs.push_back(read_spring(list[i], indexed("springs", i), i, m, kl));
    if (const auto list = optional_list(root, "bushings"))
      for (std::size_t i = 0; i < list.size(); ++i)
        m.bushings.push_back(read_bushing(list[i], indexed("bushings", i), i));
    check_path_probe(root["solver"], m);
    m.shell_supports = shells.supports(root["shell_supports"], m.shells);
    for (auto& j :
         shells.connections(root["shell_connections"], m.shells, [&](const std::string& name) {
           if (body_lines_.contains(name)) return true;
           const auto open = name.find('[');
           const auto it = beams_.find(name.substr(0, open));
           return open != std::string::npos && it != beams_.end() && !it->second.shell;
         }))
      m.joints.push_back(std::move(j));
    m.shell_loads = shells.loads(root["shell_loads"], m.shells);
    m.kl_supports = kl.supports(root["kl_supports"], m);
    m.kl_loads = kl.loads(root["kl_loads"], m);
    m.kl_interfaces = kl.interfaces(root["kl_interfaces"], m);
    return m;
  }

 private:
  ReadOptions options_;
  // ---- values and blocks (YamlFields: structure, scalars, vectors) --------------------------

  // ---- blocks -----------------------------------------------------------------------------

  void read_solver(const YAML::Node& n, model::Solver& s) const {
    if (n.IsNull()) return;
    expect_map(n, "solver");
    check_keys(n, "solver",
               {"analysis",
                "formulation",
                "integrator",
                "rho_infinity",
                "numerical_dissipation",
                "scaling",
                "dt",
                "t_end",
                "residual_tolerance",
                "increment_tolerance",
                "max_iterations",
                "max_rotation_correction",
                "mixed_tangent",
                "max_subdivisions",
                "linear",
                "initial_equilibrium",
                "path_following",
                "cosimulation",
                "saddle_point_solver",
                "support_rows",
                "linear_solver",
                "multigrid_coarsening"});
    if (const auto v = n["analysis"]) {
      const std::string name = string(v, "solver.analysis");
      if (name != "static" && name != "dynamic")
        fail(v, "solver.analysis", "unknown analysis \"" + name + "\" (valid: static, dynamic)");
      s.analysis = name == "static" ? model::Analysis::statics : model::Analysis::dynamic;
    }
    if (const auto v = n["formulation"]) {
      const std::string name = string(v, "solver.formulation");
      const auto f = model::formulation_from_string(name);
      if (!f)
        fail(
            v, "solver.formulation",
            "unknown formulation \"" + name + "\" (valid: constrained, nullspace, reparametrized)");
      s.formulation = *f;
    }
    if (const auto v = n["integrator"]) {
      const std::string name = string(v, "solver.integrator");
      const auto i = model::integrator_from_string(name);
      if (!i)
        fail(v, "solver.integrator",
             "unknown integrator \"" + name +
                 "\" (valid: energy_momentum, generalized_alpha, bdf1, bdf2)");
      s.integrator = *i;
    }
    if (const auto v = n["rho_infinity"]) {
      s.rho_infinity = number(v, "solver.rho_infinity");
      if (s.rho_infinity < 0.0 || s.rho_infinity > 1.0)
        fail(v, "solver.rho_infinity",
             fmt::format("{} is outside [0, 1] (the spectral radius of generalized-α at infinite "
                         "frequency)",
                         s.rho_infinity));
    }
    if (const auto v = n["numerical_dissipation"]) {
      s.numerical_dissipation = number(v, "solver.numerical_dissipation");
      if (s.numerical_dissipation < 0.0 || s.numerical_dissipation > 0.25)
        fail(v, "solver.numerical_dissipation",
             fmt::format("{} is outside [0, 0.25] (χ of the algorithmic stress on the strains' "
                         "second difference; 0.01–0.1 damps the modes with ωΔt ≈ 1–100)",
                         s.numerical_dissipation));
      if (s.numerical_dissipation > 0.0 && s.integrator != model::Integrator::energy_momentum)
        fail(v, "solver.numerical_dissipation",
             "is for the energy–momentum integrator (generalized-α has rho_infinity; BDF "
             "dissipates by itself)");
    }
    if (const auto v = n["scaling"]) s.scaling = boolean(v, "solver.scaling");
    if (const auto v = n["dt"]) s.dt = positive(v, "solver.dt");
    if (const auto v = n["t_end"]) s.t_end = positive(v, "solver.t_end");
    if (const auto v = n["residual_tolerance"])
      s.residual_tolerance = positive(v, "solver.residual_tolerance");
    if (const auto v = n["increment_tolerance"])
      s.increment_tolerance = positive(v, "solver.increment_tolerance");
    if (const auto v = n["max_iterations"])
      s.max_iterations = integer(v, "solver.max_iterations", 1);
    if (const auto v = n["max_rotation_correction"]) {
      s.max_rotation_correction = number(v, "solver.max_rotation_correction");
      if (!(s.max_rotation_correction >= 0.0))
        fail(v, "solver.max_rotation_correction",
             fmt::format("{} is negative (the largest turn, in rad, of a Newton correction; 0: "
                         "no limit)",
                         s.max_rotation_correction));
    }
    if (const auto v = n["mixed_tangent"]) s.mixed_tangent = boolean(v, "solver.mixed_tangent");
    if (const auto v = n["linear"]) s.linear = boolean(v, "solver.linear");
    if (const auto v = n["max_subdivisions"]) {
      s.max_subdivisions = integer(v, "solver.max_subdivisions", 0);
      if (s.max_subdivisions > 20) fail(v, "solver.max_subdivisions", "at most 20 (Δt/2²⁰)");
    }
    if (const auto v = n["initial_equilibrium"]) {
      s.initial_equilibrium = integer(v, "solver.initial_equilibrium", 0);
      if (s.initial_equilibrium > 0 && s.analysis == model::Analysis::statics)
        fail(v, "solver.initial_equilibrium",
             "the start from a static equilibrium is for a dynamic analysis (a static analysis "
             "finds the equilibrium itself)");
      if (s.initial_equilibrium > 10000)
        fail(v, "solver.initial_equilibrium", "at most 10000 load steps");
    }
    if (const auto v = n["saddle_point_solver"]) {
      const std::string name = string(v, "solver.saddle_point_solver");
      if (name == "lu")
        s.saddle_point_solver = model::SaddlePointSolver::lu;
      else if (name == "augmented_lagrangian")
        s.saddle_point_solver = model::SaddlePointSolver::augmented_lagrangian;
      else if (name != "auto")
        fail(v, "solver.saddle_point_solver",
             "unknown solver \"" + name + "\" (valid: auto, lu, augmented_lagrangian)");
    }
    if (const auto v = n["linear_solver"]) read_linear_solver(v, s);
    if (const auto v = n["support_rows"]) {
      const std::string name = string(v, "solver.support_rows");
      if (name == "multipliers")
        s.support_rows_as_multipliers = true;
      else if (name != "auto")
        fail(v, "solver.support_rows",
             "unknown choice \"" + name + "\" (valid: auto, multipliers)");
    }
    if (const auto v = n["multigrid_coarsening"]) {
      const std::string name = string(v, "solver.multigrid_coarsening");
      if (name == "degree")
        s.multigrid_coarsening = model::MultigridCoarsening::degree;
      else if (name != "knots")
        fail(v, "solver.multigrid_coarsening",
             "unknown coarsening \"" + name + "\" (valid: knots, degree)");
    }
    if (const auto v = n["path_following"]) read_path_following(v, s);
    if (const auto v = n["cosimulation"]) read_cosimulation(v, s);
    // The step count of the file's own dt and t_end (command-line overrides: app load()).
    if (const std::string problem = model::step_count_problem(s); !problem.empty()) {
      if (const auto v = n["t_end"]) fail(v, "solver.t_end", problem);
      fail(n["dt"], "solver.dt", problem);  // the default t_end: dt is the one given
    }
  }

  void read_linear_solver(const YAML::Node& v, model::Solver& s) const {
    const std::string name = string(v, "solver.linear_solver");
    const auto kind = model::linear_solver_from_string(name);
    if (!kind)
      fail(v, "solver.linear_solver",
           "unknown solver \"" + name +
               "\" (valid: auto, direct, cg_gamg, cg_hypre, mumps, cg_multigrid)");
    s.linear_solver = *kind;
    std::string why;
    if (name != "auto" && name != "direct" && !solve::krylov_available(&why))
      fail(v, "solver.linear_solver", name + " is a PETSc solver: " + why);
  }

  void read_cosimulation(const YAML::Node& n, model::Solver& s) const {
    const std::string p = "solver.cosimulation";
    expect_map(n, p);
    check_keys(n, p, {"macro_step", "hold"});
    model::CoSimulation c;
    c.line = line_of(n);
    const YAML::Node H = require(n, p, "macro_step");
    c.macro_step = positive(H, join(p, "macro_step"));
    const double ratio = c.macro_step / s.dt;
    if (ratio < 1.0 - 1e-9 || std::abs(ratio - std::round(ratio)) > 1e-9 * ratio)
      fail(H, join(p, "macro_step"),
           fmt::format("{:g} is not a whole multiple of solver.dt = {:g} (the integrators take "
                       "steps of dt between the exchanges)",
                       c.macro_step, s.dt));
    if (const auto v = n["hold"]) {
      const std::string name = string(v, join(p, "hold"));
      if (name == "constant")
        c.hold = model::CoSimulationHold::constant;
      else if (name != "linear")
        fail(v, join(p, "hold"), "unknown hold \"" + name + "\" (valid: constant, linear)");
    }
    if (s.analysis != model::Analysis::dynamic)
      fail(n, p, "co-simulation is for a dynamic analysis");
    s.cosimulation = c;
  }

  void read_path_following(const YAML::Node& n, model::Solver& s) const {
    const std::string p = "solver.path_following";
    expect_map(n, p);
    check_keys(n, p,
               {"method", "arc_length", "max_arc_length", "load_weight", "target_iterations",
                "max_steps", "probe", "direction", "displacement"});
    model::PathFollowing& f = s.path;
    const YAML::Node method = require(n, p, "method");
    const std::string name = string(method, join(p, "method"));
    if (name == "arc_length")
      f.method = model::PathMethod::arc_length;
    else if (name == "displacement")
      f.method = model::PathMethod::displacement;
    else
      fail(method, join(p, "method"),
           "unknown method \"" + name + "\" (valid: arc_length, displacement)");
    f.line = line_of(n);
    if (s.linear)
      fail(method, join(p, "method"),
           "path following needs a nonlinear analysis (remove solver.linear)");
    const bool arc = f.method == model::PathMethod::arc_length;
    const auto only = [&](const char* key, bool allowed) {
      if (n[key] && !allowed)
        fail(n[key], join(p, key),
             fmt::format("not used with method {}", arc ? "arc_length" : "displacement"));
    };
    for (const char* key :
         {"arc_length", "max_arc_length", "load_weight", "target_iterations", "max_steps"})
      only(key, arc);
    for (const char* key : {"probe", "direction", "displacement"}) only(key, !arc);
    if (const auto v = n["arc_length"]) f.arc_length = positive(v, join(p, "arc_length"));
    if (const auto v = n["max_arc_length"])
      f.max_arc_length = positive(v, join(p, "max_arc_length"));
    if (const auto v = n["load_weight"]) {
      f.load_weight = number(v, join(p, "load_weight"));
      if (!(f.load_weight >= 0.0)) fail(v, join(p, "load_weight"), "must be >= 0");
    }
    if (const auto v = n["target_iterations"])
      f.target_iterations = integer(v, join(p, "target_iterations"), 1);
    if (const auto v = n["max_steps"]) {
      f.max_steps = integer(v, join(p, "max_steps"), 1);
      if (f.max_steps > model::kMaxSteps) fail(v, join(p, "max_steps"), "at most 1e8 steps");
    }
    if (arc) return;
    f.probe = string(require(n, p, "probe"), join(p, "probe"));
    f.displacement = number(require(n, p, "displacement"), join(p, "displacement"));
    if (const auto v = n["direction"]) {
      const Vec3 d = vec3(v, join(p, "direction"));
      if (!(d.norm() > 0.0)) fail(v, join(p, "direction"), "must not be zero");
      f.direction = d.normalized();
    }
  }

  // The probe of displacement control is one of the model's probes.
  void check_path_probe(const YAML::Node& solver, const Model& m) const {
    if (m.solver.path.method != model::PathMethod::displacement) return;
    if (std::none_of(m.probes.begin(), m.probes.end(),
                     [&](const model::Probe& p) { return p.name == m.solver.path.probe; }))
      fail(solver["path_following"]["probe"], "solver.path_following.probe",
           "no probe named \"" + m.solver.path.probe + "\" (give it under probes)");
  }

  void read_output(const YAML::Node& n, model::Output& o) const {
    if (n.IsNull()) return;
    expect_map(n, "output");
    check_keys(n, "output",
               {"vtk_every", "vtk_format", "history", "reactions", "hdf5", "hdf5_state_every"});
    if (const auto v = n["vtk_every"]) o.vtk_every = integer(v, "output.vtk_every", 0);
    if (const auto v = n["vtk_format"]) {
      const std::string name = string(v, "output.vtk_format");
      if (name == "ascii")
        o.vtk_format = model::VtkFormat::ascii;
      else if (name != "binary")
        fail(v, "output.vtk_format", "unknown format \"" + name + "\" (valid: binary, ascii)");
    }
    if (const auto v = n["history"]) o.history = boolean(v, "output.history");
    if (const auto v = n["reactions"]) o.reactions = boolean(v, "output.reactions");
    if (const auto v = n["hdf5"]) o.hdf5 = boolean(v, "output.hdf5");
    if (const auto v = n["hdf5_state_every"])
      o.hdf5_state_every = integer(v, "output.hdf5_state_every", 1);
  }

  Body read_body(const YAML::Node& n, const std::string& p) {
    expect_map(n, p);
    check_keys(n, p,
               {"name", "mass", "inertia", "position", "orientation", "velocity",
                "angular_velocity", "shape"});
    Body b;
    b.source = source(n);

    const YAML::Node name = require(n, p, "name");
    b.name = string(name, join(p, "name"));
    if (b.name.empty()) fail(name, join(p, "name"), "must not be empty");
    if (b.name == "ground")
      fail(name, join(p, "name"), "\"ground\" is reserved for the fixed space");
    if (b.name.find_first_of("[]") != std::string::npos)
      fail(name, join(p, "name"), kBracketMessage);
    if (const auto [pos, inserted] = body_lines_.emplace(b.name, line_of(name)); !inserted)
      fail(name, join(p, "name"),
           fmt::format("duplicate body name \"{}\" (first at line {})", b.name, pos->second));
    body_names_.emplace(b.name, std::make_pair(name, join(p, "name")));

    b.mass = positive(require(n, p, "mass"), join(p, "mass"));

    const YAML::Node inertia = require(n, p, "inertia");
    b.inertia = positive_vec3(inertia, join(p, "inertia"));
    for (int i = 0; i < 3; ++i) {
      const int j = (i + 1) % 3, k = (i + 2) % 3;
      const double sum = b.inertia(j) + b.inertia(k);
      if (b.inertia(i) > sum * (1.0 + kTriangleTolerance))
        fail(inertia, join(p, "inertia"),
             fmt::format("principal moments violate the triangle inequality J{} <= J{} + J{} "
                         "({} > {})",
                         i + 1, j + 1, k + 1, b.inertia(i), sum));
    }

    b.position = vec3(require(n, p, "position"), join(p, "position"));
    if (const auto v = n["orientation"])
      b.orientation = triad(v, join(p, "orientation"), "principal axes [d1, d2, d3]");
    if (const auto v = n["velocity"]) b.velocity = vec3(v, join(p, "velocity"));
    if (const auto v = n["angular_velocity"])
      b.angular_velocity = vec3(v, join(p, "angular_velocity"));
    if (const auto v = n["shape"]) b.shape = read_shape(v, join(p, "shape"));
    return b;
  }

  Shape read_shape(const YAML::Node& n, const std::string& p) const {
    expect_map(n, p);
    Shape s;
    const YAML::Node type = require(n, p, "type");
    const std::string name = string(type, join(p, "type"));
    if (name == "box") {
      s.kind = ShapeKind::box;
      check_keys(n, p, {"type", "size", "offset"});
      s.size = positive_vec3(require(n, p, "size"), join(p, "size"));
    } else if (name == "sphere") {
      s.kind = ShapeKind::sphere;
      check_keys(n, p, {"type", "radius", "offset"});
      s.radius = positive(require(n, p, "radius"), join(p, "radius"));
    } else if (name == "cylinder") {
      s.kind = ShapeKind::cylinder;
      check_keys(n, p, {"type", "radius", "height", "offset"});
      s.radius = positive(require(n, p, "radius"), join(p, "radius"));
      s.height = positive(require(n, p, "height"), join(p, "height"));
    } else if (name == "pyramid") {
      s.kind = ShapeKind::pyramid;
      check_keys(n, p, {"type", "base", "height", "offset"});
      s.base = positive(require(n, p, "base"), join(p, "base"));
      s.height = positive(require(n, p, "height"), join(p, "height"));
    } else {
      fail(type, join(p, "type"),
           "unknown shape type \"" + name + "\" (valid: box, sphere, cylinder, pyramid)");
    }
    if (const auto v = n["offset"]) s.offset = vec3(v, join(p, "offset"));
    return s;
  }

  // A reference to a body or a beam node by name; `allow_ground` admits "ground". A beam node
  // "<beam>[<i>]" is returned in the canonical form (decimal index without leading zeros).
  std::string body_ref(const YAML::Node& n, const std::string& key, bool allow_ground) const {
    const std::string name = string(n, key);
    if (name == "ground") {
      if (!allow_ground) fail(n, key, "must name a body, not the fixed space \"ground\"");
      return name;
    }
    if (body_lines_.contains(name)) return name;
    if (name.find_first_of("[]") != std::string::npos) return beam_node_ref(n, key, name);
    if (const auto it = beams_.find(name); it != beams_.end())
      fail(n, key,
           fmt::format("\"{0}\" is a {2}, not a body: name one of its nodes, {0}[i] with i = 0 "
                       "… {1}",
                       name, it->second.node_count - 1, it->second.shell ? "shell" : "beam"));
    fail(n, key, "no body named \"" + name + "\"");
  }

  // "<beam>[<i>]" with a defined beam and 0 <= i < its node count.
  std::string beam_node_ref(const YAML::Node& n, const std::string& key,
                            const std::string& ref) const {
    const auto open = ref.find('[');
    const bool well_formed =
        open != std::string::npos && open > 0 && ref.find_first_of("[]") == open &&
        ref.size() >= open + 3 && ref.back() == ']' &&
        ref.find_first_of("[]", open + 1) == ref.size() - 1 &&
        std::all_of(ref.begin() + static_cast<std::ptrdiff_t>(open) + 1, ref.end() - 1,
                    [](char c) { return c >= '0' && c <= '9'; });
    if (!well_formed)
      fail(n, key,
           fmt::format("malformed beam node reference \"{}\" (expected BEAM[INDEX], e.g. "
                       "crank[0], with a decimal index counted from 0)",
                       ref));
    const std::string beam = ref.substr(0, open);
    const std::string digits = ref.substr(open + 1, ref.size() - open - 2);
    const auto it = beams_.find(beam);
    if (it == beams_.end()) fail(n, key, "no beam or shell named \"" + beam + "\"");
    const int count = it->second.node_count;
    long long index = 0;
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), index);
    if (ec != std::errc() || end != digits.data() + digits.size() || index >= count) {
      const auto first = digits.find_first_not_of('0');
      fail(n, key,
           fmt::format("node index {} out of range: beam \"{}\" has {} nodes (0 … {})",
                       first == std::string::npos ? "0" : digits.substr(first), beam, count,
                       count - 1));
    }
    return fmt::format("{}[{}]", beam, index);
  }

  // A polyline: `points`, `elements` per segment, `d1` not parallel to any segment.
  void read_beam_polyline(const YAML::Node& n, const std::string& p, model::Beam& b) const {
    const YAML::Node points = n["points"];
    const std::string points_key = join(p, "points");
    if (!points)
      fail(n, points_key, "missing required key (the polyline; or arc for a curved beam)");
    if (!points.IsSequence() || points.size() < 2)
      fail(points, points_key, "expected a list of at least 2 points [[x, y, z], [x, y, z], ...]");
    for (std::size_t k = 0; k < points.size(); ++k) {
      b.points.push_back(vec3(points[k], indexed(points_key, k)));
      if (k > 0 && b.points[k] == b.points[k - 1])
        fail(points[k], indexed(points_key, k),
             fmt::format("coincides with {} (consecutive points must be distinct)",
                         indexed("points", k - 1)));
    }
    const std::size_t segments = points.size() - 1;

    const YAML::Node elements = require(n, p, "elements");
    const std::string elements_key = join(p, "elements");
    if (elements.IsSequence()) {
      if (elements.size() != segments)
        fail(elements, elements_key,
             fmt::format("expected one number of elements per segment ({} {}), got {}", segments,
                         segments == 1 ? "segment" : "segments", elements.size()));
      for (std::size_t k = 0; k < segments; ++k)
        b.elements.push_back(integer(elements[k], indexed(elements_key, k), 1));
    } else if (elements.IsScalar()) {
      b.elements.assign(segments, integer(elements, elements_key, 1));
    } else {
      fail(elements, elements_key,
           "expected an integer (elements in every segment) or a list of one integer per segment");
    }

    long long total = 0;
    for (const int e : b.elements) total += e;
    if (total > kMaxBeamElements)
      fail(elements, elements_key,
           fmt::format("too many elements ({} in all, at most {})", total, kMaxBeamElements));

    const YAML::Node d1 = require(n, p, "d1");
    b.d1 = direction(d1, join(p, "d1"));
    for (std::size_t k = 0; k < segments; ++k) {
      const Vec3 axis = (b.points[k + 1] - b.points[k]).normalized();
      const double c = std::abs(b.d1.dot(axis));
      if (!(c < 1.0 - kParallelTolerance))
        fail(
            d1, join(p, "d1"),
            fmt::format("must not be parallel to segment {} (points[{}] to points[{}]): |cos| = {}",
                        k, k, k + 1, c));
    }
  }

  // An arc or a helix (model::BeamArc): one `elements` count, `d1` (default: the axis) not
  // parallel to the tangent at the start.
  void read_beam_arc(const YAML::Node& n, const std::string& p, model::Beam& b) const {
    const YAML::Node a = n["arc"];
    const std::string ap = join(p, "arc");
    expect_map(a, ap);
    check_keys(a, ap, {"axis_point", "axis", "start", "angle", "pitch"});
    model::BeamArc arc;
    arc.axis_point = vec3(require(a, ap, "axis_point"), join(ap, "axis_point"));
    arc.axis = direction(require(a, ap, "axis"), join(ap, "axis"));
    const YAML::Node start = require(a, ap, "start");
    arc.start = vec3(start, join(ap, "start"));
    const YAML::Node angle = require(a, ap, "angle");
    arc.angle = positive(angle, join(ap, "angle")) * M_PI / 180.0;
    if (const auto v = a["pitch"]) arc.pitch = number(v, join(ap, "pitch"));
    const double r = arc.radius(), scale = (arc.start - arc.axis_point).norm();
    if (!(r > 1e-9 * std::max(scale, 1.0)))
      fail(start, join(ap, "start"), "lies on the axis: the radius of the arc is zero");
    if (arc.pitch == 0.0 && arc.angle > 2.0 * M_PI * (1.0 + 1e-12))
      fail(angle, join(ap, "angle"),
           "an arc without pitch turns at most 360 degrees (give pitch for a helix)");

    const YAML::Node elements = require(n, p, "elements");
    const std::string elements_key = join(p, "elements");
    if (!elements.IsScalar())
      fail(elements, elements_key, "expected one integer (the elements along the arc)");
    const int e = integer(elements, elements_key, 1);
    if (e > kMaxBeamElements)
      fail(elements, elements_key,
           fmt::format("too many elements ({}, at most {})", e, kMaxBeamElements));
    b.elements = {e};

    const Vec3 tangent = arc.start_tangent();
    if (const YAML::Node d1 = n["d1"]) {
      b.d1 = direction(d1, join(p, "d1"));
      const double c = std::abs(b.d1.dot(tangent));
      if (!(c < 1.0 - kParallelTolerance))
        fail(d1, join(p, "d1"),
             fmt::format("must not be parallel to the arc's tangent at its start: |cos| = {}", c));
    } else {
      b.d1 = arc.axis;
    }
    b.arc = arc;
  }

  model::Beam read_beam(const YAML::Node& n, const std::string& p) {
    expect_map(n, p);
    check_keys(n, p,
               {"name", "points", "arc", "elements", "d1", "section", "draw", "velocity",
                "angular_velocity", "velocity_point", "node_velocities"});
    model::Beam b;
    b.source = source(n);

    const YAML::Node name = require(n, p, "name");
    const std::string name_key = join(p, "name");
    b.name = string(name, name_key);
    if (b.name.empty()) fail(name, name_key, "must not be empty");
    if (b.name == "ground") fail(name, name_key, "\"ground\" is reserved for the fixed space");
    if (b.name.find_first_of("[]") != std::string::npos) fail(name, name_key, kBracketMessage);
    if (const auto it = beams_.find(b.name); it != beams_.end())
      fail(name, name_key,
           fmt::format("duplicate beam name \"{}\" (first at line {})", b.name, it->second.line));
    if (const auto it = body_names_.find(b.name); it != body_names_.end()) {
      // Reported at whichever of the two comes later in the file.
      const auto& [body_name, body_key] = it->second;
      if (line_of(body_name) > line_of(name))
        fail(body_name, body_key,
             fmt::format("duplicate name \"{}\": already the name of the beam at line {}", b.name,
                         line_of(name)));
      fail(name, name_key,
           fmt::format("duplicate name \"{}\": already the name of the body at line {}", b.name,
                       line_of(body_name)));
    }

    const YAML::Node points = n["points"], arc = n["arc"];
    if (points && arc)
      fail(arc, join(p, "arc"), "give either points (a polyline) or arc, not both");
    if (arc)
      read_beam_arc(n, p, b);
    else
      read_beam_polyline(n, p, b);
    b.initial = node_velocities(n, p, b.node_count(), fmt::format("beam \"{}\"", b.name));
    b.section = read_section(require(n, p, "section"), join(p, "section"));
    if (const auto v = n["draw"]) {
      const std::string dp = join(p, "draw");
      expect_map(v, dp);
      check_keys(v, dp, {"width", "height"});
      b.draw_width = positive(require(v, dp, "width"), join(dp, "width"));
      b.draw_height = positive(require(v, dp, "height"), join(dp, "height"));
    }
    beams_.emplace(b.name, BeamInfo{line_of(name), b.node_count()});
    return b;
  }

  model::BeamSection read_section(const YAML::Node& n, const std::string& p) const {
    expect_map(n, p);
    check_keys(n, p,
               {"EA", "GA", "GA1", "GA2", "EI", "EI1", "EI2", "GJ", "A_rho", "M_rho", "M_rho1",
                "M_rho2", "eta"});
    model::BeamSection s;
    s.EA = positive(require(n, p, "EA"), join(p, "EA"));
    s.GJ = positive(require(n, p, "GJ"), join(p, "GJ"));
    s.A_rho = positive(require(n, p, "A_rho"), join(p, "A_rho"));
    // `both` sets the two values at once; otherwise both long forms are required.
    auto either = [&](const char* both, const char* first, const char* second, double& v1,
                      double& v2) {
      if (const auto v = n[both]) {
        for (const char* k : {first, second})
          if (n[k]) fail(n[k], join(p, k), fmt::format("give either {} or {}, not both", both, k));
        v1 = v2 = positive(v, join(p, both));
        return;
      }
      if (!n[first] && !n[second])
        fail(n, join(p, both),
             fmt::format("missing required key (or give both {} and {})", first, second));
      for (const char* k : {first, second})
        if (!n[k])
          fail(n, join(p, k),
               fmt::format("missing required key (give both {} and {}, or {} alone)", first, second,
                           both));
      v1 = positive(n[first], join(p, first));
      v2 = positive(n[second], join(p, second));
    };
    either("GA", "GA1", "GA2", s.GA1, s.GA2);
    either("EI", "EI1", "EI2", s.EI1, s.EI2);
    either("M_rho", "M_rho1", "M_rho2", s.M_rho1, s.M_rho2);
    if (const auto v = n["eta"]) s.eta = damping_factor(v, join(p, "eta"));
    return s;
  }

  model::DistributedLoad read_distributed_load(const YAML::Node& n, const std::string& p,
                                               std::size_t index) const {
    expect_map(n, p);
    check_keys(n, p, {"name", "beam", "force_per_length"});
    model::DistributedLoad l;
    l.source = source(n);
    if (const auto v = n["name"]) {
      l.name = string(v, join(p, "name"));
    } else {
      l.name = "distributed_load" + std::to_string(index);
    }
    const YAML::Node beam = require(n, p, "beam");
    l.beam = string(beam, join(p, "beam"));
    if (!beams_.contains(l.beam) || beams_.at(l.beam).shell) {
      if (beams_.contains(l.beam))
        fail(beam, join(p, "beam"), "\"" + l.beam + "\" is a shell: load it with shell_loads");
      if (body_lines_.contains(l.beam))
        fail(beam, join(p, "beam"),
             "\"" + l.beam + "\" is a body: distributed loads act on beams only");
      if (const auto open = l.beam.find('[');
          open != std::string::npos && beams_.contains(l.beam.substr(0, open)))
        fail(beam, join(p, "beam"),
             fmt::format("must name a whole beam (\"{}\"), not one of its nodes",
                         l.beam.substr(0, open)));
      fail(beam, join(p, "beam"), "no beam named \"" + l.beam + "\"");
    }
    l.force_per_length =
        time_functions(require(n, p, "force_per_length"), join(p, "force_per_length"));
    return l;
  }

  Joint read_joint(const YAML::Node& n, const std::string& p, std::size_t index,
                   const model::Model& m, const KLShellReader& kl) {
    expect_map(n, p);
    check_keys(n, p,
               {"name", "type", "body_a", "body_b", "point", "point_a", "point_b", "axis", "axis_a",
                "axis2", "axis2_b", "spring", "driver"});
    Joint j;
    j.source = source(n);

    const YAML::Node name = n["name"];
    j.name = name ? string(name, join(p, "name")) : "joint" + std::to_string(index);
    if (j.name.empty()) fail(name, join(p, "name"), "must not be empty");
    if (const auto [pos, inserted] = joint_lines_.emplace(j.name, line_of(name ? name : n));
        !inserted)
      fail(name ? name : n, join(p, "name"),
           fmt::format("duplicate joint name \"{}\" (first at line {})", j.name, pos->second));

    const YAML::Node type = require(n, p, "type");
    const std::string type_name = string(type, join(p, "type"));
    const auto t = model::joint_type_from_string(type_name);
    if (!t)
      fail(type, join(p, "type"),
           "unknown joint type \"" + type_name + "\" (valid: " + list_names(kJointTypeNames) + ")");
    j.type = *t;

    const YAML::Node body_b = require(n, p, "body_b");
    if (kl_shell_ref(body_b) || kl_shell_ref(n["body_a"])) {
      if (n["spring"])
        fail(n["spring"], join(p, "spring"),
             "a spring is built for revolute and prismatic joints between bodies and beam nodes");
      if (n["driver"])
        fail(n["driver"], join(p, "driver"),
             "a driver is built for joints between bodies and beam nodes (or the ground), not at "
             "a point of a Kirchhoff–Love shell");
      read_kl_surface_joint(n, p, j, m, kl);
      return j;
    }
    if (const auto v = n["body_a"]) j.body_a = body_ref(v, join(p, "body_a"), true);
    j.body_b = body_ref(body_b, join(p, "body_b"), false);
    if (j.body_a == j.body_b)
      fail(body_b, join(p, "body_b"),
           fmt::format("body_a and body_b are the same {} \"{}\"",
                       j.body_b.ends_with(']') ? "beam node" : "body", j.body_b));

    // At most one of each group of alternatives.
    auto one_of = [&](std::initializer_list<const char*> keys) {
      const char* first = nullptr;
      for (const char* k : keys)
        if (n[k]) {
          if (first)
            fail(n[k], join(p, k), fmt::format("give either {} or {}, not both", first, k));
          first = k;
        }
      return first;
    };
    const char* point_key = one_of({"point", "point_a", "point_b"});
    if (const auto v = n["point"]) j.point = vec3(v, join(p, "point"));
    if (const auto v = n["point_a"]) j.point_a = vec3(v, join(p, "point_a"));
    if (const auto v = n["point_b"]) j.point_b = vec3(v, join(p, "point_b"));
    // A control point of a Kirchhoff–Love shell is itself the joint point.
    const bool control_point = kl_node(j.body_a) || kl_node(j.body_b);
    if (needs_point(j.type) && !point_key && !control_point)
      fail(n, join(p, "point"),
           fmt::format("missing required key for a {} joint (or give point_a or point_b)",
                       type_name));

    const char* axis_key = one_of({"axis", "axis_a"});
    if (needs_axis(j.type)) {
      if (!axis_key)
        fail(n, join(p, "axis"),
             fmt::format("missing required key for a {} joint (or give axis_a)", type_name));
      if (const auto v = n["axis"]) j.axis = direction(v, join(p, "axis"));
      if (const auto v = n["axis_a"]) j.axis_a = direction(v, join(p, "axis_a"));
    } else if (axis_key) {
      fail(n[axis_key], join(p, axis_key), fmt::format("not allowed for a {} joint", type_name));
    }

    const char* axis2_key = one_of({"axis2", "axis2_b"});
    if (j.type == JointType::universal) {
      if (!axis2_key)
        fail(n, join(p, "axis2"), "missing required key for a universal joint (or give axis2_b)");
      if (const auto v = n["axis2"]) j.axis2 = direction(v, join(p, "axis2"));
      if (const auto v = n["axis2_b"]) j.axis2_b = direction(v, join(p, "axis2_b"));
      // Axes in body coordinates are checked when the model is compiled (system).
      if (j.axis && j.axis2) {
        const double c = j.axis->dot(*j.axis2);
        if (!(std::abs(c) < kPerpendicularTolerance))
          fail(n["axis2"], join(p, "axis2"),
               fmt::format("must be perpendicular to axis (cosine of the angle {})", c));
      }
    } else if (axis2_key) {
      fail(n[axis2_key], join(p, axis2_key),
           fmt::format("not allowed for a {} joint (only universal)", type_name));
    }
    if (const auto v = n["spring"]) j.spring = read_joint_spring(v, join(p, "spring"), j.type);
    if (const auto v = n["driver"]) {
      if (control_point)
        fail(v, join(p, "driver"),
             "a driver is built for joints between bodies and beam nodes (or the ground), not "
             "for a control point of a Kirchhoff–Love shell");
      j.driver = read_joint_driver(v, join(p, "driver"), j);
    }
    return j;
  }

  // A prescribed motion of a joint (system/joint_drivers.hpp): revolute: the angle θ(t) (rad),
  // prismatic: the slide s(t), one time function each; spherical to the ground: the ground
  // point's position, three. Whether θ(0), s(0) or the position at t = 0 fit the configuration
  // is checked when the model is compiled (system).
  std::vector<std::string> read_joint_driver(const YAML::Node& n, const std::string& p,
                                             const Joint& j) const {
    switch (j.type) {
      case JointType::revolute:
      case JointType::prismatic: {
        const bool revolute = j.type == JointType::revolute;
        if (!n.IsScalar())
          fail(n, p,
               fmt::format("expected one number or expression in t: the {} of the {} joint",
                           revolute ? "angle θ(t) (rad)" : "slide s(t)", to_string(j.type)));
        return {time_function(n, p)};
      }
      case JointType::spherical: {
        if (j.body_a != "ground")
          fail(n, p,
               fmt::format("a spherical joint's driver moves its point on the ground: body_a must "
                           "be ground, not \"{}\"",
                           j.body_a));
        const auto f = time_functions(n, p);
        return {f.begin(), f.end()};
      }
      default:
        fail(n, p,
             fmt::format("a driver is built for revolute joints (the angle), prismatic joints "
                         "(the slide) and spherical joints to the ground (the point's position), "
                         "not {}",
                         to_string(j.type)));
    }
  }

  // A spring–damper in a revolute joint (free_angle, rad) or a prismatic one (free_length).
  model::JointSpring read_joint_spring(const YAML::Node& n, const std::string& p,
                                       JointType type) const {
    if (type != JointType::revolute && type != JointType::prismatic)
      fail(n, p,
           fmt::format("a spring is built for revolute and prismatic joints only, not {}",
                       model::to_string(type)));
    expect_map(n, p);
    const bool revolute = type == JointType::revolute;
    const char* free = revolute ? "free_angle" : "free_length";
    check_keys(n, p, {"stiffness", "damping", free});
    model::JointSpring s;
    for (const auto& [key, out] :
         {std::pair<const char*, double*>{"stiffness", &s.stiffness}, {"damping", &s.damping}})
      if (const YAML::Node v = n[key]) {
        *out = number(v, join(p, key));
        if (!(*out >= 0.0)) fail(v, join(p, key), "must be ≥ 0");
      }
    if (!n["stiffness"] && !n["damping"]) fail(n, p, "give stiffness, damping or both");
    if (const YAML::Node v = n[free]) s.free_value = number(v, join(p, free));
    return s;
  }

  // A bushing: the frame keys of a joint (point required, axes optional) and 6 × 6 matrices.
  model::Bushing read_bushing(const YAML::Node& n, const std::string& p, std::size_t index) const {
    expect_map(n, p);
    check_keys(n, p,
               {"name", "body_a", "body_b", "point", "point_a", "point_b", "axis", "axis_a",
                "axis2", "axis2_b", "stiffness", "damping"});
    model::Bushing b;
    b.source = source(n);
    b.name = n["name"] ? string(n["name"], join(p, "name")) : "bushing" + std::to_string(index);
    Joint& j = b.frame;
    j.name = b.name;
    j.type = JointType::fixed;
    j.source = b.source;
    if (const auto v = n["body_a"]) j.body_a = body_ref(v, join(p, "body_a"), true);
    const YAML::Node body_b = require(n, p, "body_b");
    j.body_b = body_ref(body_b, join(p, "body_b"), false);
    if (j.body_a == j.body_b)
      fail(body_b, join(p, "body_b"),
           fmt::format("body_a and body_b are the same \"{}\"", j.body_b));
    const auto at_most_one = [&](const char* x, const char* y) {
      if (n[x] && n[y]) fail(n[y], join(p, y), fmt::format("give either {} or {}, not both", x, y));
    };
    at_most_one("point", "point_a");
    at_most_one("point", "point_b");
    at_most_one("point_a", "point_b");
    at_most_one("axis", "axis_a");
    at_most_one("axis2", "axis2_b");
    if (!n["point"] && !n["point_a"] && !n["point_b"])
      fail(n, join(p, "point"), "missing required key (or give point_a or point_b)");
    if (const auto v = n["point"]) j.point = vec3(v, join(p, "point"));
    if (const auto v = n["point_a"]) j.point_a = vec3(v, join(p, "point_a"));
    if (const auto v = n["point_b"]) j.point_b = vec3(v, join(p, "point_b"));
    if (const auto v = n["axis"]) j.axis = direction(v, join(p, "axis"));
    if (const auto v = n["axis_a"]) j.axis_a = direction(v, join(p, "axis_a"));
    if (const auto v = n["axis2"]) j.axis2 = direction(v, join(p, "axis2"));
    if (const auto v = n["axis2_b"]) j.axis2_b = direction(v, join(p, "axis2_b"));
    if ((j.axis2 || j.axis2_b) && !(j.axis || j.axis_a))
      fail(n[j.axis2 ? "axis2" : "axis2_b"], join(p, j.axis2 ? "axis2" : "axis2_b"),
           "the first frame axis needs the third: give axis (or axis_a) too");
    if (j.axis && j.axis2 && !(std::abs(j.axis->dot(*j.axis2)) < kPerpendicularTolerance))
      fail(n["axis2"], join(p, "axis2"),
           fmt::format("must be perpendicular to axis (cosine of the angle {})",
                       j.axis->dot(*j.axis2)));
    if (const auto v = n["stiffness"]) b.stiffness = matrix6(v, join(p, "stiffness"));
    if (const auto v = n["damping"]) b.damping = matrix6(v, join(p, "damping"));
    if (!n["stiffness"] && !n["damping"]) fail(n, p, "give stiffness, damping or both");
    return b;
  }

  // A 6 × 6 symmetric positive semi-definite matrix: six numbers (the diagonal) or six rows of six.
  Mat<6, 6> matrix6(const YAML::Node& n, const std::string& key) const {
    constexpr const char* kShape =
        "expected 6 numbers (the diagonal) or 6 rows of 6 numbers (a symmetric matrix)";
    if (!n.IsSequence() || n.size() != 6) fail(n, key, kShape);
    Mat<6, 6> K = Mat<6, 6>::Zero();
    const bool rows = n[0].IsSequence();
    for (std::size_t i = 0; i < 6; ++i) {
      if (!rows) {
        K(i, i) = number(n[i], indexed(key, i));
        continue;
      }
      if (!n[i].IsSequence() || n[i].size() != 6) fail(n[i], indexed(key, i), kShape);
      for (std::size_t k = 0; k < 6; ++k) K(i, k) = number(n[i][k], indexed(indexed(key, i), k));
    }
    const double scale = K.cwiseAbs().maxCoeff();
    if (!((K - K.transpose()).cwiseAbs().maxCoeff() <= 1e-12 * scale))
      fail(n, key, "must be symmetric");
    const double low = Eigen::SelfAdjointEigenSolver<Mat<6, 6>>(K).eigenvalues().minCoeff();
    if (low < -1e-12 * scale)
      fail(n, key, fmt::format("must be positive semi-definite (smallest eigenvalue {:g})", low));
    return K;
  }

  Load read_load(const YAML::Node& n, const std::string& p, std::size_t index) const {
    expect_map(n, p);
    check_keys(n, p, {"name", "body", "force", "moment", "frame", "point", "point_local"});
    Load l;
    l.source = source(n);
    if (const auto v = n["name"]) {
      l.name = string(v, join(p, "name"));
    } else {
      l.name = "load" + std::to_string(index);
    }
    l.body = body_ref(require(n, p, "body"), join(p, "body"), false);
    if (const auto v = n["force"]) l.force = time_functions(v, join(p, "force"));
    if (const auto v = n["moment"]) l.moment = time_functions(v, join(p, "moment"));
    if (!l.force && !l.moment) fail(n, p, "at least one of force and moment is required");
    if (const auto v = n["frame"]) {
      const std::string name = string(v, join(p, "frame"));
      if (name == "body")
        l.frame = model::LoadFrame::body;
      else if (name != "global")
        fail(v, join(p, "frame"), "unknown frame \"" + name + "\" (valid: global, body)");
    }
    read_point(n, p, l.point, l.point_local);
    return l;
  }

  Probe read_probe(const YAML::Node& n, const std::string& p, const Model& m,
                   const KLShellReader& kl) {
    expect_map(n, p);
    check_keys(n, p, {"name", "body", "shell", "point", "point_local"});
    const YAML::Node name = require(n, p, "name");
    const std::string probe = string(name, join(p, "name"));
    if (probe.empty()) fail(name, join(p, "name"), "must not be empty");
    if (const auto [pos, inserted] = probe_lines_.emplace(probe, line_of(name)); !inserted)
      fail(name, join(p, "name"),
           fmt::format("duplicate probe name \"{}\" (first at line {})", probe, pos->second));
    Probe r = read_material_point(n, p, m, kl, false);
    r.name = probe;
    return r;
  }

  // A material point (a probe's keys but the name): body (a body or node; "ground" if
  // allow_ground, then with a global point) with point or point_local, or shell with point.
  Probe read_material_point(const YAML::Node& n, const std::string& p, const Model& m,
                            const KLShellReader& kl, bool allow_ground) {
    Probe r;
    r.source = source(n);
    if ((n["body"] ? 1 : 0) + (n["shell"] ? 1 : 0) != 1)
      fail(n, p, "give exactly one of body (a body or node) or shell (a kl_shell, with point)");
    if (const YAML::Node shell = n["shell"]) {
      const std::string name = string(shell, join(p, "shell"));
      const auto it = std::find_if(m.kl_shells.begin(), m.kl_shells.end(),
                                   [&](const model::KLShell& s) { return s.name == name; });
      if (it == m.kl_shells.end())
        fail(shell, join(p, "shell"), "no kl_shell named \"" + name + "\"");
      if (n["point_local"]) fail(n["point_local"], join(p, "point_local"), "not used with shell");
      const YAML::Node pt = require(n, p, "point");
      r.kl_shell = name;
      r.point = vec3(pt, join(p, "point"));
      const auto [xi, eta] =
          kl.point_on_surface(pt, join(p, "point"), *r.point, kl_surface(m, *it));
      r.xi = xi;
      r.eta = eta;
      return r;
    }
    r.body = body_ref(require(n, p, "body"), join(p, "body"), allow_ground);
    read_point(n, p, r.point, r.point_local);
    if (r.body == "ground") {
      if (r.point_local)
        fail(n["point_local"], join(p, "point_local"),
             "the ground has no body "
             "coordinates: give its point globally (point)");
      if (!r.point) fail(n, p, "a point of the ground needs point");
    }
    return r;
  }

  Spring read_spring(const YAML::Node& n, const std::string& p, std::size_t index, const Model& m,
                     const KLShellReader& kl) {
    expect_map(n, p);
    check_keys(n, p,
               {"name", "a", "b", "stiffness", "damping", "free_length", "stiffness_law",
                "damping_law", "actuator"});
    Spring s;
    s.source = source(n);
    s.name = n["name"] ? string(n["name"], join(p, "name")) : "spring" + std::to_string(index);
    for (const char* end : {"a", "b"}) {
      const YAML::Node e = require(n, p, end);
      expect_map(e, join(p, end));
      check_keys(e, join(p, end), {"body", "shell", "point", "point_local"});
      (end[0] == 'a' ? s.a : s.b) = read_material_point(e, join(p, end), m, kl, true);
    }
    if (s.a.body == "ground" && s.b.body == "ground")
      fail(n, p, "both ends are on the ground: the spring would act on nothing");
    const auto non_negative = [&](const char* key, double& out) {
      if (const YAML::Node v = n[key]) {
        out = number(v, join(p, key));
        if (!(out >= 0.0)) fail(v, join(p, key), "must be ≥ 0");
      }
    };
    non_negative("stiffness", s.stiffness);
    non_negative("damping", s.damping);
    for (const auto& [law, linear] :
         {std::pair{"stiffness_law", "stiffness"}, {"damping_law", "damping"}})
      if (n[law] && n[linear])
        fail(n[law], join(p, law), fmt::format("give either {} or {}, not both", linear, law));
    if (const YAML::Node v = n["stiffness_law"])
      s.stiffness_law = law_expression(v, join(p, "stiffness_law"), "e");
    if (const YAML::Node v = n["damping_law"]) {
      s.damping_law = law_expression(v, join(p, "damping_law"), "v");
      check_dissipative(v, join(p, "damping_law"), s.damping_law);
    }
    if (const YAML::Node v = n["actuator"]) s.actuator = time_function(v, join(p, "actuator"));
    if (!n["stiffness"] && !n["damping"] && !n["stiffness_law"] && !n["damping_law"] &&
        !n["actuator"])
      fail(n, p, "give stiffness, damping (or stiffness_law, damping_law), actuator or several");
    if (const YAML::Node v = n["free_length"]) {
      double L = 0.0;
      non_negative("free_length", L);
      s.free_length = L;
    }
    return s;
  }

  // A force law: a number or a muParser expression in `variable` (e or v), compiled here so that
  // a malformed expression or another variable is an error of the file.
  std::string law_expression(const YAML::Node& n, const std::string& key,
                             const std::string& variable) const {
    if (!n.IsScalar()) fail(n, key, "expected a number or an expression in " + variable);
    try {
      elements::ForceLaw check(n.Scalar(), variable);
    } catch (const std::invalid_argument& e) {
      fail(n, key, e.what());
    }
    return n.Scalar();
  }

  // A damper must dissipate, v N_d(v) ≥ 0: checked at v = ±10ᵏ, k = −4 … 4, and v = 0 (N_d = 0).
  void check_dissipative(const YAML::Node& n, const std::string& key,
                         const std::string& expression) const {
    const elements::ForceLaw law(expression, "v");
    std::vector<double> samples{0.0};
    for (int k = -4; k <= 4; ++k)
      for (double sign : {-1.0, 1.0}) samples.push_back(sign * std::pow(10.0, k));
    for (const double v : samples) {
      const double N = law.force(v);
      if (!std::isfinite(N) || v * N < 0.0 || (v == 0.0 && N != 0.0))
        fail(n, key,
             fmt::format("a damper must dissipate, v·N_d(v) ≥ 0 and N_d(0) = 0, but N_d({:g}) = "
                         "{:g}",
                         v, N));
    }
  }

  void read_point(const YAML::Node& n, const std::string& p, std::optional<Vec3>& point,
                  std::optional<Vec3>& point_local) const {
    const YAML::Node global = n["point"];
    const YAML::Node local = n["point_local"];
    if (global && local)
      fail(local, join(p, "point_local"), "give either point or point_local, not both");
    if (global) point = vec3(global, join(p, "point"));
    if (local) point_local = vec3(local, join(p, "point_local"));
  }

  // A beam or a shell: both have nodes "<name>[i]".
  struct BeamInfo {
    int line = 0;  // of its name
    int node_count = 0;
    bool shell = false;
    bool kl = false;  // a Kirchhoff–Love shell: its nodes are control points
  };
  // Whether a body reference names a Kirchhoff–Love shell itself.
  bool kl_shell_ref(const YAML::Node& n) const {
    if (!n || !n.IsScalar()) return false;
    const auto it = beams_.find(n.Scalar());
    return it != beams_.end() && it->second.kl;
  }

  // A joint with a Kirchhoff–Love shell on one side (body_b after this; the other side is a body,
  // a node or the ground): spherical, at `point` on the shell's surface.
  void read_kl_surface_joint(const YAML::Node& n, const std::string& p, Joint& j,
                             const model::Model& m, const KLShellReader& kl) const {
    const bool shell_is_a = kl_shell_ref(n["body_a"]);
    const YAML::Node shell = shell_is_a ? n["body_a"] : n["body_b"];
    const std::string shell_key = join(p, shell_is_a ? "body_a" : "body_b");
    const YAML::Node other = shell_is_a ? n["body_b"] : n["body_a"];
    if (j.type != JointType::spherical && j.type != JointType::revolute)
      fail(n["type"], join(p, "type"),
           fmt::format("\"{}\" is a Kirchhoff–Love shell: a joint at a point of its surface is "
                       "spherical or revolute (name a control point \"{}[A]\" for a rigid "
                       "attachment)",
                       shell.Scalar(), shell.Scalar()));
    if (kl_shell_ref(other))
      fail(other, join(p, shell_is_a ? "body_b" : "body_a"),
           "a joint between two Kirchhoff–Love shells is not built yet (multipatch coupling)");
    for (const char* k : {"point_a", "point_b"})
      if (n[k]) fail(n[k], join(p, k), "give the joint point on the shell as `point` (global)");
    const bool revolute = j.type == JointType::revolute;
    for (const char* k : {"axis", "axis_a", "axis2", "axis2_b"}) {
      const bool allowed = revolute && (std::string(k) == "axis" || std::string(k) == "axis_a");
      if (n[k] && !allowed)
        fail(n[k], join(p, k), fmt::format("not allowed for a {} joint", to_string(j.type)));
    }
    if (revolute) {
      if (n["axis"] && n["axis_a"])
        fail(n["axis_a"], join(p, "axis_a"), "give at most one of axis, axis_a");
      if (!n["axis"] && !n["axis_a"])
        fail(n, p, "a revolute joint at a shell point requires `axis` (or `axis_a`)");
      // axis_a: in the coordinates of the side that is not the shell.
      if (n["axis_a"] && shell_is_a)
        fail(n["axis_a"], join(p, "axis_a"),
             "body_a is the shell: give the axis globally as `axis` (at t = 0)");
      if (n["axis_a"] && !other)
        fail(n["axis_a"], join(p, "axis_a"), "the other side is the ground: give `axis`");
      const YAML::Node ax = n["axis"] ? n["axis"] : n["axis_a"];
      const std::string key = join(p, n["axis"] ? "axis" : "axis_a");
      const Vec3 v = vec3(ax, key);
      if (!(v.norm() > 0.0)) fail(ax, key, "the axis must be nonzero");
      (n["axis"] ? j.axis : j.axis_a) = v.normalized();
    }
    j.kl_shell = shell.Scalar();
    j.body_b = j.kl_shell;
    j.body_a = other ? body_ref(other, join(p, shell_is_a ? "body_b" : "body_a"), true) : "ground";
    const YAML::Node pt = require(n, p, "point");
    j.point = vec3(pt, join(p, "point"));
    const auto it = std::find_if(m.kl_shells.begin(), m.kl_shells.end(),
                                 [&](const model::KLShell& s) { return s.name == j.kl_shell; });
    if (it == m.kl_shells.end()) fail(shell, shell_key, "no kl_shell named \"" + j.kl_shell + "\"");
    const auto [xi, eta] = kl.point_on_surface(pt, join(p, "point"), *j.point, kl_surface(m, *it));
    j.xi = xi;
    j.eta = eta;
  }

  // Whether a body reference names a control point "<kl shell>[A]".
  bool kl_node(const std::string& ref) const {
    const auto open = ref.find('[');
    if (open == std::string::npos) return false;
    const auto it = beams_.find(ref.substr(0, open));
    return it != beams_.end() && it->second.kl;
  }

  std::map<std::string, int> body_lines_;  // name → line of its definition
  std::map<std::string, std::pair<YAML::Node, std::string>> body_names_;  // name → (node, key)
  std::map<std::string, BeamInfo> beams_;
  std::map<std::string, int> joint_lines_;
  std::map<std::string, int> probe_lines_;
};

}  // namespace

model::Model read_model_string(const std::string& yaml, const std::string& name_for_messages,
                               const ReadOptions& options) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml);
  } catch (const YAML::ParserException& e) {
    throw ModelError(name_for_messages, e.mark.line >= 0 ? e.mark.line + 1 : 1, "", e.msg);
  }
  const std::vector<std::string> set =
      apply_model_overrides(root, options.overrides, name_for_messages);
  try {
    return Reader(name_for_messages, options).read(root);
  } catch (const ModelError& e) {
    // The last setting of a key is the one in effect.
    for (std::size_t k = set.size(); k-- > 0;) {
      const std::string& s = set[k];
      const bool below = e.key().size() > s.size() && e.key().compare(0, s.size(), s) == 0 &&
                         (e.key()[s.size()] == '.' || e.key()[s.size()] == '[');
      if (e.key() == s || below)
        throw ModelError(name_for_messages, 0, e.key(),
                         e.message() + " (the value of --set " + options.overrides[k].key + "=" +
                             options.overrides[k].value + ")");
    }
    throw;
  }
}

model::Model read_model(const std::string& path, const ReadOptions& options) {
  std::error_code ec;
  std::ifstream in;
  if (std::filesystem::is_regular_file(path, ec)) in.open(path, std::ios::binary);
  if (!in.is_open()) throw ModelError(path, 0, "", "cannot open model file");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw ModelError(path, 0, "", "cannot read model file");
  return read_model_string(text.str(), path, options);
}

}  // namespace isoflex::io
