#pragma once
// An isogeometric Kirchhoff–Love shell patch (IGA-thesis ch. 3–4): one NURBS surface, its control
// points as point nodes (x ∈ R³ each, positions, so rigid motion is exact: IGA-thesis Rem. 3.2),
// St. Venant–Kirchhoff plane stress in curvilinear components (3.15)–(3.17), membrane and bending
// Green–Lagrange strains (3.9)–(3.12) with the exact normal, internal energy (3.22), residual and
// analytic tangent (3.33)–(3.36) including the second variation of the normal, and the constant
// consistent mass (4.24). Gauss quadrature per knot span; the reference geometry is evaluated once
// per quadrature point (§6.2.2). Theory, conventions and deviations from the thesis:
// docs/theory/kl-shell.md; point kernel: kl_shell_point.hpp.
//
// Layout: x ∈ R^{3·ncp}, control point i (NurbsSurface numbering i_u + n_u·i_v) at x[3i, 3i+3).
#include <Eigen/SparseCore>
#include <cstddef>
#include <memory>
#include <vector>

#include "isoflex/geometry/nurbs_surface.hpp"
#include "isoflex/math/types.hpp"

namespace isoflex::elements {

using SpMat = Eigen::SparseMatrix<double>;

struct KLShellSection {
  double young = 0.0;
  double poisson = 0.0;
  double thickness = 0.0;
  double density = 0.0;  // mass per volume (mass matrix, self-weight)
  // Kelvin–Voigt damping factor η (time): viscous stresses S_v = η C Ė (IGA-thesis (3.51)–(3.52)).
  double eta = 0.0;
  // A bending strip (IGA-thesis §4.4.2): no membrane stiffness (4.28) and bending stiffness E
  // (`young`) only across the strip, along ξ, in local Cartesian components (4.29), so that the
  // energy density is ½ (t³/12) E ‖A₁‖⁻⁴ (E^f₁₁)² (4.30)–(4.31); linear along η is allowed.
  bool bending_strip = false;
};

// nonlinear: Green–Lagrange strains (3.9)–(3.12). linear: the strains linearized about the
// reference configuration (small displacements), so the residual is K (x − X) with a constant K.
enum class KLKinematics { nonlinear, linear };

// Stress recovery at one parametric point (IGA-thesis §3.4).
struct KLShellStress {
  Vec3 point = Vec3::Zero();  // current mid-surface point
  // Local Cartesian frame (3.47): e1 along the current a1, e2 in the tangent plane, e3 = a3.
  Mat3 frame = Mat3::Identity();  // columns e1, e2, e3
  // Membrane forces n (per unit length) and bending moments m (per unit length) in that frame,
  // Voigt order (11, 22, 12) (3.47).
  Vec3 n = Vec3::Zero(), m = Vec3::Zero();
  // Cauchy stresses (11, 22, 12) in the frame at the top (+t/2, along a3) and bottom (−t/2)
  // surfaces (3.44)–(3.46), their principal stresses (σ_I ≥ σ_II) and von Mises (3.48)–(3.50).
  Vec3 sigma_top = Vec3::Zero(), sigma_bottom = Vec3::Zero();
  Eigen::Vector2d principal_top = Eigen::Vector2d::Zero(),
                  principal_bottom = Eigen::Vector2d::Zero();
  double von_mises_top = 0.0, von_mises_bottom = 0.0;
};

class KLShellPatch {
 public:
  // rule_u, rule_v: Gauss points per knot span and direction; 0 = p + 1 (q + 1), the default.
  // Throws std::invalid_argument for a degree < 2 in either direction (a Kirchhoff–Love shell
  // needs C¹ inside the patch: second derivatives; a bending strip needs them across only), more
  // than 36 functions per element
  // ((p+1)(q+1) > 36, the fixed-size kernel), a non-positive E, thickness or density < 0,
  // ν outside (−1, 0.5), a negative rule, an invalid surface (NurbsSurface::validate), or a
  // degenerate reference point (|A₁ × A₂| ≤ 10⁻¹² |A₁||A₂| at a quadrature point).
  // Interior knots of multiplicity p (C⁰) are accepted; the patch alone is a hinge there (no
  // bending coupling across). A model couples such lines like interfaces between patches
  // (system/kl_interfaces.hpp, a patch joined to itself).
  KLShellPatch(geometry::NurbsSurface reference, KLShellSection section, int rule_u = 0,
               int rule_v = 0);

