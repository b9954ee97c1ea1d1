#include "isoflex/io/nurbs_vtk_writer.hpp"

#include <fmt/format.h>

#include <cstdint>
#include <stdexcept>
#include <string_view>

#include "isoflex/geometry/bezier_extraction.hpp"
#include "isoflex/geometry/quadrature.hpp"
#include "isoflex/io/summary_writer.hpp"
#include "isoflex/io/vtu_data_arrays.hpp"

namespace isoflex::io {

namespace {

inline constexpr unsigned char kVtkLine = 3;
inline constexpr unsigned char kVtkQuad = 9;

// One <Piece> of a VTK XML UnstructuredGrid in the order the format expects: PointData, CellData,
// Points, Cells.
class VtuText {
 public:
  VtuText(std::size_t n_points, std::size_t n_cells, model::VtkFormat format) : a_(format) {
    a_.start("1.0");
    a_.xml("  <UnstructuredGrid>\n");
    a_.xml("    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n", n_points, n_cells);
  }
  // `attributes` e.g. `RationalWeights="RationalWeights"` (the active-attribute markers).
  void open(std::string_view section, std::string_view attributes = {}) {
    a_.xml("      <{}{}{}>\n", section, attributes.empty() ? "" : " ", attributes);
  }
  void close(std::string_view section) { a_.xml("      </{}>\n", section); }

  void reals(std::string_view name, int n_components, const std::vector<double>& v) {
    a_.open(8, VtkType::float64, name, components(n_components));
    a_.reals(v, static_cast<std::size_t>(n_components));
    a_.close();
  }
  void integers(VtkType type, std::string_view name, int n_components,
                const std::vector<std::int64_t>& v) {
    a_.open(8, type, name, components(n_components));
    a_.integers(v, 24);
    a_.close();
  }
  void points(const std::vector<double>& xyz) {
    open("Points");
    reals("Points", 3, xyz);
    close("Points");
  }
  // Cells given by their connectivity, end offsets and types.
  void cells(const std::vector<std::int64_t>& connectivity,
             const std::vector<std::int64_t>& offsets, const std::vector<std::int64_t>& types) {
    open("Cells");
    integers(VtkType::int64, "connectivity", 1, connectivity);
    integers(VtkType::int64, "offsets", 1, offsets);
    integers(VtkType::uint8, "types", 1, types);
    close("Cells");
  }
  std::string finish() {
    a_.xml(
        "    </Piece>\n"
        "  </UnstructuredGrid>\n");
    return a_.finish();
  }

