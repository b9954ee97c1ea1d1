#pragma once
// Reading back the ascii .vtu (VTK XML) files written by the writers, by plain string search.
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

}  // namespace isoflex::test
