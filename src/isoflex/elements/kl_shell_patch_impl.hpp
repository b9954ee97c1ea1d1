#pragma once
// Private state of KLShellPatch, shared by its translation units (assembly: kl_shell_patch.cpp,
// stress recovery: kl_shell_stress.cpp). Not part of the public interface.
#include <mutex>
#include <string>
#include <vector>

#include "isoflex/elements/coloured_element_loop.hpp"
#include "isoflex/elements/kl_shell_patch.hpp"
#include "isoflex/elements/kl_shell_point.hpp"
#include "isoflex/geometry/element_basis.hpp"
#include "isoflex/geometry/quadrature.hpp"

namespace isoflex::elements {

struct KLShellPatch::Impl {
  geometry::NurbsSurface ref;
  KLShellSection sec;
  geometry::GaussRule rule_u, rule_v;
  std::vector<geometry::SurfaceElement> elems;
  ColouredElementLoop loop;  // the elements in blocks of p × q, for the threaded assembly
  int elements_u = 1;        // elements along u: element e lies in the row e / elements_u
  int n_fun = 0;             // (p+1)(q+1), local functions per element
  int n_qp = 0;              // quadrature points per element
  // Pre-evaluated reference geometry (§6.2.2), point g of element e at e·n_qp + g.
  std::vector<kl::ReferencePoint> points;
  // Global control point of local function k of element e at e·n_fun + k.
  std::vector<int> conn;
  // Assembly positions in the compressed pattern: entry (3A + i, 3B + c) of K, A = conn(e, k),
  // B = conn(e, l), is valuePtr()[block_pos[(e·n_fun + l)·n_fun + k] + c·col_nnz[B] + i].
  std::vector<int> block_pos;
  std::vector<int> col_nnz;  // non-zeros of each of the three columns of control point B
  SpMat pattern;
  // The constant consistent mass, computed on first use (a static analysis never asks for it:
  // pattern-sized, 1.8 GB at 10⁶ unknowns). Shared by the copies of a patch, hence once_flag.
  mutable std::once_flag mass_once;
  mutable SpMat mass;
  const SpMat& consistent_mass() const;
  // The linear tangent (KLKinematics::linear) is constant: its values in the pattern, stored by
  // the first linear evaluation with a tangent and copied by the later ones (kl-shell.md §3).
  // Not part of the patch's value: the copies of a patch share it, hence the mutex.
  mutable std::mutex linear_mutex;
  mutable std::vector<double> linear_values;

  VecX reference_positions() const;
  // The thicknesses the membrane and bending resultants are integrated with: t and t³/12, the
  // membrane 0 for a bending strip (IGA-thesis (4.28)).
  double membrane_thickness() const { return sec.bending_strip ? 0.0 : sec.thickness; }
  double bending_thickness() const { return sec.thickness * sec.thickness * sec.thickness / 12.0; }
  // Threads internal_force uses when asked for `threads` (fewer on small patches).
  int workers(int threads) const;
  // Local control points of element e taken from x (3·ncp).
  void gather(const VecX& x, int e, kl::LocalPoints& xl) const;
  void check_size(const VecX& x, const char* what) const;
  // Gives K the fixed pattern: keeps it if K already has it (same size, compressed, same outer
  // index), else replaces it by a copy of `pattern`. Values are left as they are.
  void adopt_pattern(SpMat& K) const;
  // values += the matrix Ke of element e with every block (a matrix that is not symmetric; block
  // (k, l) column-major in rows 9l … 9l + 8 of column k, kl::element_tangent_full), scattered by
  // the precomputed positions.
  void scatter_full(int e, const MatX& Ke, double* values) const;
  // The basis of quadrature point g of an element, as the point kernel reads it.
  static kl::BasisView view(const geometry::ElementBasis& eb, int g) {
    return {eb.values.data() + 6 * static_cast<std::ptrdiff_t>(eb.row_stride) * g, eb.n_functions,
            eb.row_stride, 1};
  }
};

}  // namespace isoflex::elements
