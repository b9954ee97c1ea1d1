#pragma once
// The text of a VTK XML file (.vtu) with its <DataArray> elements, written by hand (no VTK
// library): the caller writes the other elements (VTKFile, Piece, PointData, …) with xml() and
// each data array value by value between open() and close(). Values are written as text inside
// the element (format="ascii"); the lines are the caller's (end_line), so that each writer keeps
// its layout.
#include <fmt/format.h>

#include <cstdint>
#include <iterator>
#include <span>
#include <string>
#include <string_view>
#include <utility>

namespace isoflex::io {

// The VTK types of the arrays written here (the type attribute of <DataArray>).
enum class VtkType { int32, int64, uint8, float64 };

class VtuDataArrays {
 public:
  // ascii_digits: significant digits of the Float64 values.
  explicit VtuDataArrays(int ascii_digits);

  // Text outside the data arrays, appended as given.
  void xml(std::string_view text) { xml_.append(text); }
  template <class... T>
  void xml(fmt::format_string<T...> format, T&&... args) {
    fmt::format_to(std::back_inserter(xml_), format, std::forward<T>(args)...);
  }

  // Starts <DataArray type="…" Name="name"ATTRIBUTES format="ascii"> at `indent` spaces; the
  // lines of values are indented two more. `name` is escaped for the attribute value;
  // `attributes` (e.g. ` NumberOfComponents="3"`, with its leading space) go in as given.
  void open(int indent, VtkType type, std::string_view name, std::string_view attributes = {});
  // The next value of a Float64 array (non-finite as 0: VTK's ascii reader rejects nan and inf).
  void real(double v);
  // The next value of an integer array.
  void integer(std::int64_t v);
  // Ends the line of values; with `trailing_space` a space follows the last value first.
  void end_line(bool trailing_space = false);
  // `values` as lines of `per_line` values each (the last line may be shorter).
  void reals(std::span<const double> values, std::size_t per_line);
  void integers(std::span<const std::int64_t> values, std::size_t per_line);
  // Ends the array (and a line left open).
  void close();

  // The whole text.
  std::string finish() { return std::string(xml_.data(), xml_.size()); }

 private:
  void start_value();

  int ascii_digits_;
  fmt::memory_buffer xml_;
  int indent_ = 0;
  VtkType type_ = VtkType::float64;
  bool line_open_ = false;
};

}  // namespace isoflex::io
