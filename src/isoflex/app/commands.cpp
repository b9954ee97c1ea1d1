#include "isoflex/app/commands.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <new>
#include <optional>
#include <thread>

#include "isoflex/app/exit_codes.hpp"
#include "isoflex/app/interrupt.hpp"
#include "isoflex/app/run_outputs.hpp"
#include "isoflex/app/simulation.hpp"
#include "isoflex/elements/point_spring_damper.hpp"
#include "isoflex/integrate/cosimulation.hpp"
#include "isoflex/integrate/energy_momentum.hpp"
#include "isoflex/integrate/initial_equilibrium.hpp"
#include "isoflex/integrate/static_equilibrium.hpp"
#include "isoflex/io/hdf5_results.hpp"
#include "isoflex/io/model_error.hpp"
#include "isoflex/io/model_reader.hpp"
#include "isoflex/io/output_error.hpp"
#include "isoflex/io/summary_writer.hpp"
#include "isoflex/loads/line_actuator.hpp"
#include "isoflex/solve/linear_solver.hpp"
#include "isoflex/solve/memory.hpp"
#include "isoflex/solve/process_group.hpp"
#include "isoflex/system/kl_interface_report.hpp"
#include "isoflex/system/memory_estimate.hpp"
#include "isoflex/system/system.hpp"

