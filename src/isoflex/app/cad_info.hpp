#pragma once
// `isoflex cad-info FILE`: the NURBS patches of an IGES/STEP file and their analysis checks
// (docs/cad-import.md).
#include <ostream>
#include <string>

namespace isoflex::app {

// Prints, per patch, its name, degrees, control-point counts, knot vectors (distinct knots with
// multiplicities), weights, control-point bounding box and the findings of io::check_patch, then
// a one-line summary. Returns 0, or 2 with one error line on `err` naming the file when the file
// is missing or cannot be read.
int cad_info_command(const std::string& file, std::ostream& out, std::ostream& err);

}  // namespace isoflex::app
