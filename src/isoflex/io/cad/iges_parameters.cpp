#include "isoflex/io/cad/iges_parameters.hpp"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <fstream>

namespace isoflex::io::detail {

namespace {

// The fixed 80-column line: data in columns 1–72 (1–64 in the P section), section letter in 73.
struct Sections {
  std::string global, parameters;     // G text; P data, each line's 64 columns
  std::vector<int> parameter_owner;   // per P line: the D number it belongs to
  std::map<int, int> directory_type;  // D number of an entry's first line → entity type
};

Sections read_sections(const std::filesystem::path& file) {
  Sections s;
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.size() < 73) continue;
    const char section = line[72];
    if (section == 'G') {
      s.global += line.substr(0, 72);
    } else if (section == 'D') {
      const int seq = std::atoi(line.substr(73).c_str());
      if (seq % 2 == 1) s.directory_type[seq] = std::atoi(line.substr(0, 8).c_str());
    } else if (section == 'P') {
      s.parameters += line.substr(0, 64);
      s.parameter_owner.push_back(std::atoi(line.substr(64, 8).c_str()));
    }
  }
  return s;
}

// Global parameters 1 and 2: "1H<c>" or empty (',' and ';').
void delimiters(const std::string& g, char& parameter, char& record) {
  parameter = ',';
  record = ';';
  std::size_t at = 0;
  if (g.compare(0, 2, "1H") == 0 && g.size() > 2) {
    parameter = g[2];
    at = 3;
  }
  if (at < g.size() && g[at] == parameter) ++at;
  if (g.compare(at, 2, "1H") == 0 && g.size() > at + 2) record = g[at + 2];
}

// Splits one entity's parameter text at the delimiters, keeping Hollerith strings (nH…) whole.
std::vector<std::string> split(const std::string& text, char parameter, char record) {
  std::vector<std::string> out;
  std::string cur;
  for (std::size_t k = 0; k < text.size(); ++k) {
    const char c = text[k];
    if (c == parameter || c == record) {
      out.push_back(cur);
      cur.clear();
      if (c == record) break;
      continue;
    }
    if (c == 'H' && !cur.empty() &&
        std::all_of(cur.begin(), cur.end(), [](unsigned char d) { return std::isdigit(d); })) {
      const std::size_t n = std::strtoul(cur.c_str(), nullptr, 10);
      cur += text.substr(k, n + 1);
      k += n;
      continue;
    }
    if (c != ' ') cur += c;
  }
  return out;
}

}  // namespace

std::map<int, IgesEntityParameters> iges_parameters_of_type(const std::filesystem::path& file,
                                                            int type) {
  const Sections s = read_sections(file);
  char parameter = ',', record = ';';
  delimiters(s.global, parameter, record);
  // Each entity's text: the P lines that name its D number, in order.
  std::map<int, std::string> text;
  for (std::size_t k = 0; k < s.parameter_owner.size(); ++k)
    if (const auto d = s.directory_type.find(s.parameter_owner[k]);
        d != s.directory_type.end() && d->second == type)
      text[s.parameter_owner[k]] += s.parameters.substr(64 * k, 64);
  std::map<int, IgesEntityParameters> out;
  for (const auto& [d, t] : text) {
    std::vector<std::string> values = split(t, parameter, record);
    if (values.empty()) continue;
    IgesEntityParameters& e = out[d];
    e.type = std::atoi(values.front().c_str());
    e.values.assign(values.begin() + 1, values.end());
  }
  return out;
}

bool iges_real(const std::string& text, double& value) {
  std::string t = text;
  for (char& c : t)
    if (c == 'D' || c == 'd') c = 'E';
  if (t.empty()) return false;
  char* end = nullptr;
  value = std::strtod(t.c_str(), &end);
  return *end == '\0';
}

}  // namespace isoflex::io::detail
