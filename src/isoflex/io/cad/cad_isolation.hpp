#pragma once
// Reading a CAD file in a child process (docs/cad-import.md "Isolation"). OpenCASCADE is a
// library we do not control: malformed files make it crash (SIGSEGV in the IGES and STEP
// transfers) or run for minutes. So read_cad forks, the child runs the reader and sends the
// result back through a pipe, and the parent turns a crash or a child still running at the time
// limit into a CadError that names the file and what was being read. Internal to io/cad.
#include <filesystem>
#include <string>

#include "isoflex/io/cad/cad_model.hpp"
#include "isoflex/io/cad/cad_plugin.hpp"

namespace isoflex::io::detail {

// The module's entry point (cad_plugin.hpp).
using CadReadFn = int (*)(const char*, CadStageFn, void*, CadModel*, std::string*, std::string*);

// Runs read(file, …) in a child process and returns its model, the same bits as a read in this
// process. The child writes nothing but the pipe (stdout and stderr go to /dev/null, no core
// file, no exit handlers). Throws CadError if the reader fails (its own message), crashes
// ("OpenCASCADE crashed (SIGSEGV: …) while <stage>") or takes longer than time_limit_s seconds
// (the child is killed: "did not finish within 60 s while <stage>"). Call it from one thread:
// the child of a multi-threaded process may only rely on what fork copies.
CadModel read_in_child(const std::filesystem::path& file, CadReadFn read, double time_limit_s);

}  // namespace isoflex::io::detail
