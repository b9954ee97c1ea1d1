#pragma once
// A ParaView time series of the bodies, beams and shells: outdir/vtk/step_NNNNNN.vtu (VTK XML
// UnstructuredGrid, its arrays binary or ascii: io/vtu_data_arrays.hpp) for every `every`-th
// snapshot plus the last one, and outdir/results.pvd (a VTK Collection of them, rewritten
// atomically whenever a file is added, so an interrupted run leaves a valid series).
//
// Each .vtu holds, per body, its drawing shape as surface cells in the current pose
// x = φ + R·X (R = [d₁ d₂ d₃]) and the director triad as three line cells from φ.
// Each beam element is one hexahedron between the cross-sections of its nodes (width and height
// along d₁, d₂ from the beam's `draw` key, default 1/50 of its length): shear, bending and twist
// show.
// Each director-shell element is one quad (VTK_QUAD) through the current positions φ of its four
// nodes (the deformed mid-surface, shell_mesh.hpp); neighbouring elements share their points.
//   cell data:  body_id (Int32, index into model.bodies; −1 for beam and shell elements), part
//               (Int32: 0 shape, 1/2/3 = d₁/d₂/d₃, 4 beam element, 5 shell element), n and m
//               (Float64 × 3: the beam element's stress resultants in director components,
//               DNSM-III (69); 0 for bodies and shells)
//   point data: velocity (Float64 × 3) = φ̇ + ω × (x − φ)
//   field data: TimeValue (Float64, the snapshot time; ParaView shows it as the time)
// With shell elements in the snapshot (and only then, so that files without shells stay as they
// were) the same grid also carries — one grid rather than a second <Piece>, because VTK's reader
// merges the pieces of a file into one grid anyway, and an array missing from one piece is left
// unset there without a warning (VTK 9.1), so the pieces would need the same arrays regardless:
//   cell data:  shell_id (Int32, index into model.shells; −1 for bodies and beams); n11, n22,
//               n12, m11, m22, m12, q1, q2 (Float64: the element's membrane forces, bending
//               moments and shear forces at its centre, components in its frame (e₁, e₂) at t = 0,
//               ShellElementValue); n_vm, m_vm (Float64: von_mises(n), von_mises(m) of
//               shell_mesh.hpp); all 0 on the cells of bodies and beams
//   point data: displacement (Float64 × 3) = φ − φ at the first snapshot, and director
//               (Float64 × 3) = d, on the shell points; 0 on the points of bodies and beams
//   field data: shell_id[NAME] (Int32, one per shell of the model: its shell_id, the legend)
//
// Kirchhoff–Love patches (Snapshot::kl_patches, and only when the snapshot has them) go to files
// of their own, vtk/<shell>_NNNNNN.vtu for the same written steps: the tessellated deformed
// patch with kl_shell_vtu's fields (kl_shell_vtk.hpp), its displacement from the patch's
// reference surface. They are not merged into the step file because their point and cell arrays
// differ from the multibody ones (see above for what VTK makes of that). results.pvd lists each
// as part 1 + k (k = its index in model.kl_shells) of the step's time, next to the step file as
// part 0, so ParaView reads every time step as one multiblock data set. <shell> is the shell's
// name with every character other than A–Z, a–z, 0–9, '_', '.', '-' replaced by '_', and "-k"
// appended while it is "step" or another patch's (kl_patch_file_stems).
#include <array>
#include <chrono>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "isoflex/integrate/snapshot.hpp"
#include "isoflex/io/kl_shell_vtk.hpp"
#include "isoflex/model/model.hpp"

