#include "isoflex/io/vtk_writer.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <numbers>
#include <set>
#include <stdexcept>
#include <system_error>
#include <type_traits>

#include "isoflex/io/kl_shell_vtk.hpp"
#include "isoflex/io/output_error.hpp"
#include "isoflex/io/shell_mesh.hpp"
#include "isoflex/io/summary_writer.hpp"
#include "isoflex/io/vtu_data_arrays.hpp"

namespace isoflex::io {

namespace {

// Collects points (in body coordinates) and cells; transformed to the pose at the end.
class MeshBuilder {
 public:
  int point(const Vec3& X) {
    local_.push_back(X);
    return static_cast<int>(local_.size()) - 1;
  }
  void cell(std::initializer_list<int> ids, unsigned char type, int part) {
    mesh_.connectivity.insert(mesh_.connectivity.end(), ids.begin(), ids.end());
    close(type, part);
  }
  void cell(const std::vector<int>& ids, unsigned char type, int part) {
    mesh_.connectivity.insert(mesh_.connectivity.end(), ids.begin(), ids.end());
    close(type, part);
  }
  BodyMesh finish(const integrate::BodyPose& pose) {
    const Mat3& R = pose.directors;
    mesh_.points.reserve(local_.size());
    mesh_.velocities.reserve(local_.size());
    for (const Vec3& X : local_) {
      const Vec3 r = R * X;
      mesh_.points.push_back(pose.position + r);
      mesh_.velocities.push_back(pose.velocity + pose.angular_velocity.cross(r));
    }
    return std::move(mesh_);
  }

