// libFuzzer harness: the YAML model reader (io::read_model_string) through System::compile
// (issue #15), as `isoflex check` and `run` load a model (app/commands.cpp, load()).
//
// Allowed, as load() turns them into exit code 2 with one line: io::ModelError and
// system::CompileError, whose messages must be located ("fuzz.yaml:LINE: …" or, for file-level
// errors, "fuzz.yaml: …"), and other std::runtime_error (a numerical failure while compiling,
// "FILE: the system could not be set up: …"). A finding is anything else escaping (e.g.
// std::bad_alloc, std::invalid_argument, std::out_of_range, YAML exceptions), an unlocated
// message, a crash, an assertion (Debug build: Eigen's and the project's), a sanitizer report.
//
// It loads as `isoflex check --max-memory 80MB` would: a model whose memory estimate exceeds
// 80 MB (64 MB of them the process itself) is refused before System::compile, as load()
// refuses it (exit 2). Larger models run the
// same code at more cost (10-100 ms each under ASan would hold the fuzzer to tens of inputs per
// second); the refusal itself is tested in tests/app/test_cli_memory.cpp.
//
// CAD files named by a model are not read: the build of this harness has no OpenCASCADE module
// (ISOFLEX_CAD_OCCT=OFF), so `cad:` ends in a located "cannot load the CAD import module" error
// instead of forking the reading process inside the fuzzer.
#include <cstdint>
#include <string>

#include "isoflex/io/model_error.hpp"
#include "isoflex/io/model_reader.hpp"
#include "isoflex/system/compile_error.hpp"
#include "isoflex/system/memory_estimate.hpp"
#include "isoflex/system/system.hpp"

using namespace isoflex;

namespace {

constexpr double kMemoryLimit = 80.0 * 1024 * 1024;

void expect_located(const std::string& message) {
  if (message.rfind("fuzz.yaml:", 0) != 0) __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string yaml(reinterpret_cast<const char*>(data), size);
  try {
    const model::Model m =
        io::read_model_string(yaml, "fuzz.yaml", {kMemoryLimit, "--max-memory is 80 MB"});
    if (system::estimate_memory(m).total() > kMemoryLimit) return 0;
    const system::System sys = system::System::compile(m);
  } catch (const io::ModelError& e) {
    expect_located(e.what());
  } catch (const system::CompileError& e) {
    expect_located(e.what());
  } catch (const std::runtime_error&) {
    // load(): "FILE: the system could not be set up: …" (exit 2)
  }
  return 0;
}
