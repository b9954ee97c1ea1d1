#include "isoflex/io/cad/occt_nurbs.hpp"

#include <BRepTools.hxx>
#include <BRep_Tool.hxx>
#include <GeomConvert.hxx>
#include <Geom_BezierSurface.hxx>
#include <Geom_BoundedSurface.hxx>
#include <Geom_ConicalSurface.hxx>
#include <Geom_CylindricalSurface.hxx>
#include <Geom_OffsetSurface.hxx>
#include <Geom_Plane.hxx>
#include <Geom_RectangularTrimmedSurface.hxx>
#include <Geom_SphericalSurface.hxx>
#include <Geom_SurfaceOfLinearExtrusion.hxx>
#include <Geom_SurfaceOfRevolution.hxx>
#include <Geom_ToroidalSurface.hxx>
#include <stdexcept>
#include <vector>

namespace isoflex::io::detail {

namespace {

// OCCT stores distinct knots and multiplicities (1-based arrays); the kernel wants the full
// vector, e.g. 0^3 1^3 → 0 0 0 1 1 1.
std::vector<double> full_knots(const TColStd_Array1OfReal& knots,
                               const TColStd_Array1OfInteger& mults) {
  std::vector<double> full;
  for (int k = knots.Lower(); k <= knots.Upper(); ++k)
    full.insert(full.end(), static_cast<std::size_t>(mults(k)), knots(k));
  return full;
}

}  // namespace

geometry::NurbsSurface to_nurbs(const opencascade::handle<Geom_BSplineSurface>& s0) {
  opencascade::handle<Geom_BSplineSurface> s = s0;
  if (s->IsUPeriodic() || s->IsVPeriodic()) {
    s = opencascade::handle<Geom_BSplineSurface>::DownCast(s0->Copy());
    if (s->IsUPeriodic()) s->SetUNotPeriodic();
    if (s->IsVPeriodic()) s->SetVNotPeriodic();
  }
  geometry::NurbsSurface out;
  out.u = geometry::KnotVector(s->UDegree(), full_knots(s->UKnots(), s->UMultiplicities()));
  out.v = geometry::KnotVector(s->VDegree(), full_knots(s->VKnots(), s->VMultiplicities()));
  const int nu = s->NbUPoles();
  const int nv = s->NbVPoles();
  if (out.n_u() != nu || out.n_v() != nv)
    throw std::invalid_argument("knot vectors do not match the number of control points");
  out.points.resize(static_cast<std::size_t>(nu) * nv);
  out.weights.assign(static_cast<std::size_t>(nu) * nv, 1.0);
  const bool rational = s->IsURational() || s->IsVRational();
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const gp_Pnt& p = s->Pole(i + 1, j + 1);
      const auto k = static_cast<std::size_t>(out.index(i, j));
      out.points[k] = Vec3(p.X(), p.Y(), p.Z());
      if (rational) out.weights[k] = s->Weight(i + 1, j + 1);
    }
  return out;
}

std::string surface_type_name(const opencascade::handle<Geom_Surface>& s) {
  if (s->IsKind(STANDARD_TYPE(Geom_BSplineSurface))) return "B-spline";
  if (s->IsKind(STANDARD_TYPE(Geom_BezierSurface))) return "Bezier";
  if (s->IsKind(STANDARD_TYPE(Geom_Plane))) return "plane";
  if (s->IsKind(STANDARD_TYPE(Geom_CylindricalSurface))) return "cylinder";
  if (s->IsKind(STANDARD_TYPE(Geom_ConicalSurface))) return "cone";
  if (s->IsKind(STANDARD_TYPE(Geom_SphericalSurface))) return "sphere";
  if (s->IsKind(STANDARD_TYPE(Geom_ToroidalSurface))) return "torus";
  if (s->IsKind(STANDARD_TYPE(Geom_SurfaceOfRevolution))) return "surface of revolution";
  if (s->IsKind(STANDARD_TYPE(Geom_SurfaceOfLinearExtrusion))) return "linear extrusion";
  if (s->IsKind(STANDARD_TYPE(Geom_OffsetSurface))) return "offset surface";
  if (const auto t = opencascade::handle<Geom_RectangularTrimmedSurface>::DownCast(s); !t.IsNull())
    return "trimmed " + surface_type_name(t->BasisSurface());
  return s->DynamicType()->Name();
}

FaceSurface face_surface(const TopoDS_Face& face) {
  // With the face's location applied (a transformed copy if it has one).
  const opencascade::handle<Geom_Surface> s = BRep_Tool::Surface(face);
  if (s.IsNull()) throw std::invalid_argument("the face has no surface");
  FaceSurface out;
  out.type = surface_type_name(s);
  if (const auto b = opencascade::handle<Geom_BSplineSurface>::DownCast(s); !b.IsNull()) {
    out.bspline = b;
    b->Bounds(out.u0, out.u1, out.v0, out.v1);
    return out;
  }
  out.converted = true;
  if (s->IsKind(STANDARD_TYPE(Geom_BoundedSurface))) {
    s->Bounds(out.u0, out.u1, out.v0, out.v1);
    out.bspline = GeomConvert::SurfaceToBSplineSurface(s);
  } else {
    BRepTools::UVBounds(face, out.u0, out.u1, out.v0, out.v1);
    const opencascade::handle<Geom_Surface> piece =
        new Geom_RectangularTrimmedSurface(s, out.u0, out.u1, out.v0, out.v1);
    out.bspline = GeomConvert::SurfaceToBSplineSurface(piece);
  }
  if (out.bspline.IsNull()) throw std::invalid_argument("no B-spline form of a " + out.type);
  return out;
}

}  // namespace isoflex::io::detail
