#pragma once
// The compiled system (docs/architecture.md, "system"): DOF layout, elements, loads, joints, the
// constraint graph with its spanning forest, and the assembly of every quantity the integrators
// need. Nodes: the bodies (node i is body i) and the beam nodes are frame nodes (12 coordinates,
// DNSM-III (16)); shell nodes are director nodes (6 coordinates, (40)). What a node kind is
// (coordinates, internal rows, twist form, update map): math/node_kind.hpp.
//
// Layouts
//   q ∈ Rⁿ: node i occupies q[q_offset(i), q_offset(i) + coordinate_count(i)), in node order.
//   Constraint rows ("all rows"): the internal rows of every node in node order (6 for a frame
//   node (20), 1 for a director node (41)), then every joint's rows in model order. Selected
//   rows: internal, tree joints, and the independent rows of the loop-closing joints; redundant
//   rows are kept out of every system that is solved.
//   Twists: t ∈ R^{6N}, (φ̇, ω) per node (joints/joint.hpp); a director node's P_int is
//   [I 0; 0 −d̂] (68).
//   ν ∈ Rᵏ (tree coordinates): for each root node its free velocities (a twist (6) for a frame
//   node, (φ̇, θ̇₁, θ̇₂) (47) for a director node), then τ (r entries) for each tree joint.
//   q̇ = P_tree(q) ν with P_tree = P_int · E (DNSM-III (57), Table 3 iii.1(a)).
#include <Eigen/SparseCore>
#include <array>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "isoflex/elements/beam_element.hpp"
#include "isoflex/elements/director_shell_element.hpp"
#include "isoflex/elements/element.hpp"
#include "isoflex/elements/kl_patch_element.hpp"
#include "isoflex/joints/constraint.hpp"
#include "isoflex/joints/frame_joint.hpp"
#include "isoflex/joints/joint.hpp"
#include "isoflex/loads/load.hpp"
#include "isoflex/model/model.hpp"
#include "isoflex/system/compile_error.hpp"
#include "isoflex/system/global_matrix.hpp"
#include "isoflex/system/kl_interfaces.hpp"
#include "isoflex/system/linear_constraints.hpp"

