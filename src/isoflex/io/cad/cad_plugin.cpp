#include "isoflex/io/cad/cad_plugin.hpp"

#include <exception>

extern "C" int isoflex_cad_read(const char* path, isoflex::io::CadStageFn stage, void* context,
                                isoflex::io::CadModel* out, std::string* file,
                                std::string* message) {
  try {
    *out = isoflex::io::read_cad_occt(path, stage, context);
    return 0;
  } catch (const isoflex::io::CadError& e) {
    *file = e.file();
    *message = e.message();
    return 1;
  } catch (const std::exception& e) {
    *message = e.what();
    return 2;
  }
}
