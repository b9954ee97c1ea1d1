#include "isoflex/io/vtu_data_arrays.hpp"

#include <bit>
#include <cmath>
#include <cstring>

namespace isoflex::io {

// The appended blocks are the values' bytes as they are in memory, and the files say
// byte_order="LittleEndian".
static_assert(std::endian::native == std::endian::little,
              "the binary .vtu writer copies little-endian values as they are");

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

template <class T>
void append_bytes(std::string& out, T v) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &v, sizeof(T));
  out.append(bytes, sizeof(T));
}

double finite(double v) {
  return std::isfinite(v) ? v : 0.0;
}

}  // namespace

VtuDataArrays::VtuDataArrays(model::VtkFormat format) : format_(format) {}

void VtuDataArrays::start(std::string_view ascii_version) {
  const bool binary = format_ == model::VtkFormat::binary;
  const std::string_view version = binary ? "1.0" : ascii_version;
  xml("<?xml version=\"1.0\"?>\n"
      "<VTKFile type=\"UnstructuredGrid\" version=\"{}\" byte_order=\"LittleEndian\"{}>\n",
      version, version == "0.1" ? "" : " header_type=\"UInt64\"");
}

void VtuDataArrays::open(int indent, VtkType type, std::string_view name,
                         std::string_view attributes) {
  indent_ = indent;
  type_ = type;
  line_open_ = false;
  xml("{:{}}<DataArray type=\"{}\" Name=\"", "", indent, type_name(type));
  append_escaped(xml_, name);
  if (format_ == model::VtkFormat::binary) {
    xml("\"{} format=\"appended\" offset=\"{}\"/>\n", attributes, appended_.size());
    append_bytes(appended_, std::uint64_t{0});  // the byte count, filled in by close()
    block_ = appended_.size();
  } else {
    xml("\"{} format=\"ascii\">\n", attributes);
  }
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
  if (type_ != VtkType::float64) {
    integer(static_cast<std::int64_t>(finite(v)));
    return;
  }
  if (format_ == model::VtkFormat::binary) {
    append_bytes(appended_, finite(v));
    return;
  }
  start_value();
  xml("{}", finite(v));
}

void VtuDataArrays::integer(std::int64_t v) {
  if (format_ == model::VtkFormat::binary) {
    switch (type_) {
      case VtkType::int32:
        append_bytes(appended_, static_cast<std::int32_t>(v));
        break;
      case VtkType::uint8:
        append_bytes(appended_, static_cast<std::uint8_t>(v));
        break;
      case VtkType::int64:
        append_bytes(appended_, v);
        break;
      case VtkType::float64:
        append_bytes(appended_, static_cast<double>(v));
        break;
    }
    return;
  }
  start_value();
  xml("{}", v);
}

void VtuDataArrays::end_line(bool trailing_space) {
  if (format_ == model::VtkFormat::binary) return;
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
  if (format_ == model::VtkFormat::binary) {
    const std::uint64_t bytes = appended_.size() - block_;
    std::memcpy(appended_.data() + block_ - sizeof bytes, &bytes, sizeof bytes);
    return;
  }
  if (line_open_) end_line();
  xml("{:{}}</DataArray>\n", "", indent_);
}

std::string VtuDataArrays::finish() {
  constexpr std::string_view kOpen = "  <AppendedData encoding=\"raw\">\n   _";
  constexpr std::string_view kClose = "\n  </AppendedData>\n";
  constexpr std::string_view kEnd = "</VTKFile>\n";
  std::string file;
  const bool binary = format_ == model::VtkFormat::binary;
  file.reserve(xml_.size() + (binary ? kOpen.size() + appended_.size() + kClose.size() : 0) +
               kEnd.size());
  file.append(xml_.data(), xml_.size());
  if (binary) {
    file.append(kOpen);
    file.append(appended_);
    file.append(kClose);
  }
  file.append(kEnd);
  return file;
}

}  // namespace isoflex::io