namespace isoflex::app {

namespace {

// The memory a model may use: --max-memory, else what the system has available (0: unknown, no
// limit), and how a message says it.
struct MemoryLimit {
  double bytes = 0;
  std::string text;  // "17 GB are available", "--max-memory is 2.0 GB"
};

MemoryLimit memory_limit(const std::optional<double>& max_memory) {
  if (max_memory)
    return {*max_memory, fmt::format("--max-memory is {}", system::format_bytes(*max_memory))};
  if (const auto available = solve::available_memory_bytes())
    return {*available, fmt::format("{} are available", system::format_bytes(*available))};
  return {};
}

// What an allocation failure says: the solver's own message (solve::OutOfMemory: which
// factorization, how many unknowns), not "std::bad_alloc".
std::string out_of_memory_cause(const std::bad_alloc& e) {
  if (dynamic_cast<const solve::OutOfMemory*>(&e)) return e.what();
  return "an allocation failed";
}

// A model compiled as a system, with its memory estimate.
struct Loaded {
  model::Model model;
  std::unique_ptr<system::System> sys;
  system::MemoryEstimate memory;
  MemoryLimit limit;
};

// Says that the memory ran out while `doing` (reading, compiling) the model: one error line, and
// the message in `out_of_memory` if given.
void report_out_of_memory(const std::string& file, const char* doing, const std::bad_alloc& e,
                          double estimate, const MemoryLimit& limit, std::FILE* err,
                          std::string* out_of_memory) {
  const std::string message = fmt::format(
      "{}: out of memory while {} the model ({}; the estimate was {}, {})", file, doing,
      out_of_memory_cause(e), estimate > 0 ? system::format_bytes(estimate) : "not made yet",
      limit.bytes > 0 ? limit.text : "the available memory is unknown");
  fmt::print(err, "error: {}\n", message);
  if (out_of_memory) *out_of_memory = message;
}

// Compiles a model read from `file`, with the options' solver overrides applied first; prints one
// error line and returns nullopt on bad input. A model whose memory estimate exceeds the limit is
// refused before it is compiled (the located part that needs the most). If the memory runs out
// all the same, `out_of_memory` (if given) receives the message.
std::optional<Loaded> prepare(model::Model model, const std::string& file, std::FILE* err,
                              const RunOptions* o, const MemoryLimit& limit,
                              std::string* out_of_memory = nullptr) {
  double estimate = 0;
  try {
    Loaded l{std::move(model), nullptr, {}, limit};
    model::Solver& s = l.model.solver;
    if (o && o->formulation) s.formulation = *o->formulation;
    if (o && o->dt) s.dt = *o->dt;
    if (o && o->t_end) s.t_end = *o->t_end;
    if (o && o->max_subdivisions) s.max_subdivisions = *o->max_subdivisions;
    if (!(s.dt > 0) || !(s.t_end > 0)) {
      fmt::print(err, "error: --dt and --t-end must be positive\n");
      return std::nullopt;
    }
    if (o && o->statics) s.analysis = model::Analysis::statics;
    if (s.path.method != model::PathMethod::load && s.analysis != model::Analysis::statics) {
      fmt::print(err,
                 "error: {}:{}: solver.path_following: path following is for a static analysis "
                 "(analysis: static, or run --static)\n",
                 file, s.path.line);
      return std::nullopt;
    }
    // With --dt or --t-end the step count is checked again (the file's own values were checked
    // by the reader, with their line).
    if (o && (o->dt || o->t_end)) {
      if (const std::string problem = model::step_count_problem(s); !problem.empty()) {
        fmt::print(err, "error: --dt, --t-end: {}\n", problem);
        return std::nullopt;
      }
    }
    // Before anything of the model's size is allocated (System::compile).
    l.memory = system::estimate_memory(l.model);
    estimate = l.memory.total();
    if (limit.bytes > 0 && estimate > limit.bytes) {
      const system::MemoryPart* part = l.memory.largest();
      const std::string where =
          part && part->source.line > 0
              ? fmt::format("{}:{}: {}: ", part->source.file.empty() ? file : part->source.file,
                            part->source.line, part->what)
              : fmt::format("{}: ", file);
      fmt::print(err,
                 "error: {}this model needs about {} ({}; {}: {}), {} (--max-memory to change)\n",
                 where, system::format_bytes(estimate), l.memory.breakdown(),
                 part ? part->what : "", part ? part->detail : "", limit.text);
      return std::nullopt;
    }
    l.sys = std::make_unique<system::System>(system::System::compile(l.model));
    return l;
  } catch (const std::bad_alloc& e) {
    report_out_of_memory(file, "compiling", e, estimate, limit, err, out_of_memory);
  } catch (const io::ModelError& e) {
    fmt::print(err, "error: {}\n", e.what());
  } catch (const system::CompileError& e) {
    fmt::print(err, "error: {}\n", e.what());
  } catch (const std::runtime_error& e) {
    // A numerical failure while compiling that no model entry explains (e.g. a singular matrix
    // in the initial velocity projection): still one line and exit code 2, not an abort.
    fmt::print(err, "error: {}: the system could not be set up: {}\n", file, e.what());
  }
  return std::nullopt;
}

// Reads the model file and compiles it (prepare).
std::optional<Loaded> load(const std::string& file, std::FILE* err, const RunOptions* o,
                           const std::optional<double>& max_memory,
                           const std::vector<io::ModelOverride>& overrides,
                           std::string* out_of_memory = nullptr) {
  const MemoryLimit limit = memory_limit(max_memory);
  try {
    return prepare(io::read_model(file, {limit.bytes, limit.text, overrides}), file, err, o, limit,
                   out_of_memory);
  } catch (const std::bad_alloc& e) {
    report_out_of_memory(file, "reading", e, 0, limit, err, out_of_memory);
  } catch (const io::ModelError& e) {
    fmt::print(err, "error: {}\n", e.what());
  }
  return std::nullopt;
}

// Joint names of the rows in `rows`, with how many rows of each.
std::string rows_by_joint(const system::System& sys, const std::vector<int>& rows) {
  std::vector<std::pair<std::string, int>> by;
  for (int r : rows) {
    const int j = sys.joint_of_row(r), c = sys.nary_of_row(r);
    const std::string name = j >= 0   ? sys.joints()[j].name
                             : c >= 0 ? sys.nary_constraints()[c].name
                                      : "internal";
    if (!by.empty() && by.back().first == name)
      ++by.back().second;
    else
      by.push_back({name, 1});
  }
  std::string s;
  for (const auto& [n, c] : by) s += fmt::format("{}{} ({} rows)", s.empty() ? "" : ", ", n, c);
  return s;
}

// A Kirchhoff–Love patch: mesh, quadrature and control points.
void print_kl_check(const model::Model& m, const system::KLPatchInstance& P, std::FILE* out) {
  const elements::KLShellPatch& p = P.element->patch();
  const auto shell = std::find_if(m.kl_shells.begin(), m.kl_shells.end(),
                                  [&](const model::KLShell& s) { return s.name == P.name; });
  fmt::print(out,
             "kl shell         {} on surface {}: {} elements, {} quadrature points ({} x {} "
             "per element; reference data {} bytes per point)\n",
             P.name, shell->surface, p.elements(), p.quadrature_points(),
             shell->quadrature[0] > 0 ? shell->quadrature[0] : p.reference().degree_u() + 1,
             shell->quadrature[1] > 0 ? shell->quadrature[1] : p.reference().degree_v() + 1,
             p.reference_bytes_per_point());
  fmt::print(out, "control points   {} (3 coordinates each)\n", p.control_points());
  fmt::print(out, "dofs             {}\n", p.dofs());
  fmt::print(out, "kinematics       {}\n",
             P.element->kinematics() == elements::KLKinematics::linear ? "linear" : "nonlinear");
}

// The interfaces between Kirchhoff–Love patches: which edges, how many triples, the angle, the
// coupling, and what was refined to make them conforming.
void print_kl_interfaces(const system::System& sys, std::FILE* out) {
  for (const std::string& line : system::kl_interface_report(sys)) fmt::print(out, "{}\n", line);
}

// The slave coordinates of the System's tied rows (AF-D in a static analysis).
int tied_coordinates(const system::System& sys) {
  const system::LinearConstraints& lin = sys.linear_constraints();
  if (lin.tied.empty()) return 0;
  return static_cast<int>(system::DofMap::build(sys.n(), lin.eliminated, lin.tied).slaves.size());
}

// A static analysis: load steps, the linear conditions and the unknowns.
void print_static_check(const system::System& sys, const model::Solver& solver, std::FILE* out) {
  const integrate::StaticEquilibrium eq(sys, solver);
  const integrate::StaticSettings& s = eq.settings();
  const integrate::PathSettings& p = s.path;
  if (p.control == integrate::PathControl::arc_length)
    fmt::print(out,
               "analysis         static, arc length (first step {}, load weight {:g}, at most {} "
               "steps) until the load factor reaches {:g}\n",
               p.arc_length > 0 ? fmt::format("{:g}", p.arc_length)
                                : fmt::format("that of load factor {:g}", s.t_end / s.steps),
               p.load_weight, p.max_steps, s.t_end);
  else if (p.control == integrate::PathControl::displacement)
    fmt::print(out,
               "analysis         static, displacement control of probe {} along ({:g}, {:g}, "
               "{:g}) to {:g} in {} steps{}\n",
               solver.path.probe, solver.path.direction.x(), solver.path.direction.y(),
               solver.path.direction.z(), p.displacement, s.steps,
               s.adaptive ? fmt::format(" (adaptive, at most {} halvings)", s.max_cuts) : "");
  else
    fmt::print(out, "analysis         static, {} load steps to t = {:g}{}\n", s.steps, s.t_end,
               s.adaptive ? fmt::format(" (adaptive, at most {} halvings)", s.max_cuts) : "");
  fmt::print(out, "eliminated       {}  (fixed coordinates)\n", eq.eliminated());
  fmt::print(out,
             "multipliers      {}  (linear conditions: symmetry slopes, prescribed edges{}{})\n",
             eq.multipliers(),
             eq.implied_multipliers() > 0
                 ? fmt::format("; {} implied by the tied rows, their multipliers 0",
                               eq.implied_multipliers())
                 : std::string(),
             eq.tied_rows() > 0
                 ? fmt::format("; {} symmetry and clamp slope rows tied instead, for the PETSc "
                               "solver",
                               eq.tied_rows())
                 : std::string());
  if (eq.tied() > 0 || eq.dropped_tied_rows() > 0)
    fmt::print(out,
               "tied             {}  (slave coordinates of the {}, eliminated by substitution; {} "
               "row{} implied by the others)\n",
               eq.tied(),
               eq.tied_rows() == 0 ? "straight triples' G¹ rows (5.36)"
               : sys.linear_constraints().tied.empty()
                   ? "symmetry and clamp slope rows"
                   : "symmetry and clamp slope rows and the straight triples' G¹ rows (5.36)",
               eq.dropped_tied_rows(), eq.dropped_tied_rows() == 1 ? "" : "s");
  fmt::print(out,
             "unknowns         {}  (static: free coordinates + multipliers + constraint rows)\n",
             eq.unknowns());
  const std::string_view solver_name = eq.linear_solver();
  if (solver_name != "direct")
    fmt::print(out, "linear solver    {}  (PETSc{}; docs/theory/solvers.md)\n", solver_name,
               solver.linear_solver == model::LinearSolver::automatic
                   ? fmt::format(", chosen by size: geometric multigrid from {} unknowns",
                                 sys.linear_constraints().tied.empty()
                                     ? integrate::kAutomaticMultigridUnknowns
                                     : integrate::kAutomaticTiedMultigridUnknowns)
                   : "");
}

// What a user can change after a step or load step that Newton could not solve (appended to
// the failure message).
std::string newton_failure_hint(const model::Solver& s) {
  const std::string halvings = fmt::format(
      "more halvings of a failing {} (solver.max_subdivisions or --max-subdivisions, "
      "now {}, at most 20)",
      s.analysis == model::Analysis::statics ? "load step" : "step", s.max_subdivisions);
  if (s.analysis == model::Analysis::statics)
    return fmt::format(
        "; to get further: more load steps (a smaller solver.dt), {}, more Newton iterations "
        "(solver.max_iterations, now {}), or path following past a limit point "
        "(solver.path_following)",
        halvings, s.max_iterations);
  return fmt::format(
      "; to get further: a smaller time step (solver.dt or --dt), {}, or more Newton iterations "
      "(solver.max_iterations, now {})",
      halvings, s.max_iterations);
}

// What `summary.json` and results.h5 call the time stepping of a dynamic run.
std::string dynamic_formulation(const model::Solver& s) {
  return s.integrator == model::Integrator::energy_momentum ? model::to_string(s.formulation)
                                                            : model::to_string(s.integrator);
}

// The state of a restarted run (--restart FILE --from-step N), checked against the compiled model
// before anything is written; prints one error line and returns nullopt when it cannot serve.
std::optional<io::SavedState> restart_state(const RunOptions& o, const model::Model& m,
                                            const system::System& sys,
                                            const std::filesystem::path& outdir, std::FILE* err,
                                            std::FILE* out) {
  const std::string& file = o.restart_file;
  if (m.solver.analysis == model::Analysis::statics) {
    fmt::print(err, "error: --restart: continues a dynamic run; this is a static analysis\n");
    return std::nullopt;
  }
  if (m.solver.cosimulation) {
    fmt::print(err,
               "error: --restart: a co-simulation cannot be restarted (results.h5 holds the state "
               "of its multibody part only)\n");
    return std::nullopt;
  }
  // Writing results.h5 would truncate the file being restarted from: refused rather than read
  // first, since the new file would lose every step before N.
  std::error_code ec;
  if (m.output.hdf5 &&
      std::filesystem::equivalent(file, outdir / io::Hdf5ResultsWriter::kFileName, ec) && !ec) {
    fmt::print(err,
               "error: --restart {}: this run would write its results.h5 over it; give another "
               "output folder (-o)\n",
               file);
    return std::nullopt;
  }
  io::SavedState saved;
  try {
    saved = io::read_saved_state(file, o.restart_step);
  } catch (const io::RestartError& e) {
    fmt::print(err, "error: --restart: {}\n", e.what());
    return std::nullopt;
  }
  if (saved.analysis != "dynamic") {
    fmt::print(err, "error: --restart: {}: holds a {} run; only dynamic runs can be continued\n",
               file, saved.analysis);
    return std::nullopt;
  }
  // Sizes: a state of another model (or the same file after an edit that changed its nodes or
  // constraints) is refused with the dataset and both sizes.
  const std::string where = fmt::format("{}: /steps/{:09d}", file, o.restart_step);
  const int n = sys.n(), rows = sys.m_selected();
  const integrate::State& s = saved.state;
  const auto mismatch = [&](const char* name, Eigen::Index size, const std::string& expected) {
    fmt::print(err,
               "error: --restart: {}/{}: {} entries, the model {} needs {} (n = {} coordinates, "
               "m = {} constraint rows); the file was written for {}\n",
               where, name, size, o.model_file, expected, n, rows, saved.model_file);
    return std::nullopt;
  };
  if (s.q.size() != n) return mismatch("q", s.q.size(), std::to_string(n));
  if (s.v.size() != n) return mismatch("v", s.v.size(), std::to_string(n));
  for (const auto& [name, x] : {std::pair{"a", &s.a}, std::pair{"aux", &s.aux},
                                std::pair{"q_prev", &s.q_prev}, std::pair{"v_prev", &s.v_prev}})
    if (x->size() != 0 && x->size() != n)
      return mismatch(name, x->size(), fmt::format("0 or {}", n));
  if (s.lambda.size() != 0 && s.lambda.size() != rows)
    return mismatch("lambda", s.lambda.size(), fmt::format("0 or {}", rows));
  if (std::lround((m.solver.t_end - s.t) / m.solver.dt) < 1) {
    fmt::print(err,
               "error: --restart: step {} of {} is at t = {:.17g}, t_end is {:.17g}: no step "
               "left\n",
               o.restart_step, file, s.t, m.solver.t_end);
    return std::nullopt;
  }
  // The memory of another scheme's last step means something else (the energy–momentum
  // unknowns of another formulation, no q̈ₙ): this run starts its own from qₙ, vₙ, as at t = 0.
  const std::string formulation = dynamic_formulation(m.solver);
  if (saved.formulation != formulation) {
    fmt::print(err,
               "note: --restart: {} was written by {}, this run uses {}: it continues from q and "
               "v of step {} without the last step's memory of that scheme\n",
               file, saved.formulation, formulation, o.restart_step);
    integrate::State& t = saved.state;
    t.last_unknowns.resize(0);
    t.last_dt = 0.0;
    t.last_start = 0;
    t.a.resize(0);
    t.aux.resize(0);
    t.q_prev.resize(0);
    t.v_prev.resize(0);
  }
  fmt::print(out, "restart: step {} (t = {:.6g}) of {}\n", o.restart_step, s.t, file);
  return saved;
}

}  // namespace

std::optional<double> parse_memory_size(const std::string& text) {
  std::size_t used = 0;
  double value = 0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    return std::nullopt;
  }
  std::string suffix = text.substr(used);
  if (suffix.size() == 2 && (suffix[1] == 'B' || suffix[1] == 'b')) suffix.pop_back();  // "GB"
  double unit = 1;
  if (suffix.size() == 1) {
    const char c = static_cast<char>(std::toupper(static_cast<unsigned char>(suffix[0])));
    const std::string units = "KMGT";
    const auto k = units.find(c);
    if (k == std::string::npos) return std::nullopt;
    unit = std::pow(1024.0, double(k + 1));
  } else if (!suffix.empty()) {
    return std::nullopt;
  }
  if (!(value > 0) || !std::isfinite(value * unit)) return std::nullopt;
  return value * unit;
}

