#pragma once
// Reading IGES and STEP files into NURBS patches with OpenCASCADE (docs/cad-import.md).
#include <filesystem>
#include <optional>

#include "isoflex/io/cad/cad_error.hpp"
#include "isoflex/io/cad/cad_model.hpp"

namespace isoflex::io {

struct CadReadOptions {
  // Seconds the reading (child) process may run before it is stopped; unset: the environment
  // variable ISOFLEX_CAD_TIME_LIMIT, else 60.
  std::optional<double> time_limit_s;
};

// Reads `.igs/.iges` (IGES) or `.stp/.step` (STEP), chosen by the extension (any case). Every
// face of the file becomes one CadPatch: its surface as a B-spline (converted exactly if it is
// an analytic surface), with degrees, full knot vectors, control points and weights, untrimmed.
// OpenCASCADE's messages are captured while reading (nothing is printed). The reading runs in a
// child process (cad_isolation.hpp), so a crash or a hang of OpenCASCADE is an error here.
// Throws CadError (one line naming the file) if the file is missing, has another extension,
// cannot be parsed, holds no faces, holds a surface with a weight ≤ 0 or one the kernel cannot
// represent (degree above geometry::kMaxDegree), if OpenCASCADE fails, runs out of memory or
// crashes (saying what it was reading), or if the read takes longer than the time limit.
CadModel read_cad(const std::filesystem::path& file, const CadReadOptions& options = {});

}  // namespace isoflex::io
