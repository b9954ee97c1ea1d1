#pragma once
// Checks of what `isoflex run` leaves in its output folder: complete history rows, a results.pvd
// that lists exactly the .vtu files present, all of them well-formed, and no temporary files.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "support/files.hpp"
#include "support/vtu.hpp"

namespace isoflex::test {

// The rows of `csv` after its header line (0 when it is missing).
inline int csv_rows(const std::filesystem::path& csv) {
  const std::string text = read_text(csv);
  const auto lines = std::count(text.begin(), text.end(), '\n');
  return lines > 0 ? static_cast<int>(lines) - 1 : 0;
}

// The file="…" attributes of a .pvd's DataSet entries, in order.
inline std::vector<std::string> pvd_files(const std::string& pvd) {
  std::vector<std::string> files;
  for (auto at = pvd.find("<DataSet"); at != std::string::npos; at = pvd.find("<DataSet", at + 1)) {
    const auto begin = pvd.find("file=\"", at) + 6;
    files.push_back(pvd.substr(begin, pvd.find('"', begin) - begin));
  }
  return files;
}

// Every row of history.csv has as many fields as the header, at least the 13 of every run, and
// ends in a line break (no half-written row).
inline void expect_complete_history(const std::filesystem::path& csv) {
  const std::string text = read_text(csv);
  ASSERT_FALSE(text.empty()) << csv;
  EXPECT_EQ(text.back(), '\n') << "last row incomplete: " << text.substr(text.rfind('\n') + 1);
  const std::string header = text.substr(0, text.find('\n'));
  const auto fields = std::count(header.begin(), header.end(), ',');
  EXPECT_GE(fields, 12) << header;
  std::size_t begin = 0;
  for (std::size_t end = text.find('\n'); end != std::string::npos;
       begin = end + 1, end = text.find('\n', begin)) {
    const std::string line = text.substr(begin, end - begin);
    EXPECT_EQ(std::count(line.begin(), line.end(), ','), fields) << line;
  }
}

// outdir/results.pvd is well-formed and lists exactly the .vtu files in outdir/vtk, each of them
// well-formed; no file in outdir ends in ".tmp". Returns the listed files.
inline std::vector<std::string> expect_consistent_vtk_series(const std::filesystem::path& outdir) {
  namespace fs = std::filesystem;
  const std::string pvd = read_text(outdir / "results.pvd");
  EXPECT_EQ(xml_error(pvd), "") << pvd;
  std::vector<std::string> listed = pvd_files(pvd), present;
  for (const auto& e : fs::directory_iterator(outdir / "vtk"))
    present.push_back("vtk/" + e.path().filename().string());
  std::sort(present.begin(), present.end());
  std::vector<std::string> sorted = listed;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_EQ(sorted, present) << "results.pvd lists other files than vtk/ holds";
  for (const auto& f : present) EXPECT_EQ(xml_error(read_text(outdir / f)), "") << f;
  for (const auto& e : fs::recursive_directory_iterator(outdir))
    EXPECT_NE(e.path().extension(), ".tmp") << e.path();
  return listed;
}

}  // namespace isoflex::test
