#pragma once
// The OpenCASCADE side of CAD import, built as a loadable module (libisoflex_cad_occt.so) so that
// only a run that reads a CAD file pays for loading OpenCASCADE (about 40 ms of dynamic
// relocation per process otherwise; docs/cad-import.md "The import module"). io::read_cad
// (cad_reader.hpp, cad_loader.cpp) opens the module with dlopen and calls isoflex_cad_read.
#include <filesystem>
#include <string>

#include "isoflex/io/cad/cad_error.hpp"
#include "isoflex/io/cad/cad_model.hpp"

namespace isoflex::io {

// Told what the reader starts doing next, in words that complete "while …" ("parsing the IGES
// file", "translating the IGES entities into shapes", …). read_cad runs the reader in a child
// process (cad_isolation.hpp) and forwards these to the parent, so that a crash or a timeout of
// OpenCASCADE can say what it was reading.
using CadStageFn = void (*)(void* context, const char* stage);

// The reader itself (cad_reader.cpp): what read_cad documents. `stage` may be null.
CadModel read_cad_occt(const std::filesystem::path& file, CadStageFn stage = nullptr,
                       void* context = nullptr);

}  // namespace isoflex::io

// The module's entry point: reads `path` into *out, reporting stages to stage(context, …) (may
// be null). Returns 0, or 1 for a CadError (its file and message in *file, *message), 2 for any
// other exception (its what() in *message). Module and caller are built by the same compiler
// against the same libstdc++, so C++ objects pass through.
extern "C" int isoflex_cad_read(const char* path, isoflex::io::CadStageFn stage, void* context,
                                isoflex::io::CadModel* out, std::string* file,
                                std::string* message);
