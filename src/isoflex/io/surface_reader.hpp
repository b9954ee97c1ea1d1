#pragma once
// The `surfaces` list of a model file (docs/model-files.md "surfaces"): named NURBS surfaces for
// shells, each a patch of an IGES/STEP file (read with io::read_cad) or a built-in shape
// (geometry/builders.hpp), clamped if its knot vectors are not open (geometry/clamping.hpp),
// optionally k-refined (geometry/refinement.hpp) and placed. Called by io::read_model; errors
// follow its conventions (FILE:LINE: surfaces[i].KEY: message).
#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

#include "isoflex/io/model_error.hpp"
#include "isoflex/model/model.hpp"

namespace isoflex::io {

// Reads the value of the top-level key `surfaces` (a list; an empty value is an empty list).
// `file` is the model file: the FILE of messages and Source::file, and its directory is where
// relative CAD paths start. A CAD patch whose knot vector is not open (unclamped, periodic) is
// clamped first (geometry/clamping.hpp; an info finding says so). Each surface gets the findings
// of io::check_patch on its final geometry; a CAD patch with a finding of severity error is
// rejected. Throws ModelError. Reads CAD files with io::read_cad, which uses OCCT's process-wide
// state: one model at a time per process.
std::vector<model::Surface> read_surfaces(const YAML::Node& list, const std::string& file);

}  // namespace isoflex::io
