#pragma once
// Analysis-suitability checks of an imported CAD patch (docs/cad-import.md "Checks"): what in the
// file's NURBS data would make a poor or wrong isogeometric shell model, each with a fix.
#include <string>
#include <vector>

#include "isoflex/io/cad/cad_model.hpp"

namespace isoflex::io {

enum class Severity {
  info,     // worth knowing, nothing to do (e.g. an analytic surface converted exactly)
  warning,  // the patch can be used, with the limitation stated
  error     // the patch is not a valid analysis patch as it stands
};

const char* to_string(Severity s);

struct Finding {
  Severity severity = Severity::info;
  std::string issue;  // what and where, e.g. "C⁰ line inside the patch at u = 0.5 …"
  std::string fix;    // what to do about it
};

// In this order: trimmed face (the trimming is ignored), degree < 2 per direction (not enough for
// Kirchhoff–Love shells), knot vectors that are not open (info: the model reader clamps them),
// C⁰ (multiplicity ≥ degree) and discontinuous (multiplicity > degree) lines inside the patch,
// collapsed edges, reversed face orientation (left-handed parameter domain), non-positive
// weights, converted analytic surfaces. An empty list means the patch is fit for a
// Kirchhoff–Love shell as it is; so does a list of infos only.
std::vector<Finding> check_patch(const CadPatch& patch);

}  // namespace isoflex::io
