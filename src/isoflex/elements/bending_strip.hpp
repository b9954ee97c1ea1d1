#pragma once
// The bending strip of IGA-thesis §4.4.2 (Fig. 4.7): a fictitious patch whose control net is the
// triples of control points across an interface between two Kirchhoff–Love patches (the point
// of one patch's next row, the shared point, the point of the other's next row), one quadratic
// element across (ξ) and linear elements along (η), with no mass, no membrane stiffness (4.28)
// and bending stiffness E_s only across (4.29), energy (4.31). It penalizes the change of the
// angle between the patches; as an element over the triple nodes it is a KLPatchElement on this
// patch. The strip is a geometric device (Remark 4.3): its basis is its own, B-spline (weights 1)
// even on rational patches.
#include <array>
#include <memory>
#include <vector>

#include "isoflex/elements/kl_shell_patch.hpp"

namespace isoflex::elements {

// The strip surface: control point (i, j) = triples[j][i], knots [0,0,0,1,1,1] across and open
// uniform linear along. Throws std::invalid_argument for fewer than 2 triples.
geometry::NurbsSurface bending_strip_surface(const std::vector<std::array<Vec3, 3>>& triples);

// The strip patch with E_s = `young` (β E) and the shells' thickness; Gauss rule 3 × 2 per
// element. Throws like KLShellPatch (a triple folded onto itself is a degenerate reference).
std::shared_ptr<KLShellPatch> bending_strip(const std::vector<std::array<Vec3, 3>>& triples,
                                            double young, double thickness);

}  // namespace isoflex::elements
