#pragma once
// Non-positive NURBS weights in the file itself. OpenCASCADE does not report them: its IGES
// transfer drops the weights of such a surface (a different, polynomial surface, "fit for a
// shell"), its STEP transfer drops the face (the file then "holds no faces"). So the reader
// looks at the parsed entities before the transfer. Internal to io/cad.
#include <XSControl_Reader.hxx>
#include <filesystem>

namespace isoflex::io::detail {

// Throws std::invalid_argument naming the first B-spline surface entity (IGES 128, STEP
// RATIONAL_B_SPLINE_SURFACE) with a weight that is not > 0: its label, the face that uses it
// (STEP), the control point (i, j) — from 0, i along u — and the value. IGES weights are read
// from the file (OCCT's parser has already replaced them), and a positive weight below 1e-9 is
// an error too: OCCT would replace all weights of that surface by 1.
void check_surface_weights(const XSControl_Reader& reader, const std::filesystem::path& file);

}  // namespace isoflex::io::detail
