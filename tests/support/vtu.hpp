#pragma once
// Reading back the .vtu (VTK XML) files written by the writers, ascii or appended raw binary
// (io/vtu_data_arrays.hpp), by plain string search, and a small well-formedness check of XML
// (enough for what the writers produce; no DTDs, no CDATA).
#include <algorithm>
#include <bit>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace isoflex::test {

namespace detail {
// The value of attribute `key` of the tag that starts at `tag` ("" if it has none).
inline std::string tag_attribute(const std::string& xml, std::size_t tag, const std::string& key) {
  const auto end = xml.find('>', tag);
  const auto at = xml.find(" " + key + "=\"", tag);
  if (at == std::string::npos || at > end) return "";
  const auto begin = at + key.size() + 3;
  return xml.substr(begin, xml.find('"', begin) - begin);
}

// Where the raw bytes of <AppendedData encoding="raw"> begin (after its '_'); the end of `xml`
// without such a section. Tags are searched only before it: the raw bytes may contain anything.
inline std::size_t raw_data_begin(const std::string& xml) {
  const auto at = xml.find("<AppendedData encoding=\"raw\">");
  if (at == std::string::npos) return xml.size();
  const auto underscore = xml.find('_', at);
  return underscore == std::string::npos ? xml.size() : underscore + 1;
}

template <class T>
T read_raw(const std::string& xml, std::size_t at) {
  if (at + sizeof(T) > xml.size()) throw std::runtime_error("appended data past the end of file");
  T v;
  std::memcpy(&v, xml.data() + at, sizeof(T));
  return v;
}

// The values of the appended array whose <DataArray> starts at `tag`: the block at its offset,
// a UInt64 byte count (header_type="UInt64") and that many little-endian bytes of its type.
inline std::vector<double> appended_values(const std::string& xml, std::size_t tag) {
  const auto file = xml.find("<VTKFile");
  if (file == std::string::npos || tag_attribute(xml, file, "header_type") != "UInt64" ||
      tag_attribute(xml, file, "byte_order") != "LittleEndian")
    throw std::runtime_error("appended data without header_type=\"UInt64\", LittleEndian");
  const std::size_t block = raw_data_begin(xml) + std::stoull(tag_attribute(xml, tag, "offset"));
  const auto bytes = read_raw<std::uint64_t>(xml, block);
  const std::string type = tag_attribute(xml, tag, "type");
  const std::size_t size = type == "UInt8" ? 1 : type == "Int32" ? 4 : 8;
  if (bytes % size != 0) throw std::runtime_error("appended block not a whole number of values");
  std::vector<double> values;
  for (std::size_t at = block + 8; at < block + 8 + bytes; at += size) {
    if (type == "Float64")
      values.push_back(read_raw<double>(xml, at));
    else if (type == "Int64")
      values.push_back(static_cast<double>(read_raw<std::int64_t>(xml, at)));
    else if (type == "Int32")
      values.push_back(read_raw<std::int32_t>(xml, at));
    else if (type == "UInt8")
      values.push_back(read_raw<std::uint8_t>(xml, at));
    else
      throw std::runtime_error("appended array of type " + type);
  }
  return values;
}
}  // namespace detail

// The numbers of the first <DataArray ... Name="name" ...> of `xml`, ascii (the text up to
// </DataArray>) or appended (its block of the raw appended data); empty if there is no array of
// that name.
inline std::vector<double> data_array(const std::string& xml, const std::string& name) {
  const auto at = xml.find("Name=\"" + name + "\"");
  if (at == std::string::npos || at >= detail::raw_data_begin(xml)) return {};
  const auto tag = xml.rfind("<DataArray", at);
  if (detail::tag_attribute(xml, tag, "format") == "appended")
    return detail::appended_values(xml, tag);
  const auto begin = xml.find('>', at) + 1;
  const auto end = xml.find("</DataArray>", begin);
  std::istringstream in(xml.substr(begin, end - begin));
  std::vector<double> values;
  for (double v; in >> v;) values.push_back(v);
  return values;
}

