#pragma once
// Reading back the ascii .vtu (VTK XML) files written by the writers, by plain string search, and
// a small well-formedness check of XML (enough for what the writers produce; no DTDs, no CDATA).
#include <cctype>
#include <sstream>
#include <string>
#include <vector>

namespace isoflex::test {

// The numbers of the first <DataArray ... Name="name" ...> … </DataArray> of `xml` (empty if
// there is no array of that name).
inline std::vector<double> data_array(const std::string& xml, const std::string& name) {
  const auto at = xml.find("Name=\"" + name + "\"");
  if (at == std::string::npos) return {};
  const auto begin = xml.find('>', at) + 1;
  const auto end = xml.find("</DataArray>", begin);
  std::istringstream in(xml.substr(begin, end - begin));
  std::vector<double> values;
  for (double v; in >> v;) values.push_back(v);
  return values;
}

// The Name attributes of the DataArrays inside the first <element …> … </element> of `xml`, in
// order (e.g. element "CellData"; empty if there is no such element).
inline std::vector<std::string> data_array_names(const std::string& xml,
                                                 const std::string& element) {
  std::vector<std::string> names;
  auto open = xml.find("<" + element + ">");
  if (open == std::string::npos) open = xml.find("<" + element + " ");
  if (open == std::string::npos) return names;
  const auto close = xml.find("</" + element + ">", open);
  for (auto at = xml.find("<DataArray", open); at < close; at = xml.find("<DataArray", at + 1)) {
    const auto name = xml.find("Name=\"", at);
    if (name == std::string::npos || name > xml.find('>', at)) continue;
    const auto begin = name + 6;
    names.push_back(xml.substr(begin, xml.find('"', begin) - begin));
  }
  return names;
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
// without '<' or stray '&'); otherwise what is wrong and at which byte offset.
inline std::string xml_error(const std::string& xml) {
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