namespace isoflex::system {

using SpMat = Eigen::SparseMatrix<double>;
using Triplets = std::vector<Eigen::Triplet<double>>;

struct JointInstance {
  std::string name;
  std::string type;  // as in the model file ("revolute", "shell_intersection", …)
  std::shared_ptr<const joints::Joint> joint;
  const joints::FrameJoint* frame = nullptr;  // the same joint when it joins two frame nodes
  int parent = -1;  // node index, −1 = ground (the parent side of `joint`)
  int child = -1;
  bool tree = false;      // eliminated explicitly by the spanning forest
  bool reversed = false;  // parent/child swapped relative to body_a/body_b of the model
  int row_offset = 0;     // first row in the all-rows layout
  int nu_offset = -1;     // tree joints: first entry of τ in ν
  // The same rows as a Constraint over (parent, child) (joints/joint_rows.hpp).
  std::shared_ptr<const joints::Constraint> rows;
  // Its driver (joints `driver`, system/joint_drivers.hpp): a revolute or prismatic joint's
  // driver row, an n-ary constraint (index into System::nary_constraints(); −1: none). A
  // spherical joint whose ground point moves has rheonomic rows itself (rows->rheonomic()) and
  // is never a tree joint.
  int driver = -1;
};

// An n-ary constraint (joints/constraint.hpp): rows over any set of nodes, always loop-closing
// ("cut") rows, after the joints' rows.
struct ConstraintInstance {
  std::string name;
  std::string type;
  std::shared_ptr<const joints::Constraint> constraint;
  int row_offset = 0;    // first row in the all-rows layout
  model::Source source;  // where the model states it
};

// A beam of the model: its nodes along the polyline and its elements (owned by the system).
struct BeamInstance {
  std::string name;
  std::vector<int> nodes;
  std::vector<const elements::BeamElement*> elements;
};

// A shell of the model: its director nodes (model numbering) and its elements.
struct ShellInstance {
  std::string name;
  std::vector<int> nodes;
  std::vector<const elements::DirectorShellElement*> elements;
};

// A Kirchhoff–Love patch of the model: one point node per control point (surface numbering) and
// its element (its loads are one loads::PatchLoadSet among System::loads()).
struct KLPatchInstance {
  std::string name;
  std::vector<int> nodes;
  const elements::KLPatchElement* element = nullptr;
  int element_index = -1;  // in System::elements()
  // Knots or degree were added to join it to a neighbour: its control points are numbered
  // differently from the model's surface.
  bool renumbered = false;
};

// An interface between two Kirchhoff–Love patches, or of one patch with itself along its seam
// or a C⁰ knot line (a == b; system/kl_interfaces.hpp): its shared control points are one node
// (C⁰); a bending strip, if the coupling has one, is an element over its triples.
struct KLInterfaceInstance {
  std::string a, b;  // the shells
  KLInterface geometry;
  // The system nodes of the triples, (inner a, shared, inner b) per triple along the edge.
  std::vector<int> triple_nodes;
  model::KLCoupling coupling = model::KLCoupling::c0;
  double beta = 0.0;       // E_s / E of the strip (bending_strip)
  double young = 0.0;      // E_s of the strip
  int element_index = -1;  // the strip in System::elements(), −1 for none
  // strip_constraints, angle: its rows, an n-ary constraint (System::nary_constraints()), −1 for
  // none
  int constraint_index = -1;
  // angle in a static analysis: the straight triples, whose G¹ rows (5.36) are tied rows of the
  // linear conditions (eliminated by substitution); the kinked ones are the constraint's
  int tied_triples = 0;
};

// How the Kirchhoff–Love patches were joined: the tolerance of coincidence, what was refined
// to make interfaces conforming, and the seams left open (kl_shells `seam: open`).
struct KLJoiningReport {
  double tolerance = 0.0;
  std::vector<std::string> refinements;
  std::vector<std::string> open_seams;
};

// A material point followed by a probe: X in the coordinates of `node`, or (KL patches) the
// combination Σ w φ of control points given by `weights` (node, R_A(ξ, η)).
struct ProbeInstance {
  std::string name;
  int node = -1;
  Vec3 X = Vec3::Zero();
  std::vector<std::pair<int, double>> weights;
};

// A joint at a Kirchhoff–Love shell point (n-ary constraint `constraint`): the shell's material
// point Σ w x_A over (node, w), where its reaction is reported (system/joint_reactions.hpp), and
// the body's frame node (−1: the ground).
struct ShellPointJointInstance {
  int constraint = -1;
  std::vector<std::pair<int, double>> point;
  int body = -1;
};

// A spring–damper of the model: its element in System::elements() (elements::PointSpringDamper)
// and its actuator in System::loads() (loads::LineActuator; −1: none).
// A spring–damper between two frames (system_frame_springs.cpp): a joint's spring (revolute:
// elements::RevoluteSpring; prismatic: a one-strain elements::InvariantSpringDamper) or a bushing
// (six strains u₁ u₂ u₃ θ₁ θ₂ θ₃), reported in forces.csv under `name`.
struct FrameSpringInstance {
  enum class Kind { revolute, prismatic, bushing };
  std::string name;
  int element_index = -1;
  Kind kind = Kind::revolute;
  double free_value = 0.0;  // prismatic: the free slide s₀
};

struct SpringInstance {
  std::string name;
  int element_index = -1;
  int actuator_load = -1;
  int ground_end = -1;  // 0 (a) or 1 (b) when that end is a point of the ground
};

class System {
 public:
  static System compile(const model::Model& model);

