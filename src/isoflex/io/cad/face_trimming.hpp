#pragma once
// Whether a face covers its whole surface rectangle (untrimmed) or is cut by trimming curves.
// Internal to io/cad.
#include <TopoDS_Face.hxx>

namespace isoflex::io::detail {

// True if the face has one boundary loop and that loop runs along the border of the parameter
// rectangle [u0, u1] × [v0, v1] and spans all of it: the face is the natural, untrimmed patch.
// Samples each edge's curve on the face (pcurve; projected 3D curve where a file has none) and
// accepts points within 1e-6 of the rectangle's extent.
bool has_natural_boundary(const TopoDS_Face& face, double u0, double u1, double v0, double v1);

}  // namespace isoflex::io::detail