namespace isoflex::io {

// Points and cells of one body in the current pose (exposed for tests and other writers).
struct BodyMesh {
  std::vector<Vec3> points;
  std::vector<Vec3> velocities;      // one per point
  std::vector<int> connectivity;     // point indices local to this mesh
  std::vector<int> offsets;          // end offset of each cell in `connectivity`
  std::vector<unsigned char> types;  // VTK cell types
  std::vector<int> parts;  // 0 shape, 1/2/3 = director d₁/d₂/d₃, kBeamPart, kShellPart
};

// VTK cell type numbers used here.
inline constexpr unsigned char kVtkVertex = 1;
inline constexpr unsigned char kVtkLine = 3;
inline constexpr unsigned char kVtkTriangle = 5;
inline constexpr unsigned char kVtkPolygon = 7;
inline constexpr unsigned char kVtkQuad = 9;
inline constexpr unsigned char kVtkHexahedron = 12;

// Segments around the circumference of cylinders and spheres, rings of a sphere (pole to pole).
inline constexpr int kRoundSegments = 24;
inline constexpr int kSphereRings = 12;

// BodyMesh::parts (the `part` cell data) of beam and shell elements.
inline constexpr int kBeamPart = 4;
inline constexpr int kShellPart = 5;

// Length of the drawn director lines: half the largest shape dimension, 0.2 without a shape.
double director_length(const model::Shape& shape);

// The shape (in body coordinates, see model::Shape) and the director triad of one body at `pose`.
BodyMesh body_mesh(const model::Shape& shape, const integrate::BodyPose& pose);

// One beam element as a hexahedron from the cross-section at node a to the one at node b;
// section = (width along d₁, height along d₂).
BodyMesh beam_element_mesh(const integrate::BodyPose& a, const integrate::BodyPose& b,
                           const std::array<double, 2>& section);

// A ParaView collection (.pvd) of the given <DataSet .../> lines.
std::string pvd_collection(const std::string& entries);

// The file-name stems of the model's kl_shells (index = kl_shells index): unique, none "step".
std::vector<std::string> kl_patch_file_stems(const model::Model& model);

class VtkSeriesWriter : public integrate::Observer {
 public:
  // Creates outdir/vtk; the file names of the model's Kirchhoff–Love patches (their geometry
  // comes with each snapshot). every ≤ 0 writes nothing at all. `format`: of all the .vtu files.
  // kl_per_span: quads per knot span and direction of the patch files.
  VtkSeriesWriter(const std::filesystem::path& outdir, const model::Model& model, int every,
                  model::VtkFormat format, int kl_per_span = kKLShellQuadsPerSpan);
  // Writes a collection that is still behind (a run that ended without on_finish).
  ~VtkSeriesWriter() override;
  VtkSeriesWriter(const VtkSeriesWriter&) = delete;
  VtkSeriesWriter& operator=(const VtkSeriesWriter&) = delete;

  // Both throw io::OutputError when a file cannot be written; the files listed in results.pvd
  // are then still complete (each is written to a temporary file first, then renamed).
  void on_snapshot(const integrate::Snapshot& s) override;
  void on_finish() override;

  // Files written so far, relative to outdir (e.g. "vtk/step_000010.vtu", then the patch files
  // of that step).
  const std::vector<std::string>& files() const { return files_; }

 private:
  void write_vtu(const integrate::Snapshot& s);
  void write_kl_patches(const integrate::Snapshot& s);
  void add_pvd_entry(double t, int part, const std::string& file);
  void write_pvd();

  std::filesystem::path outdir_;
  std::vector<model::Shape> shapes_;
  std::map<std::string, std::array<double, 2>> beam_sections_;  // drawn width, height per beam
  std::vector<std::string> shell_names_;                        // index = shell_id
  std::map<std::string, int> shell_ids_;
  // Per kl_shells entry: the stem of its files (the patch itself comes with the snapshot).
  std::map<std::string, int> kl_ids_;  // shell name → index into kl_stems_
  std::vector<std::string> kl_stems_;
  int kl_per_span_;
  // φ of every node at the first snapshot: the reference of the shells' displacement.
  std::vector<Vec3> reference_positions_;
  bool have_reference_ = false;
  int every_;
  model::VtkFormat format_;
  std::vector<std::string> files_;
  std::string pvd_entries_;  // the <DataSet .../> lines so far
  bool pvd_dirty_ = false;
  std::chrono::steady_clock::time_point last_pvd_write_{};
  std::optional<integrate::Snapshot> last_;  // the latest snapshot, if not yet written
  int last_written_step_ = -1;
};

}  // namespace isoflex::io