  // Sizes
  int node_count() const { return static_cast<int>(nodes_.size()); }
  NodeKind node_kind(int i) const { return nodes_[i].type->kind(); }
  const NodeType& node_type(int i) const { return *nodes_[i].type; }
  int node_count(NodeKind kind) const { return kind_count_[static_cast<int>(kind)]; }
  int q_offset(int i) const { return nodes_[i].q_offset; }
  int coordinate_count(int i) const { return nodes_[i].type->coordinates(); }
  int internal_row_offset(int i) const { return nodes_[i].row_offset; }
  int internal_row_count(int i) const { return nodes_[i].type->internal_rows(); }
  int internal_rows() const { return internal_rows_; }
  bool frame_nodes_only() const { return node_count(NodeKind::frame) == node_count(); }
  const std::vector<int>& root_widths() const { return root_width_; }
  int n() const { return static_cast<int>(q0_.size()); }
  int m_all() const { return m_all_; }
  int m_selected() const { return static_cast<int>(selected_rows_.size()); }
  int k() const { return k_; }  // tree coordinates
  int cut_rank() const { return static_cast<int>(cut_rows_.size()); }
  int dof() const { return k_ - cut_rank(); }  // degrees of freedom n − m
  const std::vector<int>& selected_rows() const { return selected_rows_; }
  const std::vector<int>& cut_rows() const { return cut_rows_; }  // selected rows of cut joints
  // Per selected row, the compliance c of a perturbed Lagrange row, Φ − c λ = 0
  // (joints/constraint.hpp); 0 for every other row.
  const VecX& selected_compliance() const { return selected_compliance_; }
  // Per constraint whose rows are reselected at every Newton iterate
  // (joints::Constraint::reselected()): their positions in selected_rows() and how many are
  // independent at the reference modulo the linear conditions, and which (indices into positions,
  // sorted: system::select_group_rows at q0, all groups together). Empty for most models.
  struct ReselectedGroup {
    int constraint = -1;  // in nary_constraints()
    std::vector<int> positions;
    int rank = 0;
    std::vector<int> reference_rows;
  };
  const std::vector<ReselectedGroup>& reselected_groups() const { return reselected_groups_; }
  // G with the eliminated coordinates' columns zeroed and projected off the rows of the linear
  // conditions (the row selection of a static analysis, at compile and at every iterate).
  SpMat modulo_linear_conditions(const SpMat& G) const;
  // Per reselected group, the Jacobian of its rows at q modulo the linear conditions (what
  // system::select_group_rows chooses from).
  std::vector<SpMat> reselected_group_jacobians(const VecX& q) const;
  const std::vector<int>& redundant_rows() const { return redundant_rows_; }
  const std::vector<JointInstance>& joints() const { return joints_; }
  const std::vector<ConstraintInstance>& nary_constraints() const { return nary_; }
  const std::vector<int>& roots() const { return roots_; }
  const std::vector<std::unique_ptr<elements::Element>>& elements() const { return elements_; }
  // Every external load, of every node kind, behind one contract (loads/load.hpp).
  const std::vector<std::shared_ptr<const loads::Load>>& loads() const { return loads_; }
  const std::vector<int>& root_nu_offsets() const { return root_nu_offset_; }
  const std::vector<int>& tree_order() const { return tree_order_; }  // parents before children
  // Coordinates of a node (−1: the ground frame), a view into q.
  joints::Joint::CRef node_q(const VecX& q, int node) const;
  // Which joint (index) or −1 (internal or an n-ary constraint) a row belongs to.
  int joint_of_row(int row) const;
  // The rows of n-ary constraint c (index into nary_constraints()) kept as independent (for rows
  // reselected at every iterate: how many are kept, the count at the reference).
  int independent_rows_of(int c) const;
  // Which n-ary constraint (index into nary_constraints()) or −1 a row belongs to.
  int nary_of_row(int row) const;
  // Independent cut rows found by pivoted QR (must agree in count with the LU selection).
  int cut_rank_qr() const { return cut_rank_qr_; }
  // ‖E ν₀ − t_given‖ / max(1, ‖t_given‖): how far the given initial velocities were from
  // admissible.
  double initial_velocity_projection_error() const { return v0_error_; }

  // Initial state.
  const VecX& q0() const { return q0_; }
  const VecX& v0() const { return v0_; }
  const SpMat& mass() const { return M_; }  // zero (no entries) in a static analysis

