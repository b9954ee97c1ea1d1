#pragma once
// The description of a multibody system as plain data, filled by io::read_model or from C++.
// Geometry given "at t = 0" is in global coordinates of the initial configuration; system::compile
// converts it to body-fixed data. Every entry keeps the source line of its model-file entry (0 when
// built from C++) so that compile-time errors can point back to the file.
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "isoflex/geometry/nurbs_surface.hpp"
#include "isoflex/math/types.hpp"

namespace isoflex::model {

struct Source {
  std::string file;  // empty when built from C++
  int line = 0;      // 1-based, 0 = unknown
};

enum class ShapeKind { none, box, sphere, pyramid, cylinder };

// Drawing shape in body coordinates (centred at the centre of mass unless `offset` is given).
struct Shape {
  ShapeKind kind = ShapeKind::none;
  Vec3 size = Vec3::Zero();    // box: edge lengths along d₁, d₂, d₃
  double radius = 0.0;         // sphere, cylinder (axis d₃)
  double height = 0.0;         // cylinder length; pyramid height (apex along +d₃)
  double base = 0.0;           // pyramid: square base edge
  Vec3 offset = Vec3::Zero();  // body coordinates of the shape's reference point (cylinder and
                               // box centre, pyramid base centre, sphere centre)
};

struct Body {
  std::string name;
  double mass = 0.0;
  Vec3 inertia = Vec3::Zero();   // principal moments J₁, J₂, J₃ about the centre of mass
  Vec3 position = Vec3::Zero();  // centre of mass at t = 0
  Mat3 orientation = Mat3::Identity();   // columns: principal axes d₁, d₂, d₃ at t = 0
  Vec3 velocity = Vec3::Zero();          // of the centre of mass at t = 0
  Vec3 angular_velocity = Vec3::Zero();  // spatial (global components) at t = 0
  Shape shape;
  Source source;
};

enum class JointType {
  spherical,
  revolute,
  prismatic,
  cylindrical,
  planar,
  universal,
  rigid,
  point_on_line,
  fixed
};

// A spring–damper in a revolute or prismatic joint (joints `spring`; elements/revolute_spring.hpp,
// elements/invariant_spring_damper.hpp): the moment −k (θ − θ₀) − c θ̇ about the axis on body_b
// (θ the angle of b relative to a, counted across turns), or the force −k (s − s₀) − c ṡ along the
// axis (s the slide of b's joint point along the axis of a). θ₀, s₀: `free_value` (default 0, the
// configuration at t = 0).
struct JointSpring {
  double stiffness = 0.0, damping = 0.0;
  double free_value = 0.0;
};

// A joint between body_a (the parent side; "ground" for the fixed space) and body_b.
// Location: `point` (global at t = 0) or, alternatively, `point_b` in body-b coordinates (the
// point on body a is then the coincident material point at t = 0).
// Axes (global at t = 0): revolute/cylindrical: rotation axis; prismatic: sliding direction;
// planar: plane normal; universal: `axis` fixed in a and `axis2` fixed in b (perpendicular);
// point_on_line: direction of the line fixed in a through `point`.
struct Joint {
  std::string name;
  JointType type = JointType::spherical;
  std::string body_a = "ground";
  std::string body_b;
  // Joint point: global at t = 0, or in body-a / body-b coordinates (at most one of the three).
  std::optional<Vec3> point;
  std::optional<Vec3> point_a;
  std::optional<Vec3> point_b;
  // Axis: global at t = 0 or in body-a coordinates; second axis (universal): global or in body-b
  // coordinates. Unit vectors.
  std::optional<Vec3> axis;
  std::optional<Vec3> axis_a;
  std::optional<Vec3> axis2;
  std::optional<Vec3> axis2_b;
  // A spherical joint at a point of a Kirchhoff–Love shell (model::kl_surface_joints): body_b is
  // the shell, `point` lies on its surface at (xi, eta), found by point projection.
  std::string kl_shell;
  double xi = 0.0, eta = 0.0;
  std::optional<JointSpring> spring;  // revolute and prismatic joints
  // A prescribed motion (joints `driver`; system/joint_drivers.hpp), time functions (muParser
  // expressions in t): revolute: one, the angle θ(t) of b relative to a about the axis (rad,
  // counted across turns, 0 in the configuration at t = 0, as a spring measures it); prismatic:
  // one, the slide s(t) of b's joint point along the axis (0 at t = 0); spherical with body_a the
  // ground: three, the position (x(t), y(t), z(t)) of the ground point that body_b's point
  // follows (`point` at t = 0). Empty: none.
  std::vector<std::string> driver;
  Source source;
};

// A bushing (elements/invariant_spring_damper.hpp; docs/theory/coupling.md §7): linear 6 × 6
// stiffness and damping between a frame on body_a (or the ground) and one on body_b, both at the
// joint point and with the joint axes of `frame` (a Joint whose type is unused: body_a, body_b,
// point/point_a/point_b, axis/axis_a as the third frame axis, axis2/axis2_b as the first). The
// strains e = (u₁, u₂, u₃, θ₁, θ₂, θ₃): the displacement of b's point from a's and the
// small-rotation measure of b's frame, in a's frame.
struct Bushing {
  std::string name;
  Joint frame;
  Mat<6, 6> stiffness = Mat<6, 6>::Zero(), damping = Mat<6, 6>::Zero();
  Source source;
};

// The frame of a load's components: global (a dead direction), or the body's (node's) director
// frame d₁, d₂, d₃ (a follower load, loads/follower_body_load.hpp).
enum class LoadFrame { global, body };

// A force and/or moment on a body, each component a time function written as an expression in t
// (muParser syntax, e.g. "1000*sin(pi*t)*(t<=2)"). The force acts at a material point given
// globally at t = 0 (`point`) or in body coordinates (`point_local`); default the centre of mass.
struct Load {
  std::string name;
  std::string body;
  std::optional<std::array<std::string, 3>> force;
  std::optional<std::array<std::string, 3>> moment;
  LoadFrame frame = LoadFrame::global;
  std::optional<Vec3> point;
  std::optional<Vec3> point_local;
  Source source;
};

// Cross-section data of a geometrically exact beam (DNSM-III (69), §5.2): stiffnesses for shear
// along d₁, d₂ (GA1, GA2), extension (EA), bending about d₁, d₂ (EI1, EI2), torsion (GJ); mass
// per length A_ρ and the cross-section's mass moments M_ρ¹, M_ρ² (inertia of d₁, d₂).
struct BeamSection {
  double EA = 0, GA1 = 0, GA2 = 0, EI1 = 0, EI2 = 0, GJ = 0;
  double A_rho = 0, M_rho1 = 0, M_rho2 = 0;
  double eta = 0;  // Kelvin–Voigt damping factor η (s): resultant rates η C (Γ̇, K̇)
};

// Initial velocities of the nodes of a beam or a shell: the rigid field
// v(x) = velocity + angular_velocity × (x − velocity_point) at every node (and ω =
// angular_velocity for a node with directors), then per-node values that replace it at their
// nodes (node index as in NAME[k]; all global).
struct NodeVelocities {
  Vec3 velocity = Vec3::Zero(), angular_velocity = Vec3::Zero();
  std::optional<Vec3> velocity_point;
  struct Node {
    int node = 0;
    Vec3 velocity = Vec3::Zero(), angular_velocity = Vec3::Zero();
  };
  std::vector<Node> nodes;
};

// A circular arc or a helix: `start` turned about the axis through `axis_point` along `axis` by
// θ ∈ [0, angle] (radians, right-handed), rising `pitch` along the axis per turn
// (elements::helix_beam_nodes).
struct BeamArc {
  Vec3 axis_point = Vec3::Zero();
  Vec3 axis = Vec3::UnitZ();  // unit
  Vec3 start = Vec3::Zero();
  double angle = 0;  // > 0
  double pitch = 0;
  double radius() const;
  double length() const;  // angle · √(R² + (pitch/2π)²)
  Vec3 end() const;
  Vec3 start_tangent() const;  // unit
};

// A beam along a polyline or an arc/helix, meshed with two-node elements; its nodes are frame
// nodes named "<name>[i]" (i = 0 … node_count() − 1, counted along the centreline) wherever a
// body name is expected (joints, loads, probes).
struct Beam {
  std::string name;
  std::vector<Vec3> points;    // polyline vertices, global at t = 0 (at least 2); empty for an arc
  std::optional<BeamArc> arc;  // the curved centreline instead of the polyline
  std::vector<int> elements;  // elements per segment (points.size() − 1 entries, each ≥ 1; one for
                              // an arc)
  Vec3 d1 = Vec3::UnitZ();  // direction of the director d₁ (made orthogonal to each segment)
  BeamSection section;
  // Cross-section of the cuboids drawn in the VTK output, along d₁ and d₂; 0: 1/50 of the length.
  double draw_width = 0, draw_height = 0;
  NodeVelocities initial;  // velocity_point default: the first node
  Source source;

