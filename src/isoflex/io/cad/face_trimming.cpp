#include "isoflex/io/cad/face_trimming.hpp"

#include <BRep_Tool.hxx>
#include <Geom2d_Curve.hxx>
#include <Geom_Curve.hxx>
#include <ShapeAnalysis_Surface.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <algorithm>
#include <cmath>
#include <limits>

namespace isoflex::io::detail {

namespace {

constexpr int kSamplesPerEdge = 9;

struct Rect {
  double u0, u1, v0, v1, tol_u, tol_v;
  bool on_border(const gp_Pnt2d& p) const {
    const bool on_u = std::abs(p.X() - u0) <= tol_u || std::abs(p.X() - u1) <= tol_u;
    const bool on_v = std::abs(p.Y() - v0) <= tol_v || std::abs(p.Y() - v1) <= tol_v;
    const bool inside =
        p.X() >= u0 - tol_u && p.X() <= u1 + tol_u && p.Y() >= v0 - tol_v && p.Y() <= v1 + tol_v;
    return inside && (on_u || on_v);
  }
};

}  // namespace

bool has_natural_boundary(const TopoDS_Face& face, double u0, double u1, double v0, double v1) {
  int wires = 0;
  for (TopExp_Explorer w(face, TopAbs_WIRE); w.More(); w.Next()) ++wires;
  if (wires != 1) return false;

  const Rect rect{u0, u1, v0, v1, 1e-6 * (u1 - u0), 1e-6 * (v1 - v0)};
  double min_u = std::numeric_limits<double>::infinity(), max_u = -min_u;
  double min_v = min_u, max_v = -min_u;
  opencascade::handle<ShapeAnalysis_Surface>
      projector;  // made on demand, for edges without a pcurve
  for (TopExp_Explorer e(face, TopAbs_EDGE); e.More(); e.Next()) {
    const TopoDS_Edge& edge = TopoDS::Edge(e.Current());
    double first = 0, last = 0;
    const opencascade::handle<Geom2d_Curve> pcurve =
        BRep_Tool::CurveOnSurface(edge, face, first, last);
    opencascade::handle<Geom_Curve> curve;
    if (pcurve.IsNull()) {
      if (BRep_Tool::Degenerated(edge)) continue;
      curve = BRep_Tool::Curve(edge, first, last);
      if (curve.IsNull()) return false;  // no way to tell where the edge runs
      if (projector.IsNull()) projector = new ShapeAnalysis_Surface(BRep_Tool::Surface(face));
    }
    for (int k = 0; k <= kSamplesPerEdge; ++k) {
      const double t = first + (last - first) * k / kSamplesPerEdge;
      const gp_Pnt2d p = pcurve.IsNull()
                             ? projector->ValueOfUV(curve->Value(t), BRep_Tool::Tolerance(edge))
                             : pcurve->Value(t);
      if (!rect.on_border(p)) return false;
      min_u = std::min(min_u, p.X());
      max_u = std::max(max_u, p.X());
      min_v = std::min(min_v, p.Y());
      max_v = std::max(max_v, p.Y());
    }
  }
  // The loop lies on the border; it is the whole border if it reaches all four sides.
  return std::abs(min_u - u0) <= rect.tol_u && std::abs(max_u - u1) <= rect.tol_u &&
         std::abs(min_v - v0) <= rect.tol_v && std::abs(max_v - v1) <= rect.tol_v;
}

}  // namespace isoflex::io::detail