  // Potential energy (conservative: gravity, elastic).
  double potential(const VecX& q) const;
  // f = DV(qₙ, qₙ₊₁) − f_ext(q_{n+½}, t); K (if not null) receives ∂f/∂qₙ₊₁.
  VecX discrete_force(const VecX& qn, const VecX& qn1, double t_mid, SpMat* K) const;
  // The mixed integration point Newton iteration (docs/theory/schemes.md §6): f as
  // discrete_force; K with the elements' geometric parts at estimated stresses
  // (Element::mixed_discrete_gradient_in_pattern: strains linearized at q_lin, or qₙ's at a
  // Newton start, q_lin null); stress_force (size n) the force of those stresses less f's.
  VecX mixed_discrete_force(const VecX& qn, const VecX& qn1, const VecX* q_lin, double t_mid,
                            SpMat* K, VecX& stress_force) const;
  // Statics (and the DAE integrators): f = ∇V(q) − f_ext(q, t); K (if not null) receives
  // ∂f/∂q = ∇²V − ∂f_ext/∂q in the same fixed pattern; load_norm (if not null) ‖f_ext(q, t)‖∞.
  VecX static_force(const VecX& q, double t, SpMat* K, double* load_norm = nullptr) const;
  // The external forces alone, f_ext(q, t) (their work: history.csv's external_work).
  VecX external_force(const VecX& q, double t) const;
  // A converged configuration (time or load step): the elements keep their history from it
  // (Element::accept: the turns of a revolute spring). Called by the integrators and the static
  // solver after every converged step.
  void accept(const VecX& q) const;
  // Whether some element has viscous forces (Kelvin–Voigt material damping, IGA-thesis §3.5).
  bool viscous() const { return viscous_; }
  // The elements' viscous forces f_v(q, q̇) (q̇ the time derivative of q; IGA-thesis (3.55)); K
  // (if not null, already in the pattern of stiffness_pattern(), e.g. from discrete_force or
  // static_force) receives cq ∂f_v/∂q + cv ∂f_v/∂q̇ added to its values. The energy–momentum
  // schemes evaluate it at (q_{n+½}, Δq/Δt) with cq = ½, cv = 1/Δt; the DAE schemes at (q, q̇(q))
  // with cq = 1, cv = γ′ (IGA-thesis (2.27), C_t).
  VecX viscous_force(const VecX& q, const VecX& qdot, double cq, double cv, SpMat* K) const;
  // Whether some element can damp its strains numerically (Element::strain_dissipation).
  bool strain_dissipation() const { return strain_dissipation_; }
  // The elements' algorithmic dissipative forces f_d(qₙ₋₁, qₙ, qₙ₊₁) of the energy–momentum
  // step with numerical dissipation χ (docs/theory/schemes.md §10); K (if not null, in the pattern
  // of stiffness_pattern()) += ∂f_d/∂qₙ₊₁.
  VecX strain_dissipation_force(const VecX& q_prev, const VecX& qn, const VecX& qn1, double chi,
                                double ratio, SpMat* K) const;
  // The same with the mixed tangent (mixed_discrete_force); stress_force (size n) += the force of
  // the estimated stresses less f_d's.
  VecX mixed_strain_dissipation_force(const VecX& q_prev, const VecX& qn, const VecX& qn1,
                                      const VecX* q_lin, double chi, double ratio, SpMat* K,
                                      VecX& stress_force) const;
  // The generalized external loads f_ext(q, t) (positive: the force the loads exert).
  VecX load_force(const VecX& q, double t) const;