namespace {

// `check`'s report of a compiled model.
int print_check(const std::string& file, const std::optional<Loaded>& l, std::FILE* out,
                std::FILE* err) {
  if (!l) return kExitBadInput;
  fmt::print(out, "model            {}\n", file);
  fmt::print(out, "memory           about {} to run, {} to check ({}){}\n",
             system::format_bytes(l->memory.total()), system::format_bytes(l->memory.compile()),
             l->memory.breakdown(), l->limit.bytes > 0 ? "; " + l->limit.text : "");
  fmt::print(out, "bodies           {}\n", l->model.bodies.size());
  const auto diagonal = [](const Mat<6, 6>& K) {
    std::string d;
    for (int i = 0; i < 6; ++i) d += fmt::format("{}{:g}", i ? ", " : "", K(i, i));
    return d;
  };
  for (const model::Bushing& b : l->model.bushings)
    fmt::print(out,
               "bushing          {}: {} – {}, stiffness diagonal [{}], damping diagonal [{}]\n",
               b.name, b.frame.body_a, b.frame.body_b, diagonal(b.stiffness), diagonal(b.damping));
  for (const model::Joint& j : l->model.joints)
    if (j.spring)
      fmt::print(out, "joint spring     {} ({}): stiffness {:g}, damping {:g}, free {} {:g}\n",
                 j.name, model::to_string(j.type), j.spring->stiffness, j.spring->damping,
                 j.type == model::JointType::revolute ? "angle" : "length", j.spring->free_value);
  if (l->sys && !l->sys->beams().empty()) {
    std::size_t elements = 0;
    for (const auto& b : l->sys->beams()) elements += b.elements.size();
    fmt::print(out, "beams            {} ({} elements)\n", l->sys->beams().size(), elements);
  }
  // Surfaces (for shells): source, size after refinement, suitability findings.
  for (const model::Surface& s : l->model.surfaces) {
    const geometry::NurbsSurface& g = s.surface;
    const auto nu = g.u.element_spans().size(), nv = g.v.element_spans().size();
    const bool refined = s.refine.elevate != std::array<int, 2>{0, 0} ||
                         s.refine.knots_per_span != std::array<int, 2>{0, 0};
    fmt::print(
        out,
        "surface          {}: {}; degrees {} x {}, control points {} x {} = {}, elements {} "
        "x {} = {}{}\n",
        s.name,
        s.kind == model::SurfaceSourceKind::cad
            ? fmt::format("cad \"{}\" patch {} \"{}\"", s.cad_file, s.cad_patch, s.cad_patch_name)
            : "builtin " + s.builtin_type,
        g.degree_u(), g.degree_v(), g.n_u(), g.n_v(), g.n_u() * g.n_v(), nu, nv, nu * nv,
        refined ? fmt::format(" (refined: elevate [{}, {}], knots per span [{}, {}])",
                              s.refine.elevate[0], s.refine.elevate[1], s.refine.knots_per_span[0],
                              s.refine.knots_per_span[1])
                : "");
    for (const model::SurfaceFinding& f : s.findings) {
      fmt::print(out, "  {:<14} {}\n", f.severity, f.issue);
      fmt::print(out, "  {:<14} fix: {}\n", "", f.fix);
    }
  }
  const auto& sys = *l->sys;
  for (const system::KLPatchInstance& P : sys.kl_patches()) print_kl_check(l->model, P, out);
  print_kl_interfaces(sys, out);
  const int m_int = sys.internal_rows();
  // Counts per node kind (math/node_kind.hpp), the kinds present only.
  std::string kinds;
  for (int k = 0; k < kNodeKinds; ++k) {
    const NodeType& type = node_type(static_cast<NodeKind>(k));
    const int count = sys.node_count(type.kind());
    if (count == 0) continue;
    kinds += fmt::format("{}{} {} nodes, {} coordinates each", kinds.empty() ? "" : "; ", count,
                         type.name(), type.coordinates());
  }
  fmt::print(out, "nodes            {} ({})\n", sys.node_count(), kinds);
  for (const auto& sp : sys.springs()) {
    const auto& e = dynamic_cast<const elements::PointSpringDamper&>(
        *sys.elements()[static_cast<std::size_t>(sp.element_index)]);
    const auto& law = e.law();
    const std::string stiffness = law.stiffness_law.empty()
                                      ? fmt::format("stiffness {:g}", law.stiffness)
                                      : fmt::format("stiffness law \"{}\"", law.stiffness_law);
    const std::string damping = law.damping_law.empty()
                                    ? fmt::format("damping {:g}", law.damping)
                                    : fmt::format("damping law \"{}\"", law.damping_law);
    const std::string actuator =
        sp.actuator_load < 0
            ? ""
            : fmt::format(", actuator \"{}\"",
                          dynamic_cast<const loads::LineActuator&>(
                              *sys.loads()[static_cast<std::size_t>(sp.actuator_load)])
                              .expression());
    fmt::print(out, "spring           {}: {}, {}{}, free length {:.6g}, length at t = 0 {:.6g}\n",
               sp.name, stiffness, damping, actuator, law.free_length,
               e.length(sys.stacked(sys.q0(), e.nodes())));
  }
  fmt::print(out, "n                {}  (redundant coordinates)\n", sys.n());
  fmt::print(out,
             "m                {}  (independent constraints: {} internal + {} joint and other)\n",
             sys.m_selected(), m_int, sys.m_selected() - m_int);
  {
    // Rows per constraint kind (all rows, redundant ones included): the nodes' internal rows,
    // then each joint type and each n-ary constraint type in the order it first appears.
    struct Kind {
      std::string type;
      int rows = 0, count = 0;
      const char* noun;  // "joint" or "constraint"
    };
    std::vector<Kind> kinds;
    const auto add = [&](const std::string& type, int rows, const char* noun) {
      auto it =
          std::find_if(kinds.begin(), kinds.end(), [&](const Kind& k) { return k.type == type; });
      if (it == kinds.end()) it = kinds.insert(kinds.end(), {type, 0, 0, noun});
      it->rows += rows;
      ++it->count;
    };
    for (const auto& J : sys.joints()) add(J.type, J.joint->constraint_count(), "joint");
    for (const auto& C : sys.nary_constraints())
      add(C.type, C.constraint->constraint_count(), "constraint");
    std::string text = fmt::format("internal {}", m_int);
    for (const Kind& k : kinds)
      text += fmt::format("; {} {} ({} {}{})", k.type, k.rows, k.count, k.noun,
                          k.count == 1 ? "" : "s");
    fmt::print(out, "constraint rows  {}\n", text);
  }
  fmt::print(out, "redundant        {}", sys.redundant_rows().size());
  if (!sys.redundant_rows().empty())
    fmt::print(out, "  (dropped: {}; full-pivot LU rank {} = pivoted QR rank {})",
               rows_by_joint(sys, sys.redundant_rows()), sys.cut_rank(), sys.cut_rank_qr());
  fmt::print(out, "\n");
  const system::LinearConstraints& lin = sys.linear_constraints();
  if (lin.eliminated.empty() && lin.multipliers() == 0 && lin.tied.empty())
    fmt::print(out, "dof              {}  (n - m)\n", sys.n() - sys.m_selected());
  else if (lin.tied.empty())  // a static analysis with supports as linear conditions
    fmt::print(
        out, "dof              {}  (n - m - eliminated - multipliers)\n",
        sys.n() - sys.m_selected() - static_cast<int>(lin.eliminated.size()) - lin.multipliers());
  else
    fmt::print(out, "dof              {}  (n - m - eliminated - independent multipliers - tied)\n",
               integrate::StaticEquilibrium(sys, l->model.solver).dof());
  fmt::print(out, "tree coordinates {}  (loop-closing rows kept: {})\n", sys.k(), sys.cut_rank());
  if (l->model.solver.analysis == model::Analysis::statics)
    print_static_check(sys, l->model.solver, out);
  else if (const model::Solver& so = l->model.solver;
           so.integrator == model::Integrator::energy_momentum) {
    fmt::print(out, "unknowns         constrained {}, nullspace {}, reparametrized {}\n",
               sys.n() + sys.m_selected(), sys.n(), sys.k());
    if (so.numerical_dissipation > 0.0)
      fmt::print(out,
                 "dissipation      numerical, chi {:g} on the strains of beams and shells "
                 "(momenta exact, energy decays)\n",
                 so.numerical_dissipation);
  } else  // a DAE scheme: (q, λ) with every selected row (integrate/dae_integrator.hpp)
    fmt::print(out, "unknowns         {} ({}{}, {})\n", sys.n() + sys.m_selected(),
               model::to_string(so.integrator),
               so.integrator == model::Integrator::generalized_alpha
                   ? fmt::format(", rho_infinity {:g}", so.rho_infinity)
                   : std::string(),
               so.scaling ? "scaled" : "not scaled");
  if (const auto& co = l->model.solver.cosimulation) {
    try {
      const integrate::CoSimulation cs(l->model);
      fmt::print(out,
                 "co-simulation    macro step {:g} ({} steps of dt), hold {}: shell part {} "
                 "unknowns, multibody part {} unknowns, {} springs across\n",
                 cs.macro_step(), cs.micro_steps(), model::to_string(co->hold), cs.shell_unknowns(),
                 cs.mbs_unknowns(), cs.crossing_springs());
    } catch (const system::CompileError& e) {
      fmt::print(err, "error: {}\n", e.what());
      return kExitBadInput;
    }
  }
  for (const std::string& w : model::gravity_warnings(l->model))
    fmt::print(out, "warning          {}\n", w);
  if (sys.initial_velocity_projection_error() > 1e-9)
    fmt::print(out,
               "warning          initial velocities violate the joints{}; projected (relative "
               "change {:.3g})\n",
               sys.rheonomic() ? " (or the rates of the prescribed motions at t = 0)" : "",
               sys.initial_velocity_projection_error());
  fmt::print(out, "joint forest\n{}", sys.describe_forest(l->model));
  return 0;
}

}  // namespace