  int node_count() const {
    int n = 1;
    for (int e : elements) n += e;
    return n;
  }
  Vec3 start_point() const { return arc ? arc->start : points.front(); }
  double length() const;  // of the reference centreline
};

// A dead load per unit reference length on a whole beam, global components as time functions.
struct DistributedLoad {
  std::string name;
  std::string beam;
  std::array<std::string, 3> force_per_length;
  Source source;
};

// --- Shells (Reissner–Mindlin director shells, DNSM-III §4) ---------------------------------

struct ShellMaterial {
  double E = 0, nu = 0, thickness = 0, density = 0;
  double shear_correction = 5.0 / 6.0;
  double eta = 0;  // Kelvin–Voigt damping factor η (s): resultant rates η C (ε̇, κ̇, γ̇)
};

// A shell meshed with bilinear four-node elements; its nodes are director nodes (φ, d) named
// "<name>[i]" (i = 0 … node_count() − 1) wherever a body name is expected. A structured mesh
// (a plate or a sampled surface) numbers its nodes i + (grid_u + 1) j along u first and has the
// edges u0 (i = 0), u1 (i = grid_u), v0 (j = 0) and v1 (j = grid_v).
struct Shell {
  std::string name;
  std::vector<Vec3> points;               // nodes at t = 0
  std::vector<Vec3> directors;            // unit directors at t = 0, one per node
  std::vector<std::array<int, 4>> quads;  // counter-clockwise seen from the directors' side
  int grid_u = 0, grid_v = 0;             // elements along u and v; 0: unstructured
  ShellMaterial material;
  NodeVelocities initial;  // velocity_point default: node 0
  Source source;