  // Constraints at time t, all rows: Φ(q) − d(t), d(t) the right-hand sides of the rheonomic
  // rows (joints/constraint.hpp) and 0 elsewhere.
  VecX constraints(const VecX& q, double t) const;
  // True when some row depends on t.
  bool rheonomic() const { return rheonomic_; }
  // d(t) of all rows (0 for the rows that do not depend on t): constraints(q, t) = Φ(q) − d(t).
  // A step's prescribed motions do the work −λ·(d(tₙ₊₁) − d(tₙ)) over the selected rows
  // (history.csv driver_work).
  VecX prescribed(double t) const;
  // (vᵀ ∇²Φᵢ(q) v)ᵢ of the selected rows: the velocity term of the rows' second derivative,
  // G q̈ + (vᵀ∇²Φᵢ v)ᵢ = d̈ (the DAE schemes' consistent start). Exact: (G(q + v) − G(q)) v for
  // the rows at most quadratic, the Hessian for the others (a driven angle).
  VecX constraint_curvature(const VecX& q, const VecX& v) const;
  // Jacobian of the selected rows (m_selected × n) or of the given rows.
  SpMat jacobian(const VecX& q) const;
  SpMat jacobian_rows(const VecX& q, const std::vector<int>& rows) const;
  // The discrete derivative G̃(q_a, q_b) of the selected or the given rows
  // (joints/constraint.hpp): G(½(q_a + q_b)) for the rows at most quadratic.
  SpMat discrete_jacobian(const VecX& qa, const VecX& qb) const;
  SpMat discrete_jacobian_rows(const VecX& qa, const VecX& qb, const std::vector<int>& rows) const;
  // Σ λᵢ ∂²Φᵢ/∂q² at q over selected rows (λ in selected order), n × n.
  SpMat constraint_hessian(const VecX& q, const VecX& lambda_selected) const;

  // Tree null space P_tree(q) (n × k): G_tree(q) P_tree(q) = 0 for every q.
  SpMat tree_null_space(const VecX& q) const;
  // An upper bound of |P_tree(q)|ᵀ t (t ≥ 0, entrywise absolute values, k) in one
  // leaves-to-root sweep: the products of the absolute blocks along each node's path.
  VecX abs_tree_null_space_transpose_bound(const VecX& q, const VecX& t) const;
  // Twist-level map E(q) (6·nodes × k) with t = E ν.
  SpMat twist_map(const VecX& q) const;
  // Nodal reparametrization q_{n+1} = F_{qₙ}(u), u ∈ Rᵏ (DNSM-III (14), (37), joint updates).
  VecX update(const VecX& qn, const VecX& u) const;
  // The same into q, with `step` (the nodes' rotations over the step) as workspace: no heap
  // allocation once both have their sizes (a Newton iteration).
  // With `increment`, also q − qn without subtracting rounded coordinates: the free nodes' parts
  // from NodeType::root_update, those of the nodes below joints composed down the tree from their
  // parents' (Joint::update with a StepIncrement). The step's velocities come from it
  // (integrate/energy_momentum.cpp). `step_increment`: workspace for the nodes' rotations over
  // the step less the identity (a local vector if null).
  void update(const VecX& qn, const VecX& u, VecX& q, std::vector<Mat3>& step,
              VecX* increment = nullptr, std::vector<Mat3>* step_increment = nullptr) const;
  // The tree coordinates ν that are rotations, for the trust region of a reparametrized Newton
  // correction (integrate/energy_momentum.cpp): the rotation increments of free frames and
  // directors and the joint velocities that turn the child (a column of the freedom block with
  // an angular part, at q₀).
  const std::vector<int>& rotation_tree_coordinates() const { return rotation_nu_; }
  // Overwrites the entries of u that belong to free nodes whose kind extrapolates a step at
  // constant velocity (NodeType::extrapolate: a director node its position only, its rotation
  // keeps the last step's increments).
  void extrapolate_increments(const VecX& q, const VecX& v, double dt, VecX& u) const;
  // The increments u of a step from qn to q1 rewritten in the bases of q1, for the free nodes
  // (NodeType::transport_increments).
  void transport_increments(const VecX& qn, const VecX& q1, VecX& u) const;
  // ∂F/∂u = P_int(q_{n+1}) (I − 𝒜(q_{n+1}))⁻¹ ℬ̃(qₙ, u), with q1 = update(qn, u) (the caller has
  // it already).
  SpMat update_derivative(const VecX& qn, const VecX& q1, const VecX& u) const;
  // ℬ̃(qₙ, u) (6N × k): ℬ at q1 = F_{qₙ}(u) with rotation-vector columns multiplied by T(θ) and
  // director tangent bases taken at tₙ (joints/joint.hpp, update_freedom_block).
  SpMat update_input_map(const VecX& qn, const VecX& q1, const VecX& u) const;

