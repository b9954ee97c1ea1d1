#include "isoflex/io/vtu_data_arrays.hpp"

#include <cmath>

namespace isoflex::io {

namespace {

std::string_view type_name(VtkType type) {
  switch (type) {
    case VtkType::int32:
      return "Int32";
    case VtkType::int64:
      return "Int64";
    case VtkType::uint8:
      return "UInt8";
    case VtkType::float64:
      break;
  }
  return "Float64";
}

void append_escaped(fmt::memory_buffer& out, std::string_view text) {
  for (const char c : text) {
    switch (c) {
      case '&':
        out.append(std::string_view("&amp;"));
        break;
      case '<':
        out.append(std::string_view("&lt;"));
        break;
      case '>':
        out.append(std::string_view("&gt;"));
        break;
      case '"':
        out.append(std::string_view("&quot;"));
        break;
      default:
        out.push_back(c);
    }
  }
}

}  // namespace

VtuDataArrays::VtuDataArrays(int ascii_digits) : ascii_digits_(ascii_digits) {}

void VtuDataArrays::open(int indent, VtkType type, std::string_view name,
                         std::string_view attributes) {
  indent_ = indent;
  type_ = type;
  line_open_ = false;
  xml("{:{}}<DataArray type=\"{}\" Name=\"", "", indent, type_name(type));
  append_escaped(xml_, name);
  xml("\"{} format=\"ascii\">\n", attributes);
}

void VtuDataArrays::start_value() {
  if (line_open_) {
    xml_.push_back(' ');
  } else {
    xml("{:{}}", "", indent_ + 2);
    line_open_ = true;
  }
}

void VtuDataArrays::real(double v) {
  start_value();
  xml("{:.{}g}", std::isfinite(v) ? v : 0.0, ascii_digits_);
}

void VtuDataArrays::integer(std::int64_t v) {
  start_value();
  xml("{}", v);
}

void VtuDataArrays::end_line(bool trailing_space) {
  if (trailing_space) xml_.push_back(' ');
  xml_.push_back('\n');
  line_open_ = false;
}

void VtuDataArrays::reals(std::span<const double> values, std::size_t per_line) {
  for (std::size_t k = 0; k < values.size(); ++k) {
    real(values[k]);
    if ((k + 1) % per_line == 0) end_line();
  }
  if (line_open_) end_line();
}

void VtuDataArrays::integers(std::span<const std::int64_t> values, std::size_t per_line) {
  for (std::size_t k = 0; k < values.size(); ++k) {
    integer(values[k]);
    if ((k + 1) % per_line == 0) end_line();
  }
  if (line_open_) end_line();
}

void VtuDataArrays::close() {
  if (line_open_) end_line();
  xml("{:{}}</DataArray>\n", "", indent_);
}

}  // namespace isoflex::io
