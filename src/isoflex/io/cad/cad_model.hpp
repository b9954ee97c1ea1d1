#pragma once
// What io::read_cad gives: one NURBS patch per face of an IGES or STEP file (docs/cad-import.md).
#include <filesystem>
#include <string>
#include <vector>

#include "isoflex/geometry/nurbs_surface.hpp"

namespace isoflex::io {

enum class CadFormat { iges, step };

struct CadPatch {
  std::string name;  // the entity's name or label in the file, else "patch <index>"
  int index = 0;     // 0-based, in the order of the faces in the file
  // The face's surface as a NURBS patch: full knot vectors as in the file (OCCT's distinct knots
  // repeated by their multiplicities), control points i + n_u·j with i along u, weights (all 1
  // for a polynomial B-spline). Always the whole untrimmed surface, in the file's own
  // parametrization and length unit.
  geometry::NurbsSurface surface;
  // The face does not cover the whole surface (trimming curves or holes); the trimming is
  // ignored and `surface` is the untrimmed patch.
  bool trimmed = false;
  // The face is REVERSED: its outward normal is −(x_u × x_v) (left-handed parameter domain).
  bool reversed_orientation = false;
  // The surface in the file was not a B-spline (plane, cylinder, …) and was converted exactly
  // (GeomConvert) on the rectangle of the face's parameter bounds.
  bool converted = false;
  std::string surface_type;  // the surface's type in the file: "B-spline", "plane", "cylinder", …
  std::string entity;        // where it is in the file: "IGES entity 128 (D5)", "STEP #17"
};

struct CadModel {
  std::filesystem::path file;
  CadFormat format = CadFormat::iges;
  // The length unit the file declares ("millimetre", "metre", "inch", …; empty if none). The
  // coordinates are the numbers in the file, not converted to any unit.
  std::string length_unit;
  std::vector<CadPatch> patches;
};

const char* to_string(CadFormat f);

}  // namespace isoflex::io