  // Factors of the tree null space without forming it: (I − 𝒜(q)) t = ℬ(q) ν, so
  // P_tree = P_int (I − 𝒜)⁻¹ ℬ. `L` = I − 𝒜 (6N × 6N), `B` = ℬ (6N × k), `Pint` (n × 6N).
  // With them the reduced Newton systems are solved in an equivalent sparse bordered form whose
  // size grows linearly with the number of bodies (integrate/energy_momentum.cpp).
  void tree_factors(const VecX& q, SpMat& L, SpMat& B, SpMat& Pint) const;
  // 𝖯ᵀ r = ℬᵀ (I − 𝒜)⁻ᵀ P_intᵀ r by one sweep from the leaves to the roots.
  VecX reduce(const VecX& q, const VecX& r) const;
  // The same into out, with y (the nodes' twist forces, 6N) as workspace.
  void reduce(const VecX& q, const VecX& r, VecX& out, VecX& y) const;

  // Momentum maps: p = Σ (M v)_φ, L = Σ_blocks q_k × (M v)_k (docs/theory).
  Vec3 linear_momentum(const VecX& v) const;
  Vec3 angular_momentum(const VecX& q, const VecX& v) const;

  const std::vector<ProbeInstance>& probes() const { return probes_; }
  // The spring–dampers (model springs) and their elements in elements().
  const std::vector<SpringInstance>& springs() const { return springs_; }
  const std::vector<FrameSpringInstance>& frame_springs() const { return frame_springs_; }
  const std::vector<ShellPointJointInstance>& shell_point_joints() const {
    return shell_point_joints_;
  }
  // Moves the ground end of spring s (springs()[s].ground_end ≥ 0) to `point`, moving at
  // `velocity` (seen by its damper): the anchor a co-simulation gives the other side's point
  // (integrate/cosimulation.hpp). Between steps only.
  void move_spring_anchor(int s, const Vec3& point, const Vec3& velocity);
  // The probe's material point in q (its velocity: the same map applied to v).
  Vec3 probe_point(const VecX& q, const ProbeInstance& p) const;
  // The gradient of direction · probe_point(q) as (coordinate, value) pairs: constant, as every
  // material point is linear in its node's coordinates (φ + Xᵢ dᵢ, DNSM-III (38); a KL point
  // Σ R_A x_A).
  std::vector<std::pair<int, double>> probe_gradient(const ProbeInstance& p,
                                                     const Vec3& direction) const;
  const std::vector<KLPatchInstance>& kl_patches() const { return kl_patches_; }
  const std::vector<KLInterfaceInstance>& kl_interfaces() const { return kl_interfaces_; }
  // The patch of kl_shells entry `shell` (std::logic_error if there is none).
  const KLPatchInstance& kl_patch_of(const std::string& shell) const;
  const KLJoiningReport& kl_joining() const { return kl_joining_; }
  // Linear conditions on q handled by the static solver (eliminated coordinates and multiplier
  // rows: the Kirchhoff–Love supports to the ground of a static analysis), not in constraints().
  const LinearConstraints& linear_constraints() const { return linear_; }
  // Threads of the Kirchhoff–Love patch assembly (elements::KLShellPatch::set_threads; results do
  // not depend on it).
  void set_threads(int threads);
  // Whether the patches keep their constant linear tangent between evaluations
  // (elements::KLShellPatch::set_keep_linear_tangent; results do not depend on it).
  void keep_linear_tangent(bool keep);
  // The elements of every Kirchhoff–Love patch that this process sums into static_force: part
  // `part` of `parts` (elements::KLShellPatch::set_partition; an MPI run, docs/theory/solvers.md
  // §6). The other elements (the interfaces' bending strips) are summed by part 0 alone. The
  // static problem then sums the processes' forces (integrate/static_equilibrium.hpp).
  void partition_kl_patches(int part, int parts);
  // The number of parts of partition_kl_patches (1: each process assembles every element).
  int kl_parts() const;
  // The fixed pattern of discrete_force's K.
  const GlobalMatrix& stiffness_pattern() const { return stiffness_; }
  const std::vector<BeamInstance>& beams() const { return beams_; }
  const std::vector<ShellInstance>& shells() const { return shells_; }
  const std::string& node_name(int i) const { return node_names_[i]; }
  // The coordinates of the given nodes, stacked (an element's q).
  VecX stacked(const VecX& q, const std::vector<int>& nodes) const;
  // Stacked coordinates (24) of element e of beam b.
  VecX beam_element_q(const VecX& q, int b, int e) const;
  Vec3 material_point(const VecX& q, int node, const Vec3& X) const;

