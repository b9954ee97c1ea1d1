// The writers' io::OutputError: it names the file the user knows (not a temporary one) and the
// system's cause, and what was written before it stays complete.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "isoflex/io/history_writer.hpp"
#include "isoflex/io/output_error.hpp"
#include "isoflex/io/summary_writer.hpp"
#include "support/files.hpp"

namespace fs = std::filesystem;
namespace io = isoflex::io;

namespace {

fs::path temp_dir(const std::string& name) {
  return isoflex::test::temp_dir("isoflex_output_error_", name);
}

// The io::OutputError `f` throws ("" when it throws none).
template <class F>
std::string output_error(F&& f) {
  try {
    f();
  } catch (const io::OutputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

// A full disk: the CSV header cannot be written to /dev/full.
TEST(OutputErrors, CsvFileOnAFullDiskNamesTheFileAndTheCause) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  const fs::path d = temp_dir("csv");
  fs::create_symlink("/dev/full", d / "history.csv");
  EXPECT_EQ(output_error([&] { io::CsvFile(d / "history.csv", "a,b"); }),
            "cannot write " + (d / "history.csv").string() + ": No space left on device");
  fs::remove_all(d);
}

// A full disk while the temporary file is written, and a directory where the file goes: the
// error names the file, the temporary file is gone, an existing file is unchanged.
TEST(OutputErrors, AtomicWritesNameTheFileAndLeaveNoTemporaryFile) {
  const fs::path d = temp_dir("atomic");
  io::write_file_atomic(d / "a.vtu", "old");
  if (fs::exists("/dev/full")) {
    fs::create_symlink("/dev/full", d / "a.vtu.tmp");
    EXPECT_EQ(output_error([&] { io::write_file_atomic(d / "a.vtu", "new"); }),
              "cannot write " + (d / "a.vtu").string() + ": No space left on device");
    EXPECT_FALSE(fs::exists(fs::symlink_status(d / "a.vtu.tmp")));
    EXPECT_EQ(isoflex::test::read_text(d / "a.vtu"), "old");
  }
  fs::create_directories(d / "results.pvd");
  EXPECT_EQ(output_error([&] { io::write_file_atomic(d / "results.pvd", "x"); }),
            "cannot write " + (d / "results.pvd").string() + ": Is a directory");
  EXPECT_FALSE(fs::exists(d / "results.pvd.tmp"));
  fs::remove_all(d);
}