// "" if the raw appended data of `xml` (if any) are exactly the blocks of its format="appended"
// DataArrays: taken in the order of their offsets, the first at 0, each a UInt64 byte count and
// that many bytes, each next one where the previous ends, and after the last only white space up
// to </AppendedData>, then </VTKFile>. Otherwise what is wrong.
inline std::string appended_data_error(const std::string& xml) {
  const std::size_t raw = detail::raw_data_begin(xml);
  std::vector<std::size_t> offsets;
  for (auto at = xml.find("<DataArray"); at < raw; at = xml.find("<DataArray", at + 1)) {
    if (detail::tag_attribute(xml, at, "format") != "appended") continue;
    const std::string offset = detail::tag_attribute(xml, at, "offset");
    if (offset.empty() || offset.find_first_not_of("0123456789") != std::string::npos)
      return "appended DataArray without an offset at byte " + std::to_string(at);
    offsets.push_back(std::stoull(offset));
  }
  if (raw == xml.size()) return offsets.empty() ? "" : "appended DataArrays but no AppendedData";
  std::sort(offsets.begin(), offsets.end());
  std::size_t end = 0;  // of the blocks so far, relative to `raw`
  for (const std::size_t offset : offsets) {
    if (offset != end)
      return "block at offset " + std::to_string(offset) + ", the previous ends at " +
             std::to_string(end);
    if (raw + end + 8 > xml.size()) return "block header past the end of file";
    end += 8 + detail::read_raw<std::uint64_t>(xml, raw + end);
    if (raw + end > xml.size()) return "block past the end of file";
  }
  std::size_t k = raw + end;
  while (k < xml.size() && std::isspace(static_cast<unsigned char>(xml[k]))) ++k;
  if (xml.compare(k, std::string::npos, "</AppendedData>\n</VTKFile>\n") != 0)
    return "the blocks end at offset " + std::to_string(end) + ", not at </AppendedData>";
  return "";
}

// The Name attributes of the DataArrays inside the first <element …> … </element> of `xml`, in
// order (e.g. element "CellData", or "VTKFile" for all; empty if there is no such element).
inline std::vector<std::string> data_array_names(const std::string& xml,
                                                 const std::string& element) {
  std::vector<std::string> names;
  auto open = xml.find("<" + element + ">");
  if (open == std::string::npos) open = xml.find("<" + element + " ");
  const std::size_t raw = detail::raw_data_begin(xml);
  if (open >= raw) return names;
  const auto close = std::min(xml.find("</" + element + ">", open), raw);
  for (auto at = xml.find("<DataArray", open); at < close; at = xml.find("<DataArray", at + 1)) {
    const auto name = xml.find("Name=\"", at);
    if (name == std::string::npos || name > xml.find('>', at)) continue;
    const auto begin = name + 6;
    names.push_back(xml.substr(begin, xml.find('"', begin) - begin));
  }
  return names;
}

// "" if `a` and `b` have the same DataArrays (names and types, in order) with the same values bit
// for bit, as a binary and an ascii file of the same data should; otherwise the first difference.
inline std::string data_arrays_difference(const std::string& a, const std::string& b) {
  const auto names = data_array_names(a, "VTKFile");
  if (data_array_names(b, "VTKFile") != names) return "other arrays";
  const auto type = [](const std::string& xml, const std::string& name) {
    return detail::tag_attribute(xml, xml.rfind("<DataArray", xml.find("Name=\"" + name + "\"")),
                                 "type");
  };
  for (const auto& name : names) {
    if (type(a, name) != type(b, name)) return name + ": other types";
    const auto va = data_array(a, name), vb = data_array(b, name);
    if (va.size() != vb.size()) return name + ": other sizes";
    for (std::size_t k = 0; k < va.size(); ++k)
      if (std::bit_cast<std::uint64_t>(va[k]) != std::bit_cast<std::uint64_t>(vb[k])) {
        std::ostringstream out;
        out.precision(17);
        out << name << "[" << k << "]: " << va[k] << " vs " << vb[k];
        return out.str();
      }
  }
  return "";
}

namespace detail {
inline bool xml_name_char(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.' ||
         c == ':' || static_cast<unsigned char>(c) >= 0x80;
}
// Text or an attribute value from `begin` to `end`: no '<', and every '&' starts a predefined or
// numeric entity.
inline bool xml_text_ok(const std::string& xml, std::size_t begin, std::size_t end) {
  for (std::size_t i = begin; i < end; ++i) {
    if (xml[i] == '<') return false;
    if (xml[i] != '&') continue;
    const auto semi = xml.find(';', i);
    if (semi == std::string::npos || semi >= end) return false;
    const std::string ref = xml.substr(i + 1, semi - i - 1);
    const bool named = ref == "amp" || ref == "lt" || ref == "gt" || ref == "quot" || ref == "apos";
    const bool numeric = ref.size() > 1 && ref[0] == '#';
    if (!named && !numeric) return false;
    i = semi;
  }
  return true;
}
}  // namespace detail