int check_command(const std::string& file, std::FILE* out, std::FILE* err,
                  const CheckOptions& options) {
  return print_check(file, load(file, err, nullptr, options.max_memory, options.overrides), out,
                     err);
}

int check_model(model::Model m, std::FILE* out, std::FILE* err, const CheckOptions& options) {
  const std::string file = m.file;
  return print_check(
      file, prepare(std::move(m), file, err, nullptr, memory_limit(options.max_memory)), out, err);
}

int run_command(const RunOptions& o, std::FILE* out, std::FILE* err) {
  // Under mpirun -n N (N > 1) every rank reads and compiles the model and takes its part of the
  // patches' elements (docs/theory/solvers.md §6); rank 0 alone prints and writes.
  const solve::ProcessGroup* group = nullptr;
  try {
    group = &solve::processes();
  } catch (const std::runtime_error& e) {
    fmt::print(err, "error: {}\n", e.what());
    return kExitBadInput;
  }
  const bool writes = group->rank() == 0;
  const std::unique_ptr<std::FILE, int (*)(std::FILE*)> silent(
      writes ? nullptr : std::fopen("/dev/null", "w"), &std::fclose);
  if (silent) out = err = silent.get();
  const std::filesystem::path outdir =
      o.outdir.empty() ? std::filesystem::path("out") /
                             std::filesystem::path(o.model_file).parent_path().filename()
                       : std::filesystem::path(o.outdir);
  std::string out_of_memory;
  auto l = load(o.model_file, err, &o, o.max_memory, o.overrides, &out_of_memory);
  if (!l && !out_of_memory.empty()) {
    // The model was accepted but its compilation ran out of memory: a run that failed, with
    // summary.json saying why (where the output folder can be made).
    io::RunSummary sum;
    sum.model = o.model_file;
    sum.status = "failed";
    sum.message = out_of_memory;
    std::error_code ec;
    if (writes) std::filesystem::create_directories(outdir, ec);
    try {
      if (!ec && writes) io::write_summary_json(outdir / "summary.json", sum);
    } catch (const io::OutputError& e) {
      fmt::print(err, "error: {}\n", e.what());
    }
    return kExitNewtonFailure;
  }
  if (!l) return kExitBadInput;
  model::Model& m = l->model;
  const bool statics = m.solver.analysis == model::Analysis::statics;
  if (group->size() > 1) {
    if (const std::string why = integrate::why_not_distributed(*l->sys, m.solver); !why.empty()) {
      fmt::print(err, "error: {} MPI ranks: {}\n", group->size(), why);
      return kExitBadInput;
    }
  }
  std::optional<io::SavedState> restart;
  if (!o.restart_file.empty()) {
    restart = restart_state(o, m, *l->sys, outdir, err, out);
    if (!restart) return kExitBadInput;
  }
  std::error_code ec;
  if (writes) std::filesystem::create_directories(outdir, ec);
  if (ec) {
    fmt::print(err, "error: {}: cannot create output directory: {}\n", outdir.string(),
               ec.message());
    // Rank 0 alone writes: the other ranks would wait for it in the first sum.
    if (group->size() > 1) group->abort(2);
    return 2;
  }

  auto& sys = *l->sys;
  // By default all cores, shared among the ranks of an MPI run on one machine (more threads
  // than cores slow the element loops down).
  sys.set_threads(
      o.threads > 0
          ? o.threads
          : std::max(1, static_cast<int>(std::thread::hardware_concurrency()) / group->size()));
  // A static analysis evaluates a linear patch's tangent once per load step: no kept copy.
  if (statics) sys.keep_linear_tangent(false);
  if (group->size() > 1) sys.partition_kl_patches(group->rank(), group->size());
  // The time stepping of a dynamic run (its set-up, e.g. the tree solver, is not needed in
  // statics); made inside the run's try block, so that a numerical failure there ends the run
  // like a failing step.
  std::unique_ptr<integrate::TimeIntegrator> integ;
  // From here on SIGINT and SIGTERM end the run after the step in progress (app/interrupt.hpp).
  const InterruptHandlers interrupts;

  io::RunSummary sum;
  sum.model = o.model_file;
  for (const auto& s : o.overrides) sum.set.push_back(s.key + "=" + s.value);
  sum.formulation = statics ? "static" : dynamic_formulation(m.solver);
  if (restart) {
    sum.restart_file = o.restart_file;
    sum.restart_from_step = o.restart_step;
  }
  sum.n_coordinates = sys.n();
  sum.n_constraints = sys.m_selected() +
                      static_cast<int>(sys.linear_constraints().eliminated.size()) +
                      sys.linear_constraints().multipliers() + tied_coordinates(sys);
  sum.n_redundant_constraints = static_cast<int>(sys.redundant_rows().size());
  sum.dt = m.solver.dt;
  sum.t_end = m.solver.t_end;
  if (!statics && m.solver.integrator == model::Integrator::energy_momentum)
    sum.newton_failed_starts = 0;
  if (!statics) sum.subdivided_steps = 0;
  if (!sys.kl_patches().empty())
    sum.threads = sys.kl_patches().front().element->patch().threads_used();
  if (group->size() > 1) sum.mpi_ranks = group->size();
  // Only the Kirchhoff–Love patches assemble on threads (bodies, beams and director shells on
  // one): a --threads that cannot be used is said, not silently ignored.
  if (o.threads > sum.threads)
    sum.threads_note = sys.kl_patches().empty()
                           ? fmt::format(
                                 "--threads {}: only Kirchhoff-Love shells assemble on "
                                 "threads; this model has none, it ran on 1",
                                 o.threads)
                           : fmt::format(
                                 "--threads {}: the patches ran on {} (one thread per "
                                 "~2000 quadrature points at most)",
                                 o.threads, sum.threads);
  if (sum.threads_note) fmt::print(err, "note: {}\n", *sum.threads_note);
  // Energy is conserved from t = 0 only by a dynamic run without loads of any kind (with
  // actuators: energy + dissipated energy − their work; with joint drivers also − theirs).
  const bool conservative = !statics && m.loads.empty() && m.distributed_loads.empty() &&
                            m.shell_loads.empty() && m.kl_loads.empty();
  sum.max_energy_drift_after_loads = conservative ? 0.0 : std::nan("");
  for (const std::string& w : model::gravity_warnings(m)) fmt::print(err, "warning: {}\n", w);
  // Given velocities that the joints do not admit are replaced by the nearest admissible ones
  // (System::set_initial_velocities): said here as `check` says it, and recorded.
  if (!statics) {
    sum.initial_velocity_projection = sys.initial_velocity_projection_error();
    if (*sum.initial_velocity_projection > 1e-9)
      fmt::print(err,
                 "warning: the initial velocities violate the joints{}; the run starts from the "
                 "nearest admissible ones (relative change {:.3g}, summary.json "
                 "initial_velocity_projection)\n",
                 sys.rheonomic() ? " (or the rates of the prescribed motions at t = 0)" : "",
                 *sum.initial_velocity_projection);
  }

  const auto names = body_names(m);
  integrate::State state;
  // A restarted run's first snapshot is the saved step's, its history row included (the step's
  // Newton figures come from the file); its energy reference stays the energy at t = 0.
  integrate::StepStats first;
  if (restart) {
    state = restart->state;
    first.iterations = restart->newton_iterations;
    first.residual = restart->residual;
  } else {
    state.q = sys.q0();
    state.v = statics ? VecX::Zero(sys.n()) : sys.v0();
  }
  const int first_step = state.step;
  auto snap = integrate::snapshot(sys, state, first, names);
  sum.energy_initial = restart ? restart->energy_initial : snap.total_energy;
  sum.max_constraint_violation = snap.constraint_violation;
  std::optional<RunOutputs> outputs;
  double path = 0.0;  // the path parameter of the last load step (path following)
  // After every step (time step or accepted load step): the summary's figures, the outputs, and
  // the end of the run if a signal came.
  // `next` the step's snapshot, of `state` (a co-simulation: of its multibody part's).
  const auto record_snapshot = [&](const integrate::Snapshot& next, const integrate::StepStats& st,
                                   const integrate::State& state) {
    // Checked before anything of the step is recorded: the outputs end with the last finite step.
    if (const std::string bad = non_finite_results(next, state); !bad.empty())
      throw integrate::NewtonFailure(fmt::format("{} {} (t = {:.6g}): non-finite results: {}",
                                                 statics ? "load step" : "step",
                                                 first_step + sum.steps + 1, state.t, bad));
    snap = next;
    ++sum.steps;
    sum.newton_iterations_total += st.iterations;
    if (sum.newton_failed_starts) *sum.newton_failed_starts += st.failed_starts;
    if (sum.subdivided_steps && st.substeps > 1) ++*sum.subdivided_steps;
    sum.max_constraint_violation =
        std::max(sum.max_constraint_violation, snap.constraint_violation);
    if (conservative)
      sum.max_energy_drift_after_loads =
          std::max(sum.max_energy_drift_after_loads,
                   std::abs(snap.total_energy + snap.dissipated_energy - snap.external_work -
                            snap.driver_work - sum.energy_initial) /
                       std::max(std::abs(sum.energy_initial), 1e-300));
    if (outputs) outputs->snapshot(snap, &state);
    throw_if_interrupted();
  };
  const auto record = [&](const integrate::StepStats& st) {
    integrate::Snapshot next = integrate::snapshot(sys, state, st, names);
    next.path = path;
    record_snapshot(next, st, state);
  };
  const auto t0 = std::chrono::steady_clock::now();
  int code = 0;
  std::string linear;  // static runs: "linear" or "nonlinear"
  // What the run is doing, for an out-of-memory message ("in load step 3 (t = 0.3)").
  std::string doing = "while opening the output files";
  try {
    if (!statics && m.solver.initial_equilibrium > 0 && !restart) {
      doing = "while finding the initial equilibrium";
      const integrate::InitialEquilibrium eq = integrate::initial_equilibrium(m);
      state.q = eq.q;
      state.v.setZero();
      snap = integrate::snapshot(sys, state, {}, names);
      sum.energy_initial = snap.total_energy;
      sum.max_constraint_violation = snap.constraint_violation;
      sum.initial_equilibrium_load_steps = eq.load_steps;
      fmt::print(out, "initial equilibrium: {} load steps, {} Newton iterations\n", eq.load_steps,
                 eq.iterations);
    }
    doing = "while opening the output files";
    io::ResultsFileRun results_file;
    results_file.formulation = sum.formulation;
    results_file.n = sys.n();
    results_file.m = sys.m_selected();
    results_file.energy_initial = sum.energy_initial;
    if (restart) {
      results_file.restart_file = o.restart_file;
      results_file.restart_from_step = o.restart_step;
    }
    if (writes) {
      outputs.emplace(outdir, m, err, &results_file);
      outputs->snapshot(snap, &state);
    }
    if (statics) {
      doing = "while setting up the static solver";
      integrate::StaticEquilibrium equilibrium(sys, m.solver);
      sum.n_unknowns = equilibrium.unknowns();
      sum.dt = m.solver.t_end / equilibrium.settings().steps;
      linear = m.solver.linear ? "linear" : "nonlinear";
      const bool petsc = std::string_view(equilibrium.linear_solver()) != "direct";
      if (petsc) sum.linear_solver = equilibrium.linear_solver();
      if (group->size() > 1 && m.solver.linear_solver == model::LinearSolver::automatic)
        fmt::print(out, "note: {} MPI ranks: solver.linear_solver auto solves with {}\n",
                   group->size(), equilibrium.linear_solver());
      doing =
          fmt::format("in load step 1 (assembling and factorizing {} unknowns)", sum.n_unknowns);
      const integrate::StaticResult result =
          equilibrium.solve([&](const integrate::LoadStepStats& st, const VecX& x) {
            state.q = x.head(sys.n());
            state.lambda = x.segment(sys.n(), sys.m_selected());
            state.t = st.t;
            state.step = st.step;
            path = st.path;
            if (petsc) {
              sum.krylov_iterations_total =
                  sum.krylov_iterations_total.value_or(0) + st.krylov_iterations;
              if (st.linear_solver_fallbacks > 0 && sum.linear_solver_fallbacks.value_or(0) == 0)
                fmt::print(err,
                           "warning: load step {}: {} failed ({}); solved by the direct solver "
                           "(summary.json counts linear_solver_fallbacks)\n",
                           st.step, *sum.linear_solver, st.linear_solver_fallback_reason);
              sum.linear_solver_fallbacks =
                  sum.linear_solver_fallbacks.value_or(0) + st.linear_solver_fallbacks;
            } else if (st.krylov_iterations > 0 || st.saddle_point_fallbacks > 0) {
              sum.krylov_iterations_total =
                  sum.krylov_iterations_total.value_or(0) + st.krylov_iterations;
              sum.saddle_point_fallbacks =
                  sum.saddle_point_fallbacks.value_or(0) + st.saddle_point_fallbacks;
            }
            doing = fmt::format("while recording load step {}", sum.steps + 1);
            record({st.iterations, st.residual, st.cuts + 1});
            doing = fmt::format("in load step {} (assembling and factorizing {} unknowns)",
                                sum.steps + 1, sum.n_unknowns);
          });
      if (!result.stopped.empty()) {
        sum.message = result.stopped;
        fmt::print(err, "warning: {}\n", result.stopped);
      }
    } else if (m.solver.cosimulation) {
      doing = "while setting up the co-simulation";
      integrate::CoSimulation co(m);
      const double H = co.macro_step();
      sum.formulation += fmt::format(", co-simulation (H = {:g}, hold {})", H,
                                     model::to_string(m.solver.cosimulation->hold));
      sum.n_unknowns = co.mbs_unknowns() + co.shell_unknowns();
      const int steps = static_cast<int>(std::lround(m.solver.t_end / H));
      for (int i = 0; i < steps; ++i) {
        doing = fmt::format("in macro step {} (t = {:.6g})", i + 1, co.t() + H);
        const integrate::StepStats st = co.advance();
        record_snapshot(co.snapshot(st), st, co.mbs_state());
      }
    } else {
      doing = "while setting up the time stepping";
      integ = integrate::make_time_integrator(sys, m.solver);
      // Only where reactions.csv is written (a model with joints): the recovery costs a solve.
      integ->set_joint_reactions(m.output.history && m.output.reactions &&
                                 !(m.joints.empty() && m.kl_surface_joints.empty()));
      sum.n_unknowns = integ->unknowns();
      // A restarted run: the steps from its state's t to t_end (on the same grid when dt is the
      // file's, so the step numbers continue).
      const int steps =
          first_step + static_cast<int>(std::lround((m.solver.t_end - state.t) / m.solver.dt));
      for (int i = first_step; i < steps; ++i) {
        doing = fmt::format("in step {} (t = {:.6g}; assembling and factorizing {} unknowns)",
                            i + 1, state.t + m.solver.dt, sum.n_unknowns);
        record(integ->step(state));
      }
    }
  } catch (const integrate::NewtonFailure& e) {
    sum.status = "failed";
    sum.message = std::string(e.what()) + newton_failure_hint(m.solver);
    code = 3;
  } catch (const io::OutputError& e) {
    sum.status = "output_error";
    sum.message = e.what();
    code = kExitOutputError;
  } catch (const Interrupted& i) {
    sum.status = "interrupted";
    sum.message = "interrupted by " + signal_name(i.signal);
    code = exit_code_for_signal(i.signal);
  } catch (const std::runtime_error& e) {
    // A numerical failure outside a Newton iteration (a singular matrix while setting up the
    // integrator or the load stepping): the run fails as a step does, with the cause.
    sum.status = "failed";
    sum.message = fmt::format("numerical failure: {}", e.what());
    code = kExitNewtonFailure;
  } catch (const std::bad_alloc& e) {
    // Out of memory although the estimate fitted (other processes took memory, or the estimate
    // was low): the run fails with what it was doing, the outputs so far stay valid.
    sum.status = "failed";
    sum.message = fmt::format("out of memory {}: {} (the estimate was {}, {})", doing,
                              out_of_memory_cause(e), system::format_bytes(l->memory.total()),
                              l->limit.bytes > 0 ? l->limit.text : "available memory unknown");
    code = kExitNewtonFailure;
  }
  sum.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::vector<std::string> output_errors;
  if (outputs) output_errors = outputs->finish();
  if (code == 0 && !output_errors.empty()) {
    sum.status = "output_error";
    sum.message = output_errors.front();
    code = kExitOutputError;
  }
  sum.energy_final = snap.total_energy;
  if (model::has_material_damping(m)) sum.dissipated_energy = snap.dissipated_energy;
  if (model::has_external_loads(m)) sum.external_work = snap.external_work;
  if (model::has_drivers(m)) sum.driver_work = snap.driver_work;
  sum.probes = snap.probes;
  try {
    if (writes) io::write_summary_json(outdir / "summary.json", sum);
  } catch (const io::OutputError& e) {
    output_errors.push_back(e.what());
    if (code == 0) code = kExitOutputError;
  }
  if (code != 0) {
    const char* prefix = sum.status == "interrupted" ? "" : "error: ";
    if (!outputs)  // the output files could not even be opened
      fmt::print(err, "{}{}\n", prefix, sum.message);
    else if (!sum.message.empty())
      fmt::print(err, "{}{}\n(results up to {}t = {:.6g}, are in {})\n", prefix, sum.message,
                 statics ? fmt::format("load step {}, ", snap.step) : std::string(), snap.t,
                 outdir.string());
    for (const std::string& e : output_errors)
      if (e != sum.message) fmt::print(err, "error: {}\n", e);
    // An output error is rank 0's alone (it writes): the other ranks may wait for it in a sum.
    if (code == kExitOutputError && group->size() > 1) group->abort(code);
    return code;
  }
  if (statics) {
    fmt::print(out,
               "{}: {} load steps, {} unknowns (static, {}), {} Newton iterations, {:.3f} s; "
               "potential energy {:.12g}; max |Phi| {:.2e}; results in {}\n",
               o.model_file, sum.steps, sum.n_unknowns, linear, sum.newton_iterations_total,
               sum.wall_time_s, sum.energy_final, sum.max_constraint_violation, outdir.string());
    for (const auto& p : snap.probes)
      fmt::print(out, "  probe {}: displacement ({:.10g}, {:.10g}, {:.10g})\n", p.name,
                 p.displacement.x(), p.displacement.y(), p.displacement.z());
    return 0;
  }
  fmt::print(out,
             "{}: {} steps, {} unknowns ({}), {} Newton iterations, {:.3f} s; energy {:.12g} -> "
             "{:.12g}; max |Phi| {:.2e}; results in {}\n",
             o.model_file, sum.steps, sum.n_unknowns, sum.formulation, sum.newton_iterations_total,
             sum.wall_time_s, sum.energy_initial, sum.energy_final, sum.max_constraint_violation,
             outdir.string());
  return 0;
}

}  // namespace isoflex::app