  const geometry::NurbsSurface& reference() const;
  const KLShellSection& section() const;
  int control_points() const;
  int dofs() const { return 3 * control_points(); }
  int elements() const;           // non-empty knot-span products
  int quadrature_points() const;  // over the whole patch
  // Memory of the pre-evaluated reference geometry per quadrature point, in bytes (§6.2.2; 304,
  // docs/theory/kl-shell.md §6). Basis functions are not stored: they are re-evaluated per element
  // and call by geometry::element_basis.
  std::size_t reference_bytes_per_point() const;
  // Reference control-point positions X, stacked (the x of the undeformed patch).
  VecX reference_positions() const;

  // Internal energy Π_int(x) (3.22). Throws std::invalid_argument if x.size() ≠ dofs() or x is
  // not finite (also internal_force and stress).
  double energy(const VecX& x, KLKinematics kin) const;
  // Internal force r = ∂Π_int/∂x (3.33)–(3.34); if K is not null it receives the tangent
  // ∂r/∂x (3.35)–(3.36) in the patch's fixed pattern (pattern(): the values are overwritten, the
  // pattern is the same on every call, compressed). A K that already has the pattern (same size,
  // compressed, same outer index) keeps its storage; any other K is replaced by a copy of it.
  VecX internal_force(const VecX& x, KLKinematics kin, SpMat* K) const;
  // The same with the tangent's values written straight into `values` (pattern().nonZeros()
  // entries, pattern()'s storage order, overwritten; nullptr: no tangent): no copy of the pattern.
  VecX internal_force_into(const VecX& x, KLKinematics kin, double* values) const;
  // Discrete gradient DV(xₙ, xₙ₊₁) of the internal energy Π_int (3.22) for the energy–momentum
  // schemes: DV·(xₙ₊₁ − xₙ) = Π(xₙ₊₁) − Π(xₙ) to round-off, DV = ∇Π(x_{n+½}) + O(|Δx|²), and DV is
  // orthogonal to the rigid motions at the midpoint (Σ_A DV_A = 0, Σ_A x_{n+½,A} × DV_A = 0), so
  // the midpoint rule with it conserves energy, linear and angular momentum. If K is not null it
  // receives ∂DV/∂xₙ₊₁ (NOT symmetric) in the patch's fixed pattern (pattern(); same storage rules
  // as internal_force). Same threads / bit-for-bit thread-count independence as internal_force.
  // Formula (stress averaged, Gonzalez-type correction of the bending strains per element),
  // threshold and limits: docs/theory/kl-shell.md §10. KLKinematics::linear: r(x_{n+½}), ½ K_lin
  // (Π is quadratic; only Σ_A DV_A = 0 holds there, the linearized strains are not invariant
  // under finite rotations). Throws like internal_force for a wrong size or non-finite entries.
  VecX discrete_gradient(const VecX& xn, const VecX& xn1, KLKinematics kin, SpMat* K) const;
  // The same with ∂DV/∂xₙ₊₁ written straight into `values` (as internal_force's).
  VecX discrete_gradient_into(const VecX& xn, const VecX& xn1, KLKinematics kin,
                              double* values) const;
  // The Kelvin–Voigt viscous force of IGA-thesis (3.55), f_v = ∫ Bᵀ S_v dA with S_v = η D Ė,
  // Ė = B(x) ẋ (3.52)–(3.54), i.e. f_v = η K_mat(x) ẋ with K_mat the material part of the tangent;
  // for KLKinematics::linear B = B(X), f_v = η K_lin ẋ. If values is not null it receives
  // cx ∂f_v/∂x + cv ∂f_v/∂ẋ (added to what is there, pattern order; NOT symmetric): the time
  // integrators combine both, e.g. ½ and 1/Δt at the midpoint x_{n+½}, ẋ = Δx/Δt. ∂f_v/∂ẋ is
  // the damping matrix of the thesis, ∂f_v/∂x its "j" part with Ė_*,v (kl-shell.md §11).
  // Zero when η = 0. Throws like internal_force for a wrong size or non-finite entries.
  VecX viscous_force_into(const VecX& x, const VecX& xdot, KLKinematics kin, double cx, double cv,
                          double* values) const;
  // Threads of internal_force and discrete_gradient (1 by default; fewer than asked on small
  // patches, ~2000 quadrature points per thread at least). The elements run in coloured blocks in a
  // fixed order (coloured_element_loop.hpp), so r and K are the same bit for bit for any number of
  // threads.
  void set_threads(int threads) { threads_ = threads < 1 ? 1 : threads; }
  int threads() const { return threads_; }
  // Whether an evaluation with linear kinematics and a tangent keeps the tangent's values (it is
  // constant) for the later ones to copy; true by default. A static analysis evaluates it once
  // per load step and does without the copy: nnz doubles, 1.2 GB at 10⁶ unknowns
  // (bench/large_shells.md). The values are the same either way. false also drops values kept
  // before (a coupling's scale, System::add_kl_couplings, evaluates every patch's tangent while
  // the model is compiled: 1.2 GB of the two-patch roof at 10⁶ unknowns, kept to the end).
  void set_keep_linear_tangent(bool keep);
  // The part of the patch whose elements internal_force and internal_force_into sum, for a run on
  // `parts` MPI ranks (docs/theory/solvers.md §6): the elements of the rows (knot spans along v)
  // rows·part/parts … rows·(part + 1)/parts − 1, contiguous blocks of element rows; r and K are
  // then that part's, zero elsewhere, and their sum over the parts is the whole patch's. (0, 1),
  // the default: the whole patch. The energy, the discrete gradient, the viscous forces and the
  // stresses are always the whole patch's. Throws std::invalid_argument unless 0 ≤ part < parts.
  void set_partition(int part, int parts);
  struct RowRange {
    int begin = 0, end = 0;  // element rows [begin, end)
  };
  RowRange partition_rows() const;
  int parts() const { return parts_; }
  // The threads internal_force actually runs on: threads(), at most one per 2 048 points.
  int threads_used() const;
  // The fixed sparsity pattern of K (3ncp × 3ncp, every pair of control points sharing an
  // element, all 3 × 3 blocks), values zero, compressed.
  const SpMat& pattern() const;
  // Consistent mass (4.24), ρ t ∫ R_A R_B dA ⊗ I₃, computed on the first call (constant; a static
  // analysis never makes it).
  const SpMat& mass() const;
  // Kinetic energy ½ ẋᵀ M ẋ of control-point velocities ẋ (3.23) with the mass above.
  double kinetic_energy(const VecX& velocity) const;
  // Stress recovery at the parametric point (ξ, η) (throws std::invalid_argument outside the
  // parameter domain or for NaN). For KLKinematics::linear the frame and the metric are the
  // reference ones (small displacements; point is still the current mid-surface point).
  KLShellStress stress(const VecX& x, double xi, double eta, KLKinematics kin) const;

 private:
  struct Impl;
  std::shared_ptr<const Impl> impl_;
  int threads_ = 1;
  bool keep_linear_tangent_ = true;
  int part_ = 0, parts_ = 1;  // set_partition
};

}  // namespace isoflex::elements
