#pragma once
// NURBS surfaces as VTK XML UnstructuredGrid files (.vtu, binary or ascii: io/vtu_data_arrays.hpp),
// written by hand (no VTK library), in three views:
//
// 1. Rational Bézier cells (nurbs_bezier_vtu): one VTK_BEZIER_QUADRILATERAL (type 77) per element
//    (knot span, IGA-thesis §4.2.1), its (p+1)(q+1) Bézier control points from the Bézier
//    extraction (geometry/bezier_extraction.hpp), the homogeneous weights as point data
//    `RationalWeights` (marked as the RationalWeights attribute of <PointData>) and the degrees
//    as cell data `HigherOrderDegrees` (Int32 × 3: p, q, 1 — the third is unused for
//    quadrilaterals; marked as the HigherOrderDegrees attribute of <CellData>). ParaView ≥ 5.8
//    then draws the exact NURBS geometry (tessellated on screen, "Nonlinear Subdivision Level").
//    Every cell has its own points (points on shared edges are repeated); interpolating point
//    data is as exact as the geometry.
//
//    Point order of a degree (p, q) cell (VTK's vtkHigherOrderQuadrilateral::PointIndexFromIJK),
//    for Bézier point (i, j), i = 0…p along ξ, j = 0…q along η:
//      0–3   corners (0,0), (p,0), (p,q), (0,q)  — counter-clockwise
//      then  edge j = 0: i = 1…p−1;  edge i = p: j = 1…q−1;
//            edge j = q: i = 1…p−1;  edge i = 0: j = 1…q−1   — each edge in increasing i or j,
//            *not* around the cell (the top and left edges run "backwards")
//      then  interior: i = 1…p−1 fastest, j = 1…q−1.
//    (vtk_bezier_quad_index below.)
//
// 2. Tessellation (nurbs_tessellated_vtu): n × n VTK_QUAD (9) per element at evenly spaced
//    parameters, points shared between elements, the surface evaluated exactly at the points.
//
// 3. The control net (nurbs_control_net_vtu): the control points and VTK_LINE (3) cells joining
//    neighbours along ξ and η, with the weights as point data.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "isoflex/geometry/nurbs_surface.hpp"
#include "isoflex/model/model.hpp"

namespace isoflex::io {

inline constexpr unsigned char kVtkBezierQuadrilateral = 77;

// Local index in a VTK Lagrange/Bézier quadrilateral of degrees (p, q) of the point (i, j).
int vtk_bezier_quad_index(int i, int j, int p, int q);

// A named field on the surface: n_components (1 = scalars, 3 = vectors; any ≥ 1 is written)
// values per point, point-major.
struct SurfaceField {
  enum class Location {
    control_points,  // one tuple per NURBS control point (index i + n_u·j), interpolated as
                     // the geometry: f = Σ R_k f_k (IGA-thesis (4.12))
    bezier_points,   // (Bézier view only) one tuple per Bézier control point, cell by cell in
                     // the order of geometry::bezier_cells, within a cell local k + (p+1)·l
  };
  std::string name;
  int n_components = 1;
  std::vector<double> values;
  Location location = Location::control_points;
};

// Fields for the tessellation: either values at the control points (interpolated with the NURBS
// basis, like SurfaceField::Location::control_points) or a callback evaluated at every sample
// point that writes n_components values to `out`.
struct SampledField {
  std::string name;
  int n_components = 1;
  std::vector<double> control_point_values;  // used when `at` is empty
  std::function<void(double xi, double eta, const Vec3& x, double* out)> at;
};

// The .vtu text of the rational Bézier view. Throws std::invalid_argument on a field of the
// wrong size or a surface that fails NurbsSurface::validate().
std::string nurbs_bezier_vtu(const geometry::NurbsSurface& s, model::VtkFormat format,
                             const std::vector<SurfaceField>& fields = {});

// The .vtu text of the tessellation: n_per_span ≥ 1 quads per element and direction. Point data:
// `parameters` (ξ, η) and the fields; cell data: `element` (index in surface_elements()).
std::string nurbs_tessellated_vtu(const geometry::NurbsSurface& s, int n_per_span,
                                  model::VtkFormat format,
                                  const std::vector<SampledField>& fields = {});

// The .vtu text of the control net. Point data `weight`; cell data `direction` (0: ξ, 1: η).
std::string nurbs_control_net_vtu(const geometry::NurbsSurface& s, model::VtkFormat format);

// The same written to `file` atomically (temporary file, then rename); io::OutputError when
// the file cannot be written.
void write_nurbs_bezier_vtu(const std::filesystem::path& file, const geometry::NurbsSurface& s,
                            model::VtkFormat format, const std::vector<SurfaceField>& fields = {});
void write_nurbs_tessellated_vtu(const std::filesystem::path& file, const geometry::NurbsSurface& s,
                                 int n_per_span, model::VtkFormat format,
                                 const std::vector<SampledField>& fields = {});
void write_nurbs_control_net_vtu(const std::filesystem::path& file, const geometry::NurbsSurface& s,
                                 model::VtkFormat format);

}  // namespace isoflex::io
