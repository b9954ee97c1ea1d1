#pragma once
// The four boundary edges of a NURBS patch and the rows of control points next to them.
//
// u0: ξ = ξ_front (control points i = 0, η varies), u1: ξ = ξ_back (i = n_u − 1),
// v0: η = η_front (j = 0, ξ varies),                v1: η = η_back (j = n_v − 1).
// With open knot vectors only row 0 of an edge has non-zero basis values on it (the edge curve's
// control points); rows 0 and 1 together carry the slope across the edge (clamping, symmetry).
#include <string>
#include <vector>

#include "isoflex/geometry/nurbs_surface.hpp"

namespace isoflex::loads {

enum class PatchEdge { u0, u1, v0, v1 };

std::string to_string(PatchEdge e);
// "u0", "u1", "v0", "v1" (the model reader checks the names): the edge.
PatchEdge patch_edge_from_string(const std::string& name);

// True for u0/u1: the edge runs along η (its parameter is η, its knot vector s.v).
inline bool edge_runs_along_v(PatchEdge e) {
  return e == PatchEdge::u0 || e == PatchEdge::u1;
}

// Control-point indices (NurbsSurface numbering) of row `row` counted from the edge (row 0 = on
// the edge), in the order of the edge parameter. Throws std::invalid_argument if row is negative
// or not smaller than the number of rows across the edge.
std::vector<int> edge_control_points(const geometry::NurbsSurface& s, PatchEdge e, int row = 0);

// The fixed parameter of the edge (ξ for u0/u1, η for v0/v1).
double edge_parameter(const geometry::NurbsSurface& s, PatchEdge e);

}  // namespace isoflex::loads