// "" if `xml` is well-formed XML (an optional <?xml …?> declaration, comments, exactly one root
// element, tags properly nested, attribute values quoted and unique per tag, text and values
// without '<' or stray '&'); otherwise what is wrong and at which byte offset. Raw appended data
// (not XML) must pass appended_data_error and are then left out.
inline std::string xml_error(const std::string& file) {
  if (const std::string error = appended_data_error(file); !error.empty()) return error;
  const std::size_t raw = detail::raw_data_begin(file);
  const std::string xml =
      raw == file.size() ? file : file.substr(0, raw) + file.substr(file.rfind("</AppendedData>"));
  std::vector<std::string> open;
  int roots = 0;
  std::size_t i = 0, text = 0;
  auto fail = [](const std::string& what, std::size_t at) {
    return what + " at offset " + std::to_string(at);
  };
  while (i < xml.size()) {
    if (xml[i] != '<') {
      ++i;
      continue;
    }
    if (!detail::xml_text_ok(xml, text, i)) return fail("bad character data", text);
    const bool outside = open.empty();
    if (outside) {  // only white space outside the root element
      for (std::size_t k = text; k < i; ++k)
        if (!std::isspace(static_cast<unsigned char>(xml[k]))) return fail("text outside root", k);
    }
    if (xml.compare(i, 4, "<!--") == 0) {
      const auto end = xml.find("-->", i + 4);
      if (end == std::string::npos) return fail("unterminated comment", i);
      if (xml.substr(i + 4, end - i - 4).find("--") != std::string::npos)
        return fail("'--' in comment", i);
      i = text = end + 3;
      continue;
    }
    if (xml.compare(i, 2, "<?") == 0) {
      if (i != 0) return fail("processing instruction not at the start", i);
      const auto end = xml.find("?>", i);
      if (end == std::string::npos) return fail("unterminated declaration", i);
      i = text = end + 2;
      continue;
    }
    const bool closing = xml.compare(i, 2, "</") == 0;
    std::size_t k = i + (closing ? 2 : 1);
    const std::size_t name_begin = k;
    while (k < xml.size() && detail::xml_name_char(xml[k])) ++k;
    const std::string name = xml.substr(name_begin, k - name_begin);
    if (name.empty() || std::isdigit(static_cast<unsigned char>(name[0])) || name[0] == '-')
      return fail("bad tag name", i);
    if (closing) {
      while (k < xml.size() && std::isspace(static_cast<unsigned char>(xml[k]))) ++k;
      if (k >= xml.size() || xml[k] != '>') return fail("bad end tag", i);
      if (open.empty() || open.back() != name)
        return fail("end tag </" + name + "> does not match", i);
      open.pop_back();
      i = text = k + 1;
      continue;
    }
    std::vector<std::string> attributes;
    bool self_closing = false;
    for (;;) {
      const std::size_t before = k;
      while (k < xml.size() && std::isspace(static_cast<unsigned char>(xml[k]))) ++k;
      if (k >= xml.size()) return fail("unterminated tag <" + name, i);
      if (xml[k] == '>') break;
      if (xml.compare(k, 2, "/>") == 0) {
        self_closing = true;
        ++k;
        break;
      }
      if (k == before) return fail("no space before attribute", k);
      const std::size_t a = k;
      while (k < xml.size() && detail::xml_name_char(xml[k])) ++k;
      const std::string attribute = xml.substr(a, k - a);
      if (attribute.empty()) return fail("bad attribute", a);
      for (const auto& seen : attributes)
        if (seen == attribute) return fail("duplicate attribute " + attribute, a);
      attributes.push_back(attribute);
      if (k + 1 >= xml.size() || xml[k] != '=' || (xml[k + 1] != '"' && xml[k + 1] != '\''))
        return fail("attribute " + attribute + " without a quoted value", a);
      const auto end = xml.find(xml[k + 1], k + 2);
      if (end == std::string::npos) return fail("unterminated attribute value", k);
      if (!detail::xml_text_ok(xml, k + 2, end)) return fail("bad attribute value", k + 2);
      k = end + 1;
    }
    if (open.empty()) {
      if (++roots > 1) return fail("second root element <" + name + ">", i);
    }
    if (!self_closing) open.push_back(name);
    i = text = k + 1;
  }
  if (!open.empty()) return "unclosed element <" + open.back() + ">";
  if (roots != 1) return "no root element";
  for (std::size_t k = text; k < xml.size(); ++k)
    if (!std::isspace(static_cast<unsigned char>(xml[k]))) return fail("text outside root", k);
  return "";
}

}  // namespace isoflex::test
