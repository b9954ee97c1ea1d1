#pragma once
// The parameter data of IGES entities as the file writes them, for what OpenCASCADE's IGES
// reader changes while parsing (surface_weights.cpp: it sets all weights of an entity 128 to 1
// when one is below 1e-9). Internal to io/cad.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace isoflex::io::detail {

struct IgesEntityParameters {
  int type = 0;                     // the entity type number (the first parameter)
  std::vector<std::string> values;  // the parameters after the type, as written, blanks removed
};

// Every entity of type `type` in the file, by the sequence number of its directory entry (the
// "D" number). Uses the file's parameter and record delimiters (global section, parameters 1 and
// 2); Hollerith strings are not split. A file it cannot make sense of gives an empty map (OCCT's
// reader then reports the file).
std::map<int, IgesEntityParameters> iges_parameters_of_type(const std::filesystem::path& file,
                                                            int type);

// A number of the parameter data ("1.", "-2.5E3", Fortran's "1.0D0"); false if it is not one.
bool iges_real(const std::string& text, double& value);

}  // namespace isoflex::io::detail