 private:
  static std::string components(int n) { return fmt::format(" NumberOfComponents=\"{}\"", n); }
  VtuDataArrays a_;
};

void check_field(const std::string& name, int n_components, std::size_t n_values,
                 std::size_t n_points, std::string_view where) {
  if (name.empty() || name.find_first_of("\"<>&") != std::string::npos)
    throw std::invalid_argument("NURBS VTK output: invalid field name '" + name + "'");
  if (n_components < 1)
    throw std::invalid_argument("NURBS VTK output: field '" + name + "' has " +
                                std::to_string(n_components) + " components");
  if (n_values != static_cast<std::size_t>(n_components) * n_points)
    throw std::invalid_argument(
        fmt::format("NURBS VTK output: field '{}' has {} values, expected {} {} × {} components",
                    name, n_values, n_points, where, n_components));
}

// Σ_k R_k f_k at (ξ, η) for a field given per control point.
void interpolate(const geometry::NurbsSurface& s, const geometry::SurfaceBasis& b,
                 const std::vector<double>& values, int nc, std::vector<double>& out) {
  for (int c = 0; c < nc; ++c) {
    double v = 0.0;
    for (int k = 0; k < b.R.cols(); ++k) v += b.R(0, k) * values[b.global_index(s, k) * nc + c];
    out.push_back(v);
  }
}

}  // namespace

int vtk_bezier_quad_index(int i, int j, int p, int q) {
  const bool on_i = (i == 0 || i == p);  // on the left or right edge
  const bool on_j = (j == 0 || j == q);  // on the bottom or top edge
  if (on_i && on_j) return i == 0 ? (j == 0 ? 0 : 3) : (j == 0 ? 1 : 2);
  constexpr int corners = 4;
  if (on_j)  // bottom edge (j = 0), then after the right edge the top edge (j = q); +i direction
    return corners + (i - 1) + (j == 0 ? 0 : (p - 1) + (q - 1));
  if (on_i)  // right edge (i = p) after the bottom one, left edge (i = 0) after the top; +j
    return corners + (j - 1) + (i == p ? (p - 1) : 2 * (p - 1) + (q - 1));
  return corners + 2 * ((p - 1) + (q - 1)) + (i - 1) + (p - 1) * (j - 1);
}

std::string nurbs_bezier_vtu(const geometry::NurbsSurface& s, model::VtkFormat format,
                             const std::vector<SurfaceField>& fields) {
  s.validate();
  const geometry::SurfaceExtraction x = geometry::extract_surface(s);
  const auto cells = geometry::bezier_cells(s, x);
  const int p = x.p, q = x.q, n_loc = (p + 1) * (q + 1);
  const std::size_t n_cells = cells.size(), n_points = n_cells * n_loc;
  for (const auto& f : fields) {
    const bool at_cp = f.location == SurfaceField::Location::control_points;
    check_field(f.name, f.n_components, f.values.size(), at_cp ? s.points.size() : n_points,
                at_cp ? "control points" : "Bézier points");
  }

  // VTK position of local Bézier point k = i + (p+1)·j.
  std::vector<int> vtk_of(n_loc);
  for (int j = 0; j <= q; ++j)
    for (int i = 0; i <= p; ++i) vtk_of[i + (p + 1) * j] = vtk_bezier_quad_index(i, j, p, q);

  std::vector<double> xyz(3 * n_points), w(n_points);
  std::vector<std::vector<double>> fv(fields.size());
  for (std::size_t f = 0; f < fields.size(); ++f) fv[f].resize(n_points * fields[f].n_components);
  for (std::size_t c = 0; c < n_cells; ++c) {
    const std::size_t base = c * n_loc;
    for (int k = 0; k < n_loc; ++k) {
      const std::size_t at = base + vtk_of[k];
      for (int d = 0; d < 3; ++d) xyz[3 * at + d] = cells[c].points[k](d);
      w[at] = cells[c].weights[k];
    }
    for (std::size_t f = 0; f < fields.size(); ++f) {
      const int nc = fields[f].n_components;
      std::vector<double> local;
      if (fields[f].location == SurfaceField::Location::control_points)
        local = geometry::extract_field(s, x.elements[c], fields[f].values, nc);
      else
        local.assign(fields[f].values.begin() + base * nc,
                     fields[f].values.begin() + (base + n_loc) * nc);
      for (int k = 0; k < n_loc; ++k)
        for (int d = 0; d < nc; ++d) fv[f][(base + vtk_of[k]) * nc + d] = local[k * nc + d];
    }
  }

  VtuText t(n_points, n_cells, format);
  t.open("PointData", "RationalWeights=\"RationalWeights\"");
  t.reals("RationalWeights", 1, w);
  for (std::size_t f = 0; f < fields.size(); ++f)
    t.reals(fields[f].name, fields[f].n_components, fv[f]);
  t.close("PointData");
  t.open("CellData", "HigherOrderDegrees=\"HigherOrderDegrees\"");
  std::vector<std::int64_t> degrees, element;
  for (std::size_t c = 0; c < n_cells; ++c) {
    degrees.insert(degrees.end(), {p, q, 1});
    element.push_back(static_cast<std::int64_t>(c));
  }
  t.integers(VtkType::int32, "HigherOrderDegrees", 3, degrees);
  t.integers(VtkType::int32, "element", 1, element);
  t.close("CellData");
  t.points(xyz);
  std::vector<std::int64_t> conn(n_points), offsets(n_cells),
      types(n_cells, kVtkBezierQuadrilateral);
  for (std::size_t k = 0; k < n_points; ++k) conn[k] = static_cast<std::int64_t>(k);
  for (std::size_t c = 0; c < n_cells; ++c) offsets[c] = static_cast<std::int64_t>((c + 1) * n_loc);
  t.cells(conn, offsets, types);
  return t.finish();
}

std::string nurbs_tessellated_vtu(const geometry::NurbsSurface& s, int n_per_span,
                                  model::VtkFormat format,
                                  const std::vector<SampledField>& fields) {
  s.validate();
  if (n_per_span < 1)
    throw std::invalid_argument("NURBS VTK output: n_per_span = " + std::to_string(n_per_span) +
                                " < 1");
  for (const auto& f : fields)
    if (!f.at)
      check_field(f.name, f.n_components, f.control_point_values.size(), s.points.size(),
                  "control points");
    else
      check_field(f.name, f.n_components, static_cast<std::size_t>(f.n_components), 1,
                  "(callback)");

  // Parameter samples shared between neighbouring elements (the surface is at least C⁰ across
  // an element boundary as long as no interior knot has multiplicity p + 1).
  const auto samples = [n_per_span](const geometry::KnotVector& kv) {
    std::vector<double> t;
    for (const auto& e : geometry::span_elements(kv))
      for (int k = 0; k < n_per_span; ++k)
        t.push_back(e.a + (e.b - e.a) * static_cast<double>(k) / n_per_span);
    t.push_back(kv.back());
    return t;
  };
  const std::vector<double> us = samples(s.u), vs = samples(s.v);
  const std::size_t nu = us.size(), nv = vs.size(), n_points = nu * nv;
  const std::size_t neu = (nu - 1) / n_per_span;
  const std::size_t n_cells = (nu - 1) * (nv - 1);

  std::vector<double> xyz, params;
  xyz.reserve(3 * n_points);
  params.reserve(2 * n_points);
  std::vector<std::vector<double>> fv(fields.size());
  for (std::size_t j = 0; j < nv; ++j) {
    for (std::size_t i = 0; i < nu; ++i) {
      const Vec3 x = geometry::evaluate(s, us[i], vs[j]).x;
      xyz.insert(xyz.end(), {x.x(), x.y(), x.z()});
      params.insert(params.end(), {us[i], vs[j]});
      bool have_basis = false;
      geometry::SurfaceBasis b;
      for (std::size_t f = 0; f < fields.size(); ++f) {
        const int nc = fields[f].n_components;
        if (fields[f].at) {
          fv[f].resize(fv[f].size() + nc);
          fields[f].at(us[i], vs[j], x, fv[f].data() + fv[f].size() - nc);
        } else {
          if (!have_basis) {
            b = geometry::surface_basis(s, us[i], vs[j]);
            have_basis = true;
          }
          interpolate(s, b, fields[f].control_point_values, nc, fv[f]);
        }
      }
    }
  }

  VtuText t(n_points, n_cells, format);
  t.open("PointData");
  t.reals("parameters", 2, params);
  for (std::size_t f = 0; f < fields.size(); ++f)
    t.reals(fields[f].name, fields[f].n_components, fv[f]);
  t.close("PointData");
  std::vector<std::int64_t> conn, offsets, types(n_cells, kVtkQuad), element;
  conn.reserve(4 * n_cells);
  for (std::size_t j = 0; j + 1 < nv; ++j) {
    for (std::size_t i = 0; i + 1 < nu; ++i) {
      const auto id = [nu](std::size_t a, std::size_t b) {
        return static_cast<std::int64_t>(a + nu * b);
      };
      conn.insert(conn.end(), {id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
      offsets.push_back(static_cast<std::int64_t>(conn.size()));
      element.push_back(static_cast<std::int64_t>(i / n_per_span + neu * (j / n_per_span)));
    }
  }
  t.open("CellData");
  t.integers(VtkType::int32, "element", 1, element);
  t.close("CellData");
  t.points(xyz);
  t.cells(conn, offsets, types);
  return t.finish();
}

std::string nurbs_control_net_vtu(const geometry::NurbsSurface& s, model::VtkFormat format) {
  s.validate();
  const int nu = s.n_u(), nv = s.n_v();
  std::vector<double> xyz;
  xyz.reserve(3 * s.points.size());
  for (const Vec3& p : s.points) xyz.insert(xyz.end(), {p.x(), p.y(), p.z()});
  std::vector<std::int64_t> conn, offsets, types, direction;
  const auto line = [&](int a, int b, int dir) {
    conn.insert(conn.end(), {a, b});
    offsets.push_back(static_cast<std::int64_t>(conn.size()));
    types.push_back(kVtkLine);
    direction.push_back(dir);
  };
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i + 1 < nu; ++i) line(s.index(i, j), s.index(i + 1, j), 0);
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j + 1 < nv; ++j) line(s.index(i, j), s.index(i, j + 1), 1);

  VtuText t(s.points.size(), types.size(), format);
  t.open("PointData", "Scalars=\"weight\"");
  t.reals("weight", 1, s.weights);
  t.close("PointData");
  t.open("CellData");
  t.integers(VtkType::int32, "direction", 1, direction);
  t.close("CellData");
  t.points(xyz);
  t.cells(conn, offsets, types);
  return t.finish();
}

void write_nurbs_bezier_vtu(const std::filesystem::path& file, const geometry::NurbsSurface& s,
                            model::VtkFormat format, const std::vector<SurfaceField>& fields) {
  write_file_atomic(file, nurbs_bezier_vtu(s, format, fields));
}

void write_nurbs_tessellated_vtu(const std::filesystem::path& file, const geometry::NurbsSurface& s,
                                 int n_per_span, model::VtkFormat format,
                                 const std::vector<SampledField>& fields) {
  write_file_atomic(file, nurbs_tessellated_vtu(s, n_per_span, format, fields));
}

void write_nurbs_control_net_vtu(const std::filesystem::path& file, const geometry::NurbsSurface& s,
                                 model::VtkFormat format) {
  write_file_atomic(file, nurbs_control_net_vtu(s, format));
}

}  // namespace isoflex::io
