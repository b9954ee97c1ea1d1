#pragma once
// OpenCASCADE B-spline surfaces → geometry::NurbsSurface. Internal to io/cad.
#include <Geom_BSplineSurface.hxx>
#include <Geom_Surface.hxx>
#include <TopoDS_Face.hxx>
#include <string>

#include "isoflex/geometry/nurbs_surface.hpp"

namespace isoflex::io::detail {

// Degrees, full knot vectors (OCCT's distinct knots repeated by their multiplicities), poles
// (i along u, index i + n_u·j) and weights (1 if non-rational). A periodic surface is first made
// non-periodic (same geometry, clamped knot vectors). Throws std::invalid_argument if the kernel
// cannot hold it (degree above geometry::kMaxDegree).
geometry::NurbsSurface to_nurbs(const opencascade::handle<Geom_BSplineSurface>& s);

// The surface of a face as a B-spline, and the parameter rectangle of the surface the face lives
// in (the untrimmed patch). B-spline surfaces are taken as they are; other bounded surfaces
// (Bézier, rectangular trimmed) are converted whole; unbounded ones (plane, cylinder, cone,
// sphere, torus, revolution, extrusion) are first cut to the face's parameter bounds. The
// conversions are exact (GeomConvert::SurfaceToBSplineSurface); they throw Standard_Failure for
// surfaces with no exact B-spline form (offset surfaces).
struct FaceSurface {
  opencascade::handle<Geom_BSplineSurface> bspline;
  double u0 = 0, u1 = 0, v0 = 0, v1 = 0;  // the rectangle, in the original surface's parameters
  bool converted = false;
  std::string type;  // "B-spline", "plane", "cylinder", …
};
FaceSurface face_surface(const TopoDS_Face& face);

// A name for the type of an OCCT surface: "B-spline", "plane", … (the class name if unknown).
std::string surface_type_name(const opencascade::handle<Geom_Surface>& s);

}  // namespace isoflex::io::detail