  int node_count() const { return static_cast<int>(points.size()); }
  // Nodes of a grid edge ("u0", "u1", "v0", "v1") in order along it; empty if there is none.
  std::vector<int> edge(const std::string& name) const {
    std::vector<int> out;
    if (grid_u <= 0 || grid_v <= 0) return out;
    const int nu = grid_u + 1;
    if (name == "u0" || name == "u1")
      for (int j = 0; j <= grid_v; ++j) out.push_back((name == "u0" ? 0 : grid_u) + nu * j);
    else if (name == "v0" || name == "v1")
      for (int i = 0; i <= grid_u; ++i) out.push_back(i + nu * (name == "v0" ? 0 : grid_v));
    return out;
  }
};

// How a supported shell node's director may turn: freely, not at all, or only about `axis`
// (a symmetry plane with normal `axis`: the director stays in the plane).
enum class DirectorSupport { free, fixed, about_axis };

// A boundary condition on shell nodes: fixed translation components and the director's freedom.
struct ShellSupport {
  std::string shell;
  std::vector<int> nodes;
  std::array<bool, 3> fixed_translation = {false, false, false};
  DirectorSupport director = DirectorSupport::free;
  Vec3 axis = Vec3::Zero();
  Source source;
};

// Loads on a shell, each component a time function of t:
//   nodal: `force` and/or `moment` at each of `nodes` (per node; with per_length, per unit
//     length of the edge the nodes lie along, lumped by the linear shape functions);
//   pressure: dead, along the reference normal (the directors' side), per unit reference area;
//   area_force: a dead force per unit reference area (self-weight, snow load).
struct ShellLoad {
  std::string name;
  std::string shell;
  std::vector<int> nodes;
  bool per_length = false;
  std::optional<std::array<std::string, 3>> force, moment;
  std::optional<std::string> pressure;
  std::optional<std::array<std::string, 3>> area_force;
  Source source;
};

// A named material point whose motion is recorded (probes.csv, summary.json).
// On a Kirchhoff–Love shell (`kl_shell` set instead of `body`) the probe is the material point
// of the mid-surface at the parameters (xi, eta) of `point`.
struct Probe {
  std::string name;
  std::string body;
  std::optional<Vec3> point;        // global at t = 0
  std::optional<Vec3> point_local;  // body coordinates
  std::string kl_shell;
  double xi = 0.0, eta = 0.0;
  Source source;
};

// A spring–damper between two material points (IGA-thesis (6.8)–(6.9); elements/
// point_spring_damper.hpp): each end a point as a probe gives it (a body or node with point or
// point_local, a kl_shell with point) or a fixed point of the ground (body "ground", point). The
// force N = k (ζ − L) + c ζ̇ along the line, ζ the distance; L defaults to ζ at t = 0. Instead of
// k and c, nonlinear laws N(e) (e = ζ − L) and N_d(v) (v = ζ̇) as muParser expressions; an
// actuator adds a force F(t) along the line (all tension > 0).
struct Spring {
  std::string name;
  Probe a, b;  // their names unused
  double stiffness = 0.0, damping = 0.0;
  std::optional<double> free_length;
  std::string stiffness_law, damping_law, actuator;  // expressions in e, v, t; empty: none
  Source source;
};

// --- Surfaces (NURBS geometry for shells, referenced by name) --------------------------------

enum class SurfaceSourceKind { cad, builtin };

// k-refinement of a surface (IGA-thesis §4.2.2): the degree is first raised by elevate[d], then
// knots_per_span[d] knots are inserted uniformly into every non-empty knot span; d = 0 is u (ξ),
// d = 1 is v (η).
struct SurfaceRefinement {
  std::array<int, 2> elevate = {0, 0};
  std::array<int, 2> knots_per_span = {0, 0};
};

// A finding of the analysis-suitability checks (docs/cad-import.md "Checks") on the final
// (refined, placed) surface; findings of severity "error" are rejected when the file is read.
struct SurfaceFinding {
  std::string severity;  // "info" or "warning"
  std::string issue;
  std::string fix;
};

// A named NURBS surface (`surfaces` in the model file): a patch of a CAD file or a built-in
// shape, refined and placed. `surface` is the final geometry that shells will use.
struct Surface {
  std::string name;
  SurfaceSourceKind kind = SurfaceSourceKind::builtin;
  // cad: the file as written in the model file and as opened (resolved against the model file's
  // directory), the patch's index and name in the file, and what the file says about the face.
  std::string cad_file;
  std::string cad_path;
  int cad_patch = 0;
  std::string cad_patch_name;
  bool trimmed = false;               // trimming ignored: `surface` is the untrimmed patch
  bool reversed_orientation = false;  // the face's normal is −(x_u × x_v)
  // builtin: rectangle, cylinder_sector, cylinder, annulus, sphere_sector, spherical_cap,
  // hemisphere or disc.
  std::string builtin_type;
  SurfaceRefinement refine;
  // Placement x ↦ origin + orientation · x, applied after refinement (identity by default).
  Vec3 origin = Vec3::Zero();
  Mat3 orientation = Mat3::Identity();
  geometry::NurbsSurface surface;
  std::vector<SurfaceFinding> findings;
  Source source;