  std::string describe_forest(const model::Model& model) const;

 private:
  struct Node {
    const NodeType* type;
    int q_offset;
    int row_offset;  // first internal row
  };
  // ℬ blocks: per root (6 × width) and per tree joint (6 × r, empty for others).
  struct InputBlocks {
    std::vector<MatX> root, joint;
  };
  InputBlocks input_blocks(const VecX& q) const;
  InputBlocks update_input_blocks(const VecX& qn, const VecX& q1, const VecX& u) const;
  SpMat twist_map(const VecX& q, const InputBlocks& in) const;
  // Each node's twist as blocks over its tree path: (first column in ν, 6 × w block of E).
  using TwistBlocks = std::vector<std::vector<std::pair<int, MatX>>>;
  TwistBlocks twist_blocks(const VecX& q, const InputBlocks& in) const;
  // The global coordinates of the given nodes, stacked.
  std::vector<int> coordinates_of(const std::vector<int>& nodes) const;
  using ElementKernel =
      std::function<VecX(const elements::Element&, const std::vector<int>& nodes, double* values)>;
  // Every element, whose kernel overwrites its matrix values; or only the viscous elements
  // (Element::viscous), whose kernel adds to them.
  enum class Kernels { all_overwriting, viscous_adding, strain_dissipation_adding };
  // global += the node blocks of `local`, a vector of the stacked coordinates of `nodes`.
  void add_stacked(const std::vector<int>& nodes, const VecX& local, VecX& global) const;
  // f += the kernel's vector per element, K += its matrix values (fixed pattern).
  void add_element_forces(const ElementKernel& kernel, VecX& f, SpMat* K,
                          Kernels kernels = Kernels::all_overwriting) const;
  void add_load_forces(const VecX& q, double t, double c, VecX& f, SpMat* K, VecX* fext) const;
  // The kernel's element forces and the loads at the midpoint (discrete_force and its mixed
  // variant), K reset to the fixed pattern first.
  VecX midpoint_forces(const ElementKernel& kernel, const VecX& qn, const VecX& qn1, double t_mid,
                       SpMat* K) const;
  // Compile phases (system_compile.cpp), in this order; Build carries what they pass on.
  struct Build;
  void add_bodies(Build& build);
  void add_beams(Build& build);
  void add_shells(Build& build);
  void add_kl_patches(const model::Model& m);  // system_kl_patches.cpp
  // Each patch's element made anew on a copy of its patch (sharing the data) that `set` adjusts.
  void configure_kl_patches(const std::function<void(elements::KLShellPatch&)>& set);
  void add_kl_couplings(const model::Model& m);
  void finish_nodes(Build& build);
  void assemble_mass();
  void add_body_loads(Build& build);
  void add_distributed_loads(Build& build);
  void add_shell_loads(Build& build);
  void add_probes(Build& build);
  // A system node by the name of a body or beam/shell node (−1: the ground); throws a located
  // CompileError for an unknown name.
  using NodeFinder =
      std::function<int(const std::string&, const model::Source&, const std::string&)>;
  void add_springs(const model::Model& m, const NodeFinder& find);  // system_springs.cpp
  // Bushings and the springs of revolute and prismatic joints (system_frame_springs.cpp).
  void add_frame_springs(const model::Model& m, const NodeFinder& find);
  // The driver rows of revolute and prismatic joints as n-ary constraints
  // (system_frame_springs.cpp, system/joint_drivers.hpp); driver_of_joint[j]: the constraint of
  // model joint j or −1.
  void add_joint_drivers(const model::Model& m, const NodeFinder& find,
                         std::vector<int>& driver_of_joint);
  void add_joint_edges(Build& build);
  void add_shell_supports(Build& build);
  void add_kl_supports(Build& build);
  void add_kl_surface_joints(Build& build);
  void add_linear_constraints(const LinearConstraints& local, const std::vector<int>& nodes);
  void add_kl_support_rows(const model::Model& model, const model::KLSupport& S,
                           const std::string& what, const KLPatchInstance& P);
  void build_forest(Build& build);
  std::shared_ptr<const joints::Joint> model_joint(const Build& build, std::size_t j, int parent,
                                                   int child, bool rev) const;
  std::shared_ptr<const joints::Joint> frame_joint(const Build& build, std::size_t j, int parent,
                                                   int child, bool rev) const;
  void add_joint_instances(Build& build);
  void mark_rotations();
  void check_assembled(const Build& build) const;
  void select_loop_rows();
  void set_initial_velocities(const model::Model& model);
  ProbeInstance kl_probe(const model::Probe& p) const;
  void build_stiffness_pattern();
  // A joint with a shell node on either side (joints/director_joints.hpp).
  std::shared_ptr<const joints::Joint> director_joint(const model::Joint& J, int parent, int child,
                                                      const std::string& what) const;
  SpMat internal_null_space(const VecX& q) const;  // P_int (n × 6N)
  // Node coordinates of a material point given globally at t = 0 or in node coordinates
  // (default: the node's origin, a body's centre of mass).
  Vec3 body_coordinates(int node, const std::optional<Vec3>& global,
                        const std::optional<Vec3>& local) const;
  void add_node(NodeKind kind, const VecX& q0, const std::string& name, int beam);
  // f(constraint, first row) for the joints' rows, then the n-ary constraints.
  template <class F>
  void for_each_constraint(F&& f) const;
  // The Jacobian rows `rows`, each constraint's block from block(C), the nodes' rows at qm.
  template <class Block>
  SpMat assemble_rows(const VecX& qm, const std::vector<int>& rows, Block&& block) const;