 private:
  void close(unsigned char type, int part) {
    mesh_.offsets.push_back(static_cast<int>(mesh_.connectivity.size()));
    mesh_.types.push_back(type);
    mesh_.parts.push_back(part);
  }
  std::vector<Vec3> local_;
  BodyMesh mesh_;
};

void add_box(MeshBuilder& m, const model::Shape& s) {
  const Vec3 h = 0.5 * s.size;
  int p[8];
  for (int k = 0; k < 8; ++k) {  // corner k = i + 2j + 4k' with i, j, k' ∈ {0, 1} along d₁, d₂, d₃
    const Vec3 sign((k & 1) ? 1.0 : -1.0, (k & 2) ? 1.0 : -1.0, (k & 4) ? 1.0 : -1.0);
    p[k] = m.point(s.offset + sign.cwiseProduct(h));
  }
  // Counter-clockwise seen from outside.
  m.cell({p[0], p[4], p[6], p[2]}, kVtkQuad, 0);  // −d₁
  m.cell({p[1], p[3], p[7], p[5]}, kVtkQuad, 0);  // +d₁
  m.cell({p[0], p[1], p[5], p[4]}, kVtkQuad, 0);  // −d₂
  m.cell({p[2], p[6], p[7], p[3]}, kVtkQuad, 0);  // +d₂
  m.cell({p[0], p[2], p[3], p[1]}, kVtkQuad, 0);  // −d₃
  m.cell({p[4], p[5], p[7], p[6]}, kVtkQuad, 0);  // +d₃
}

void add_pyramid(MeshBuilder& m, const model::Shape& s) {
  const double a = 0.5 * s.base;
  const int b0 = m.point(s.offset + Vec3(-a, -a, 0.0));
  const int b1 = m.point(s.offset + Vec3(a, -a, 0.0));
  const int b2 = m.point(s.offset + Vec3(a, a, 0.0));
  const int b3 = m.point(s.offset + Vec3(-a, a, 0.0));
  const int apex = m.point(s.offset + Vec3(0.0, 0.0, s.height));
  m.cell({b0, b3, b2, b1}, kVtkQuad, 0);
  m.cell({b0, b1, apex}, kVtkTriangle, 0);
  m.cell({b1, b2, apex}, kVtkTriangle, 0);
  m.cell({b2, b3, apex}, kVtkTriangle, 0);
  m.cell({b3, b0, apex}, kVtkTriangle, 0);
}

void add_cylinder(MeshBuilder& m, const model::Shape& s) {
  const int n = kRoundSegments;
  const double z = 0.5 * s.height;
  std::vector<int> bottom(n), top(n);
  for (int k = 0; k < n; ++k) {
    const double phi = 2.0 * std::numbers::pi * k / n;
    const double x = s.radius * std::cos(phi), y = s.radius * std::sin(phi);
    bottom[k] = m.point(s.offset + Vec3(x, y, -z));
  }
  for (int k = 0; k < n; ++k) {
    const double phi = 2.0 * std::numbers::pi * k / n;
    const double x = s.radius * std::cos(phi), y = s.radius * std::sin(phi);
    top[k] = m.point(s.offset + Vec3(x, y, z));
  }
  for (int k = 0; k < n; ++k) {
    const int k1 = (k + 1) % n;
    m.cell({bottom[k], bottom[k1], top[k1], top[k]}, kVtkQuad, 0);
  }
  m.cell(std::vector<int>(bottom.rbegin(), bottom.rend()), kVtkPolygon, 0);
  m.cell(top, kVtkPolygon, 0);
}

void add_sphere(MeshBuilder& m, const model::Shape& s) {
  const int nlon = kRoundSegments, nlat = kSphereRings;
  const double r = s.radius;
  const int north = m.point(s.offset + Vec3(0.0, 0.0, r));
  // rings[i − 1][j]: polar angle θ = π i / nlat, i = 1 … nlat − 1
  std::vector<std::vector<int>> rings(nlat - 1, std::vector<int>(nlon));
  for (int i = 1; i < nlat; ++i) {
    const double theta = std::numbers::pi * i / nlat;
    for (int j = 0; j < nlon; ++j) {
      const double phi = 2.0 * std::numbers::pi * j / nlon;
      rings[i - 1][j] =
          m.point(s.offset + r * Vec3(std::sin(theta) * std::cos(phi),
                                      std::sin(theta) * std::sin(phi), std::cos(theta)));
    }
  }
  const int south = m.point(s.offset + Vec3(0.0, 0.0, -r));
  for (int j = 0; j < nlon; ++j) {
    const int j1 = (j + 1) % nlon;
    m.cell({north, rings.front()[j], rings.front()[j1]}, kVtkTriangle, 0);
  }
  for (int i = 0; i + 1 < nlat - 1; ++i) {
    for (int j = 0; j < nlon; ++j) {
      const int j1 = (j + 1) % nlon;
      m.cell({rings[i][j], rings[i + 1][j], rings[i + 1][j1], rings[i][j1]}, kVtkQuad, 0);
    }
  }
  for (int j = 0; j < nlon; ++j) {
    const int j1 = (j + 1) % nlon;
    m.cell({south, rings.back()[j1], rings.back()[j]}, kVtkTriangle, 0);
  }
}

// One indented line "x y z" of a three-component array.
void vec3_line(VtuDataArrays& out, const Vec3& v) {
  out.real(v.x());
  out.real(v.y());
  out.real(v.z());
  out.end_line();
}

// `count` tuples of `n_components` copies of `value` (the filler of the body and beam cells or
// points in a shell array), a bounded number per line so that the lines stay readable.
template <class T>
void filler(VtuDataArrays& out, std::size_t count, int n_components, T value) {
  constexpr std::size_t kPerLine = 20;
  for (std::size_t done = 0; done < count;) {
    for (std::size_t k = 0; k < kPerLine && done < count; ++k, ++done) {
      for (int c = 0; c < n_components; ++c) {
        if constexpr (std::is_integral_v<T>)
          out.integer(value);
        else
          out.real(value);
      }
    }
    out.end_line(true);
  }
}

}  // namespace

double director_length(const model::Shape& s) {
  double largest = 0.0;
  switch (s.kind) {
    case model::ShapeKind::none:
      break;
    case model::ShapeKind::box:
      largest = s.size.cwiseAbs().maxCoeff();
      break;
    case model::ShapeKind::sphere:
      largest = 2.0 * std::abs(s.radius);
      break;
    case model::ShapeKind::pyramid:
      largest = std::max(std::abs(s.base), std::abs(s.height));
      break;
    case model::ShapeKind::cylinder:
      largest = std::max(2.0 * std::abs(s.radius), std::abs(s.height));
      break;
  }
  return largest > 0.0 ? 0.5 * largest : 0.2;
}

BodyMesh body_mesh(const model::Shape& shape, const integrate::BodyPose& pose) {
  MeshBuilder m;
  switch (shape.kind) {
    case model::ShapeKind::none:
      m.cell({m.point(Vec3::Zero())}, kVtkVertex, 0);
      break;
    case model::ShapeKind::box:
      add_box(m, shape);
      break;
    case model::ShapeKind::pyramid:
      add_pyramid(m, shape);
      break;
    case model::ShapeKind::cylinder:
      add_cylinder(m, shape);
      break;
    case model::ShapeKind::sphere:
      add_sphere(m, shape);
      break;
  }
  const double len = director_length(shape);
  const int origin = m.point(Vec3::Zero());
  for (int a = 0; a < 3; ++a) {
    const int tip = m.point(len * Vec3::Unit(a));
    m.cell({origin, tip}, kVtkLine, a + 1);
  }
  return m.finish(pose);
}

BodyMesh beam_element_mesh(const integrate::BodyPose& a, const integrate::BodyPose& b,
                           const std::array<double, 2>& section) {
  BodyMesh m;
  // Bottom face at node a, top face at node b, each (−,−), (+,−), (+,+), (−,+) in (d₁, d₂):
  // counter-clockwise about d₃, the VTK hexahedron's order.
  for (const auto* node : {&a, &b}) {
    for (const auto& [s1, s2] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
      const Vec3 r = 0.5 * (s1 * section[0] * node->directors.col(0) +
                            s2 * section[1] * node->directors.col(1));
      m.points.push_back(node->position + r);
      m.velocities.push_back(node->velocity + node->angular_velocity.cross(r));
    }
  }
  m.connectivity = {0, 1, 2, 3, 4, 5, 6, 7};
  m.offsets = {8};
  m.types = {kVtkHexahedron};
  m.parts = {kBeamPart};
  return m;
}

std::vector<std::string> kl_patch_file_stems(const model::Model& model) {
  // "step" would put a patch's files over the step files.
  std::set<std::string> used{"step"};
  std::vector<std::string> stems;
  for (std::size_t k = 0; k < model.kl_shells.size(); ++k) {
    std::string stem = model.kl_shells[k].name;
    for (char& c : stem) {
      const bool keep = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') ||
                        (c >= '0' && c <= '9') || c == '_' || c == '.' || c == '-';
      if (!keep) c = '_';
    }
    while (!used.insert(stem).second) stem += fmt::format("-{}", k);
    stems.push_back(stem);
  }
  return stems;
}

VtkSeriesWriter::VtkSeriesWriter(const std::filesystem::path& outdir, const model::Model& model,
                                 int every, model::VtkFormat format, int kl_per_span)
    : outdir_(outdir), kl_per_span_(kl_per_span), every_(every), format_(format) {
  shapes_.reserve(model.bodies.size());
  for (const auto& b : model.bodies) shapes_.push_back(b.shape);
  for (const auto& b : model.beams) {
    const double length = b.length();
    beam_sections_[b.name] = {b.draw_width > 0 ? b.draw_width : length / 50,
                              b.draw_height > 0 ? b.draw_height : length / 50};
  }
  for (const auto& sh : model.shells) {
    shell_ids_[sh.name] = static_cast<int>(shell_names_.size());
    shell_names_.push_back(sh.name);
  }
  if (every_ <= 0) return;
  const std::vector<std::string> stems = kl_patch_file_stems(model);
  for (std::size_t k = 0; k < model.kl_shells.size(); ++k) {
    kl_ids_[model.kl_shells[k].name] = static_cast<int>(k);
    kl_stems_.push_back(stems[k]);
  }
  std::error_code ec;
  std::filesystem::create_directories(outdir_ / "vtk", ec);
  if (ec) throw OutputError(outdir_ / "vtk", ec.message(), "create directory");
}

VtkSeriesWriter::~VtkSeriesWriter() {
  try {
    if (pvd_dirty_) write_pvd();
  } catch (...) {  // nothing sensible to do in a destructor
  }
}

void VtkSeriesWriter::on_snapshot(const integrate::Snapshot& s) {
  if (every_ <= 0) return;
  // Taken whether or not this snapshot is written: the displacement is from t = 0.
  if (!have_reference_) {
    reference_positions_.reserve(s.bodies.size());
    for (const auto& b : s.bodies) reference_positions_.push_back(b.position);
    have_reference_ = true;
  }
  if (s.step % every_ == 0) {
    write_vtu(s);
    last_.reset();
  } else {
    last_ = s;
  }
}

void VtkSeriesWriter::on_finish() {
  if (every_ <= 0) return;
  if (last_ && last_->step != last_written_step_) write_vtu(*last_);
  last_.reset();
  if (pvd_dirty_) write_pvd();
}

void VtkSeriesWriter::write_vtu(const integrate::Snapshot& s) {
  if (s.bodies.size() < shapes_.size()) {
    throw std::runtime_error(fmt::format("VTK output: snapshot has {} nodes, the model {} bodies",
                                         s.bodies.size(), shapes_.size()));
  }
  // Bodies (id = body index), then one hexahedron per beam element (id −1, part 4) carrying the
  // element's stress resultants, then the shell mid-surfaces (id −1, part 5) as the last mesh, so
  // that the shell arrays are filler followed by the shell values.
  std::vector<BodyMesh> meshes;
  std::vector<int> ids;
  std::vector<std::pair<Vec3, Vec3>> resultants;  // (n, m) of the mesh's cells
  meshes.reserve(shapes_.size() + s.beam_elements.size() + 1);
  std::size_t n_points = 0, n_cells = 0;
  for (std::size_t i = 0; i < shapes_.size(); ++i) {
    meshes.push_back(body_mesh(shapes_[i], s.bodies[i]));
    ids.push_back(static_cast<int>(i));
    resultants.emplace_back(Vec3::Zero(), Vec3::Zero());
  }
  for (const auto& e : s.beam_elements) {
    const auto& a = s.bodies.at(e.node_a);
    const auto& b = s.bodies.at(e.node_b);
    meshes.push_back(beam_element_mesh(a, b, beam_sections_.at(e.beam)));
    ids.push_back(-1);
    resultants.emplace_back(e.n, e.m);
  }
  const bool shells = !s.shell_elements.empty();
  ShellMesh shell;
  std::vector<int> shell_ids;  // per shell element
  if (shells) {
    for (const auto& e : s.shell_elements) {
      const auto found = shell_ids_.find(e.shell);
      if (found == shell_ids_.end()) {
        throw std::runtime_error(fmt::format(
            "VTK output: snapshot has an element of shell \"{}\", not in the model", e.shell));
      }
      shell_ids.push_back(found->second);
    }
    shell = shell_mesh(s, reference_positions_);
    meshes.push_back(std::move(shell.mesh));
    ids.push_back(-1);
    resultants.emplace_back(Vec3::Zero(), Vec3::Zero());
  }
  for (const auto& m : meshes) {
    n_points += m.points.size();
    n_cells += m.types.size();
  }

  VtuDataArrays out(format_);
  out.start("0.1");  // ascii: the version these files have always had
  out.xml(
      "  <UnstructuredGrid>\n"
      "    <FieldData>\n");
  out.open(6, VtkType::float64, "TimeValue", " NumberOfTuples=\"1\"");
  out.real(s.t);
  out.close();
  if (shells) {
    for (std::size_t k = 0; k < shell_names_.size(); ++k) {
      out.open(6, VtkType::int32, "shell_id[" + shell_names_[k] + "]", " NumberOfTuples=\"1\"");
      out.integer(static_cast<std::int64_t>(k));
      out.close();
    }
  }
  out.xml(
      "    </FieldData>\n"
      "    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n",
      n_points, n_cells);
  const std::string_view vec3 = " NumberOfComponents=\"3\"";

  // Point data
  out.xml("      <PointData Vectors=\"velocity\">\n");
  out.open(8, VtkType::float64, "velocity", vec3);
  for (const auto& m : meshes) {
    for (const Vec3& v : m.velocities) vec3_line(out, v);
  }
  out.close();
  if (shells) {
    // The shell points are the last ones, after those of the bodies and beams.
    const std::size_t n_other = n_points - shell.nodes.size();
    for (const auto* values : {&shell.displacements, &shell.directors}) {
      out.open(8, VtkType::float64, values == &shell.displacements ? "displacement" : "director",
               vec3);
      filler(out, n_other, 3, 0.0);
      for (const Vec3& v : *values) vec3_line(out, v);
      out.close();
    }
  }
  out.xml("      </PointData>\n");

  // Cell data
  out.xml("      <CellData Scalars=\"body_id\">\n");
  out.open(8, VtkType::int32, "body_id");
  for (std::size_t i = 0; i < meshes.size(); ++i) {
    if (meshes[i].types.empty()) continue;
    for (std::size_t c = 0; c < meshes[i].types.size(); ++c) out.integer(ids[i]);
    out.end_line(true);
  }
  out.close();
  out.open(8, VtkType::int32, "part");
  for (const auto& m : meshes) {
    if (m.parts.empty()) continue;
    for (const int p : m.parts) out.integer(p);
    out.end_line(true);
  }
  out.close();
  for (const int which : {0, 1}) {
    out.open(8, VtkType::float64, which == 0 ? "n" : "m", vec3);
    for (std::size_t i = 0; i < meshes.size(); ++i) {
      const Vec3& v = which == 0 ? resultants[i].first : resultants[i].second;
      for (std::size_t c = 0; c < meshes[i].types.size(); ++c) vec3_line(out, v);
    }
    out.close();
  }
  if (shells) {
    // Filler on the cells of bodies and beams, then one value per shell element and line.
    const auto& els = s.shell_elements;
    const std::size_t n_other = n_cells - els.size();
    out.open(8, VtkType::int32, "shell_id");
    filler(out, n_other, 1, -1);
    for (const int id : shell_ids) {
      out.integer(id);
      out.end_line();
    }
    out.close();
    // Symmetric parts of the off-diagonal components (the element's tensors are symmetric).
    using E = integrate::ShellElementValue;
    const std::pair<const char*, double (*)(const E&)> scalars[] = {
        {"n11", [](const E& e) { return e.n(0, 0); }},
        {"n22", [](const E& e) { return e.n(1, 1); }},
        {"n12", [](const E& e) { return 0.5 * (e.n(0, 1) + e.n(1, 0)); }},
        {"m11", [](const E& e) { return e.m(0, 0); }},
        {"m22", [](const E& e) { return e.m(1, 1); }},
        {"m12", [](const E& e) { return 0.5 * (e.m(0, 1) + e.m(1, 0)); }},
        {"q1", [](const E& e) { return e.q(0); }},
        {"q2", [](const E& e) { return e.q(1); }},
        {"n_vm", [](const E& e) { return von_mises(e.n); }},
        {"m_vm", [](const E& e) { return von_mises(e.m); }},
    };
    for (const auto& [name, value] : scalars) {
      out.open(8, VtkType::float64, name);
      filler(out, n_other, 1, 0.0);
      for (const E& e : els) {
        out.real(value(e));
        out.end_line();
      }
      out.close();
    }
  }
  out.xml("      </CellData>\n");

  // Points
  out.xml("      <Points>\n");
  out.open(8, VtkType::float64, "Points", vec3);
  for (const auto& m : meshes) {
    for (const Vec3& x : m.points) vec3_line(out, x);
  }
  out.close();
  out.xml("      </Points>\n");

  // Cells: global point ids and running end offsets.
  out.xml("      <Cells>\n");
  out.open(8, VtkType::int64, "connectivity");
  {
    std::size_t base = 0;
    for (const auto& m : meshes) {
      std::size_t begin = 0;
      for (const int end : m.offsets) {
        for (std::size_t k = begin; k < static_cast<std::size_t>(end); ++k)
          out.integer(static_cast<std::int64_t>(base) + m.connectivity[k]);
        out.end_line(true);
        begin = static_cast<std::size_t>(end);
      }
      base += m.points.size();
    }
  }
  out.close();
  out.open(8, VtkType::int64, "offsets");
  {
    std::size_t base = 0;
    for (const auto& m : meshes) {
      if (m.offsets.empty()) continue;
      for (const int end : m.offsets) out.integer(static_cast<std::int64_t>(base) + end);
      out.end_line(true);
      base += m.connectivity.size();
    }
  }
  out.close();
  out.open(8, VtkType::uint8, "types");
  for (const auto& m : meshes) {
    if (m.types.empty()) continue;
    for (const unsigned char t : m.types) out.integer(t);
    out.end_line(true);
  }
  out.close();
  out.xml(
      "      </Cells>\n"
      "    </Piece>\n"
      "  </UnstructuredGrid>\n");

  const std::string name = fmt::format("vtk/step_{:06d}.vtu", s.step);
  write_file_atomic(outdir_ / name, out.finish());
  files_.push_back(name);
  last_written_step_ = s.step;
  add_pvd_entry(s.t, 0, name);
  write_kl_patches(s);

  // Rewriting the whole collection each time costs O(files²) in total; beyond a few thousand
  // files it is rewritten at most once a second (and always on finish).
  const auto now = std::chrono::steady_clock::now();
  if (files_.size() <= 2000 || now - last_pvd_write_ >= std::chrono::seconds(1)) write_pvd();
}

void VtkSeriesWriter::write_kl_patches(const integrate::Snapshot& s) {
  for (const auto& value : s.kl_patches) {
    const auto found = kl_ids_.find(value.shell);
    if (found == kl_ids_.end()) {
      throw std::runtime_error(fmt::format(
          "VTK output: snapshot has the Kirchhoff–Love patch \"{}\", not in the model's kl_shells",
          value.shell));
    }
    if (!value.patch || value.x.size() != value.patch->dofs()) {
      throw std::runtime_error(fmt::format(
          "VTK output: Kirchhoff–Love patch \"{}\" has {} coordinates in the snapshot, {} in "
          "its patch",
          value.shell, value.x.size(), value.patch ? value.patch->dofs() : 0));
    }
    const std::string name = fmt::format(
        "vtk/{}_{:06d}.vtu", kl_stems_[static_cast<std::size_t>(found->second)], s.step);
    write_file_atomic(outdir_ / name,
                      kl_shell_vtu(*value.patch, value.kinematics, value.x, kl_per_span_, format_));
    files_.push_back(name);
    add_pvd_entry(s.t, 1 + found->second, name);
  }
}

void VtkSeriesWriter::add_pvd_entry(double t, int part, const std::string& file) {
  fmt::format_to(std::back_inserter(pvd_entries_),
                 "    <DataSet timestep=\"{:.17g}\" group=\"\" part=\"{}\" file=\"{}\"/>\n",
                 std::isfinite(t) ? t : 0.0, part, file);
  pvd_dirty_ = true;
}

std::string pvd_collection(const std::string& entries) {
  return "<?xml version=\"1.0\"?>\n"
         "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
         "  <Collection>\n" +
         entries +
         "  </Collection>\n"
         "</VTKFile>\n";
}

void VtkSeriesWriter::write_pvd() {
  write_file_atomic(outdir_ / "results.pvd", pvd_collection(pvd_entries_));
  pvd_dirty_ = false;
  last_pvd_write_ = std::chrono::steady_clock::now();
}

}  // namespace isoflex::io
