#pragma once
// The text of a VTK XML file (.vtu) with its <DataArray> elements, written by hand (no VTK
// library): the caller writes the other elements (Piece, PointData, …) with xml() and each data
// array value by value between open() and close(), in either format of model::VtkFormat:
//
//   binary  every array is <DataArray … format="appended" offset="N"/>, its values one block of
//           one <AppendedData encoding="raw"> section at the end of the file: the block's byte
//           count as UInt64, then the values' bytes, little-endian; N is where the block starts,
//           counted from the first byte after the section's '_' (VTK XML Formats, "Appended Data
//           Section"; the UInt64 counts are the file's header_type="UInt64").
//   ascii   the values as text inside <DataArray … format="ascii">, on the caller's lines
//           (end_line), so that each writer keeps its layout; a Float64 with the fewest digits
//           that read back to the same double (fmt's shortest round trip: 0.1, not
//           0.10000000000000001), so that the text is exact and short.
//
// Both formats carry the same values bit for bit: a non-finite double is written as 0 in both,
// because VTK's ascii reader rejects nan and inf.
#include <fmt/format.h>

#include <cstdint>
#include <iterator>
#include <span>
#include <string>
#include <string_view>
#include <utility>

#include "isoflex/model/model.hpp"

namespace isoflex::io {

// The VTK types of the arrays written here (the type attribute of <DataArray>).
enum class VtkType { int32, int64, uint8, float64 };

class VtuDataArrays {
 public:
  explicit VtuDataArrays(model::VtkFormat format);

  // <?xml …?> and <VTKFile type="UnstructuredGrid" …>. A binary file is version 1.0 with
  // header_type="UInt64" (the attribute exists from version 1.0 on; without it the counts would
  // be UInt32); an ascii file has `ascii_version`, and header_type unless that is 0.1.
  void start(std::string_view ascii_version);

  // Text outside the data arrays, appended as given.
  void xml(std::string_view text) { xml_.append(text); }
  template <class... T>
  void xml(fmt::format_string<T...> format, T&&... args) {
    fmt::format_to(std::back_inserter(xml_), format, std::forward<T>(args)...);
  }

  // Starts <DataArray type="…" Name="name"ATTRIBUTES format="…"> at `indent` spaces; ascii
  // lines of values are indented two more. `name` is escaped for the attribute value;
  // `attributes` (e.g. ` NumberOfComponents="3"`, with its leading space) go in as given.
  void open(int indent, VtkType type, std::string_view name, std::string_view attributes = {});
  // The next value of the open array, converted to its type.
  void real(double v);
  void integer(std::int64_t v);
  // Ascii: ends the line of values; with `trailing_space` a space follows the last value first.
  void end_line(bool trailing_space = false);
  // `values` as (ascii) lines of `per_line` values each; the last line may be shorter.
  void reals(std::span<const double> values, std::size_t per_line);
  void integers(std::span<const std::int64_t> values, std::size_t per_line);
  // Ends the array (and an ascii line left open).
  void close();

  // The whole file: the text so far, the appended section (binary) and </VTKFile>.
  std::string finish();

 private:
  void start_value();

  model::VtkFormat format_;
  fmt::memory_buffer xml_;
  std::string appended_;   // binary: the blocks so far
  std::size_t block_ = 0;  // binary: where the open array's values begin in appended_
  int indent_ = 0;         // of the open array
  VtkType type_ = VtkType::float64;
  bool line_open_ = false;  // ascii
};

}  // namespace isoflex::io
