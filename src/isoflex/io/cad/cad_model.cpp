#include "isoflex/io/cad/cad_model.hpp"

namespace isoflex::io {

const char* to_string(CadFormat f) {
  return f == CadFormat::iges ? "IGES" : "STEP";
}

}  // namespace isoflex::io
