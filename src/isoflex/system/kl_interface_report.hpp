#pragma once
// The text `isoflex check` gives of the Kirchhoff–Love interfaces (docs/model-files.md
// "kl_interfaces"): per interface the patches (the same patch twice for a closed patch's seam or
// a C⁰ knot line inside a patch), the edges or the knot line, the triples across it, the angle
// between the two sides there, the coupling with its rows; then what was refined to make
// interfaces conforming and which seams were left open.
#include <string>
#include <vector>

#include "isoflex/system/system.hpp"

namespace isoflex::system {

// "left u1 -- right u0", "ring u0 -- ring u1", "tube -- tube at the knot line ξ = 0.5".
std::string kl_interface_name(const KLInterfaceInstance& I);

// The lines of the listing, without trailing newlines; empty for a model with one patch and no
// interface (nothing is joined).
std::vector<std::string> kl_interface_report(const System& sys);

}  // namespace isoflex::system
