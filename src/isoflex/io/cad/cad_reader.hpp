#pragma once
// Reading IGES and STEP files into NURBS patches with OpenCASCADE (docs/cad-import.md).
#include <filesystem>

#include "isoflex/io/cad/cad_error.hpp"
#include "isoflex/io/cad/cad_model.hpp"

namespace isoflex::io {

// Reads `.igs/.iges` (IGES) or `.stp/.step` (STEP), chosen by the extension (any case). Every
// face of the file becomes one CadPatch: its surface as a B-spline (converted exactly if it is
// an analytic surface), with degrees, full knot vectors, control points and weights, untrimmed.
// OpenCASCADE's messages are captured while reading (nothing is printed).
// Throws CadError (one line naming the file) if the file is missing, has another extension,
// cannot be parsed, holds no faces, or holds a surface the kernel cannot represent (degree
// above geometry::kMaxDegree).
CadModel read_cad(const std::filesystem::path& file);

}  // namespace isoflex::io