  std::vector<Node> nodes_;
  int internal_rows_ = 0;
  std::array<int, kNodeKinds> kind_count_{};
  std::vector<int> root_width_;
  std::vector<std::unique_ptr<elements::Element>> elements_;
  std::vector<std::shared_ptr<const loads::Load>> loads_;
  std::vector<ShellInstance> shells_;
  std::vector<KLPatchInstance> kl_patches_;
  std::vector<KLInterfaceInstance> kl_interfaces_;
  KLJoiningReport kl_joining_;
  LinearConstraints linear_;
  // discrete_force's K: the fixed pattern and the part of each element and load.
  GlobalMatrix stiffness_;
  std::vector<int> element_part_, load_part_;
  // partition_kl_patches: the elements that this process leaves to part 0 (empty: none).
  std::vector<bool> elements_of_part_0_;
  std::vector<double> q0_build_;  // q₀ while nodes are added (compile)
  std::vector<JointInstance> joints_;
  std::vector<FrameSpringInstance> frame_springs_;
  std::vector<ShellPointJointInstance> shell_point_joints_;
  std::vector<ConstraintInstance> nary_;
  std::vector<int> tree_order_;  // joint indices, parents before children
  std::vector<int> roots_;
  std::vector<int> root_nu_offset_;
  std::vector<int> rotation_nu_;
  std::vector<int> selected_rows_, cut_rows_, redundant_rows_;
  VecX selected_compliance_;
  std::vector<ReselectedGroup> reselected_groups_;
  std::vector<ProbeInstance> probes_;
  std::vector<SpringInstance> springs_;
  std::vector<BeamInstance> beams_;
  std::vector<std::string> node_names_;  // body name or "<beam>[i]"
  std::vector<int> node_beam_;  // beam index (shells: after the beams) of a node, −1 for a body
  int m_all_ = 0, k_ = 0, cut_rank_qr_ = 0;
  double v0_error_ = 0.0;
  bool rheonomic_ = false;           // some row depends on t
  bool viscous_ = false;             // some element has viscous forces
  bool strain_dissipation_ = false;  // some element has Element::strain_dissipation
  VecX q0_, v0_;
  SpMat M_;
  VecX ground_;
};

}  // namespace isoflex::system