  // Non-empty knot spans in u times those in v.
  int element_count() const {
    return static_cast<int>(surface.u.element_spans().size() * surface.v.element_spans().size());
  }
};

// --- Isogeometric Kirchhoff–Love shells (IGA-thesis ch. 3–4; docs/model-files.md "kl_shells") --

// A Kirchhoff–Love shell patch on a surface of `surfaces`: its control points are the unknowns.
struct KLShell {
  std::string name;
  std::string surface;  // name in Model::surfaces
  double E = 0.0, nu = 0.0, thickness = 0.0, density = 0.0;
  double eta = 0.0;  // Kelvin–Voigt damping factor η (s): S_v = η C Ė (IGA-thesis (3.51))
  std::array<int, 2> quadrature = {0, 0};  // Gauss points per span; 0: degree + 1
  // `seam: open`: two edges of the patch that coincide (a closed patch, e.g. an annulus of 360°)
  // are not joined — the slit annulus of Sze et al. 2004. Default `joined`.
  bool open_seam = false;
  // At the control points (the rigid field moves the whole surface rigidly: NURBS are affine
  // invariant); velocity_point default: control point 0.
  NodeVelocities initial;
  Source source;
};

// Boundary conditions on control points (IGA-thesis §3.3, §4.2.3). On an edge (u0, u1, v0, v1),
// "rows" are the control-point rows parallel to it: row 0 on the edge, row 1 next to it.
//   fixed:     the given components of row 0 (homogeneous Dirichlet, eliminated);
//   clamped:   the given components of rows 0 and 1 (no rotation about the edge);
//   symmetry:  the component along the symmetry plane's normal of rows 0 and 1;
//   displacement: a prescribed displacement ū(t) of the edge, by Lagrange multipliers
//              (3.37)–(3.40), (4.25)–(4.27).
// Without an edge, `control_points` names control points (fixed only).
enum class KLSupportKind { fixed, clamped, symmetry, displacement };
struct KLSupport {
  std::string shell;
  std::string edge;  // empty: control_points
  std::vector<int> control_points;
  KLSupportKind kind = KLSupportKind::fixed;
  std::array<bool, 3> components = {true, true, true};
  Vec3 normal = Vec3::Zero();                              // symmetry
  std::array<std::string, 3> displacement{"0", "0", "0"};  // time functions
  // Dynamic runs: the body the supported control points are attached to (empty: the ground).
  std::string body;
  Source source;
};

// Loads on a Kirchhoff–Love shell (IGA-thesis (3.25)–(3.29)); every component a time function
// of t (a load factor in static analysis). The model's gravity acts on a Kirchhoff–Love shell only
// through a self_weight load, whose factor lets it be stepped like the other loads.
enum class KLLoadKind { area_force, pressure, self_weight, edge_force, edge_moment, point_force };
struct KLLoad {
  std::string name;
  std::string shell;
  KLLoadKind kind = KLLoadKind::area_force;
  std::array<std::string, 3> force{"0", "0", "0"};  // area_force, edge_force, point_force
  std::string pressure = "0";                       // along the normal x_ξ × x_η
  bool follower = false;                            // pressure on the current normal and area
  std::string factor = "1";                         // self_weight: ρ t g × factor(t)
  std::string moment = "0";                         // edge_moment, per unit length, about axis
  Vec3 axis = Vec3::Zero();                         // edge_moment, unit, fixed in space
  std::string edge;                                 // edge_force, edge_moment
  Vec3 point = Vec3::Zero();                        // point_force, a point on the surface
  double xi = 0.0, eta = 0.0;                       // point_force, its projection
  Source source;
};

// How Kirchhoff–Love patches are joined along the edges they share (IGA-thesis §4.4;
// docs/model-files.md "kl_interfaces", docs/theory/multipatch.md). The shared control points are
// one node either way (C⁰, (4.36c)); c0 alone is a hinge (Fig. 6.20b), bending_strip adds the
// penalty strip of §4.4.2 with stiffness E_s = β E, strip_constraints its forces as constraints
// (AF-BS, §5.1; static analyses for now), perturbed_lagrange those rows perturbed by
// −(1/β) λ (5.24b; static analyses), angle the continuity constraints on the triples
// (AF-D, §5.2).
enum class KLCoupling { c0, bending_strip, strip_constraints, perturbed_lagrange, angle };
struct KLInterfacePair {  // the setting of the interfaces between two shells
  std::string a, b;
  KLCoupling coupling = KLCoupling::bending_strip;
  double beta = 1e3;
  Source source;
};
struct KLInterfaces {
  KLCoupling coupling = KLCoupling::bending_strip;
  double beta = 1e3;  // β₁ = E_s / E of the bending strips (4.40), or α₁ of (5.24b)
  // Two points coincide within this times the diagonal of the box of all KL control points.
  double tolerance = 1e-6;
  std::vector<KLInterfacePair> pairs;
  Source source;
};

enum class Formulation { constrained, nullspace, reparametrized };

// The time integrator of a dynamic run (integrate/time_integrator.hpp): the energy–momentum
// schemes (DNSM-III; `formulation` picks one of three) or the index-3 DAE schemes of IGA-thesis
// ch. 2 on the embedded coordinates with multipliers — generalized-α (Alg. 2.1), BDF-1 (2.20),
// BDF-2 (2.21).
enum class Integrator { energy_momentum, generalized_alpha, bdf1, bdf2 };

// What `isoflex run` computes: a motion in time, or static equilibrium under a load parameter
// t ∈ [0, t_end] (`run --static` overrides the model).
enum class Analysis { dynamic, statics };

// Path following of a nonlinear static analysis (integrate/static_newton.hpp): the load factor
// becomes an unknown. `arc_length`: Crisfield's arc length, from a first step of length
// `arc_length` (0: the length of the first load increment dt's tangent predictor) until the load
// factor reaches t_end or after max_steps steps; `displacement`: the displacement of `probe`
// along `direction` is prescribed, `displacement` at t_end, in load steps of dt.
enum class PathMethod { load, arc_length, displacement };

struct PathFollowing {
  PathMethod method = PathMethod::load;
  double arc_length = 0.0;
  double max_arc_length = 0.0;  // the longest step (0: 10 × the first)
  double load_weight = 0.0;     // ψ: the weight of the load factor in the arc length
  int target_iterations = 6;
  int max_steps = 1000;
  std::string probe;
  Vec3 direction = Vec3::UnitZ();  // unit
  double displacement = 0.0;
  int line = 0;  // of the path_following entry in the model file
};

// Co-simulation (IGA-thesis §6.3.2, Fig. 6.8): the Kirchhoff–Love shells and the rest of the
// model integrated by separate integrators, exchanging the positions and velocities of the
// springs' end points every macro step H (serial: the shells first, with the other side's points
// extrapolated from t_k, then the rest, with the shells' points interpolated between t_k and
// t_k + H). integrate/cosimulation.hpp.
enum class CoSimulationHold { constant, linear };

struct CoSimulation {
  double macro_step = 0.0;  // H, a whole multiple of dt
  CoSimulationHold hold = CoSimulationHold::linear;
  int line = 0;  // of the cosimulation entry in the model file
};

// Static solves: how Newton matrices with multiplier rows are solved (integrate/static_newton.hpp
// SaddlePointMethod; automatic: by size).
enum class SaddlePointSolver { automatic, lu, augmented_lagrangian };
// Static solves: how Newton matrices without multiplier rows are solved: CHOLMOD's Cholesky
// (direct), or a PETSc solver (integrate/static_newton.hpp LinearSolverMethod; automatic: by size).
enum class LinearSolver { automatic, direct, cg_gamg, cg_hypre, mumps, cg_multigrid };
// Static solves with cg_multigrid: the first coarse level by fewer knots (h) or a lower degree
// (p, then h; system/kl_multigrid.hpp Coarsening).
enum class MultigridCoarsening { knots, degree };

struct Solver {
  Analysis analysis = Analysis::dynamic;
  Formulation formulation = Formulation::reparametrized;
  Integrator integrator = Integrator::energy_momentum;
  double rho_infinity = 0.8;  // generalized-α: spectral radius at infinite frequency, ρ∞ ∈ [0, 1]
  // Energy–momentum: χ of the algorithmic stress χ C (ΔEₙ₊₁ − ΔEₙ) that damps the second
  // difference of the strains of beams and director shells (docs/theory/schemes.md §10); 0
  // conserves the energy.
  double numerical_dissipation = 0.0;
  bool scaling = true;  // DAE schemes: scaled iteration matrix (IGA-thesis §2.2.4)
  double dt = 1e-2;
  double t_end = 1.0;
  double residual_tolerance = 1e-16;  // ‖R‖∞ relative to max(1, (2/Δt)‖M qₙ‖∞ + ‖M vₙ‖∞)
  double increment_tolerance = 1e-11;  // ‖Δx‖∞ relative to max(1, ‖x‖∞)
  int max_iterations = 25;
  // Energy–momentum, reparametrized: the trust region of a Newton correction, the largest turn
  // (rad) of a director or a frame it may apply; a longer one is shortened (0: no limit;
  // docs/theory/schemes.md §6).
  double max_rotation_correction = 0.1;
  // Energy–momentum: the Newton matrix's geometric part with stresses linearized from the last
  // iterate (mixed integration point Newton, docs/theory/schemes.md §6; director shells); false:
  // with the stresses of the current iterate.
  bool mixed_tangent = true;
  // A time step whose Newton iteration fails is retried as two half steps, at most this many
  // halvings deep (0: never; the run stops at the failing step). On by default: a step too long
  // for Newton (a free-flying beam at Δt = 0.5) is halved rather than ending the run.
  int max_subdivisions = 6;
  // Static solve only: small displacements (one Newton correction from q₀ per load step).
  bool linear = false;
  // Dynamic runs: > 0 starts the run at rest in the static equilibrium under the loads at t = 0,
  // reached in this many load steps (integrate/initial_equilibrium.hpp); 0 starts from the model.
  int initial_equilibrium = 0;
  SaddlePointSolver saddle_point_solver = SaddlePointSolver::automatic;   // static analyses only
  LinearSolver linear_solver = LinearSolver::automatic;                   // static analyses only
  MultigridCoarsening multigrid_coarsening = MultigridCoarsening::knots;  // cg_multigrid only
  PathFollowing path;                                                     // static analyses only
  std::optional<CoSimulation> cosimulation;  // dynamic analyses only; none: monolithic
  // Static analyses: the homogeneous rows of the Kirchhoff–Love supports (symmetry and clamp
  // slopes) tied where a PETSc solver takes the Newton matrix (false, `support_rows: auto`), or
  // always multiplier rows (true, `support_rows: multipliers`).
  bool support_rows_as_multipliers = false;
};

// How the .vtu files hold their arrays: raw bytes in an appended section, or text.
enum class VtkFormat { binary, ascii };

struct Output {
  int vtk_every = 1;  // write a .vtu every k steps (0 = none)
  VtkFormat vtk_format = VtkFormat::binary;
  bool history = true;
  bool reactions = true;     // reactions.csv (with history), the joint reactions
  bool hdf5 = false;         // results.h5 (io/hdf5_results.hpp)
  int hdf5_state_every = 1;  // results.h5 holds the state of every k-th step (and the last)
};

struct Model {
  std::string name;
  std::string file;  // where it was read from, for messages
  Vec3 gravity = Vec3::Zero();
  std::vector<Body> bodies;
  std::vector<Beam> beams;
  std::vector<Joint> joints;
  std::vector<Joint> kl_surface_joints;  // spherical joints at shell points (Joint::kl_shell)
  std::vector<Load> loads;
  std::vector<DistributedLoad> distributed_loads;
  std::vector<Shell> shells;
  std::vector<ShellSupport> shell_supports;
  std::vector<ShellLoad> shell_loads;
  std::vector<Probe> probes;
  std::vector<Spring> springs;
  std::vector<Bushing> bushings;
  std::vector<Surface> surfaces;
  std::vector<KLShell> kl_shells;
  std::vector<KLSupport> kl_supports;
  std::vector<KLLoad> kl_loads;
  KLInterfaces kl_interfaces;
  Solver solver;
  Output output;
};

const char* to_string(JointType t);
std::optional<JointType> joint_type_from_string(const std::string& s);
const char* to_string(Formulation f);
std::optional<Formulation> formulation_from_string(const std::string& s);
const char* to_string(LinearSolver s);
std::optional<LinearSolver> linear_solver_from_string(const std::string& s);
const char* to_string(Integrator i);
const char* to_string(CoSimulationHold h);
std::optional<Integrator> integrator_from_string(const std::string& s);

// At most this many steps (time steps, or load steps of a static analysis) in a run: a run
// writes a row of history.csv per step (≈ 200 bytes), so 10⁸ steps are already ≈ 20 GB; beyond
// the int range the step count would not even be representable.
inline constexpr double kMaxSteps = 1e8;

// What is wrong with the number of steps t_end / dt (rounded) of `s`, "" if nothing: more than
// kMaxSteps, or, in a dynamic analysis, no step at all (t_end < dt / 2; a static analysis takes
// at least one load step). dt and t_end are > 0.
std::string step_count_problem(const Solver& s);
// Where the model's gravity does not act although it might be meant to: rigid bodies, beams and
// director shells carry their weight from their mass data, a Kirchhoff–Love shell only through a
// self_weight load (kl_loads), so a shell with density under gravity and without one gets a
// warning (`check` and `run` print them). Empty without gravity.
std::vector<std::string> gravity_warnings(const Model& m);
// Whether a dynamic run of `m` dissipates through material damping (eta > 0 in a kl_shells or
// shells material or a beam section) or dampers (springs with damping > 0 or a damping law,
// bushings with a damping matrix, joints with a damping spring): history.csv gets the
// dissipated_energy column.
bool has_material_damping(const Model& m);
// Whether some spring has an actuator (a force prescribed in time).
bool has_actuators(const Model& m);
// Whether a dynamic run has external loads (loads, distributed_loads, shell_loads, kl_loads,
// actuators): history.csv then gets `external_work`, their work since t = 0.
bool has_external_loads(const Model& m);
// Whether a dynamic run has joint drivers (joints `driver`): history.csv then gets
// `driver_work`, the work of the prescribed motions since t = 0.
bool has_drivers(const Model& m);
// Number of constraints m and relative degrees of freedom r of a joint between two frame nodes.
int joint_constraint_count(JointType t);

}  // namespace isoflex::model
