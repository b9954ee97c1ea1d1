// A bounded mutation fuzz test (issue #15 "Keep it that way"): model files made from the
// examples and CAD files from tests/data/cad, mutated with a fixed seed, run through the real
// `isoflex` executable (ISOFLEX_BINARY) with `check` and, where check accepts the model, `run`.
// For every input it asserts what README "Exit codes" promises:
//   - the process ends by itself within a time limit (no hang) and is not killed by a signal;
//   - `check` exits 0 or 2, `run` exits 0, 2 or 3 (4 is an output error, which the test does
//     not cause: its output folder is always writable);
//   - exit 2 prints a located message "error: FILE:LINE: …" naming the model file, and writes
//     nothing;
//   - exit 3 writes summary.json with "status": "failed";
//   - exit 0 leaves no non-finite number (nan, inf; null in summary.json) in any output file.
// A failing input is saved to fuzz-findings/ in the build folder (the model file, and the CAD
// file it reads) and printed with the command that reproduces it.
//
// The seeds are shortened (2 steps, coarse meshes) so that a run takes tens of milliseconds; the
// input counts keep the whole test within about half a minute on a 2-core machine.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include "support/files.hpp"
#include "support/vtu.hpp"

namespace isoflex::test {
namespace {

namespace fs = std::filesystem;

// A child gets this long to end by itself (runs take well under a second; the CAD reader's own
// limit, below, is shorter), so that reaching it means a hang, not a slow machine.
constexpr auto kChildTimeLimit = std::chrono::seconds(30);
// The time limit of the CAD reading process (ISOFLEX_CAD_TIME_LIMIT): OpenCASCADE may spin on a
// mutated file (issue #15: a knot of −1e300); isoflex then reports a located error (exit 2),
// which is a pass, so a short limit only keeps such inputs cheap.
constexpr const char* kCadTimeLimitSeconds = "1";

// splitmix64: the same inputs on every machine and standard library (the distributions of
// <random> are implementation-defined).
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : s_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (s_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  std::size_t below(std::size_t n) { return n == 0 ? 0 : static_cast<std::size_t>(next() % n); }
  template <class T>
  const T& pick(const std::vector<T>& v) {
    return v[below(v.size())];
  }

 private:
  std::uint64_t s_;
};

// ---- running the executable ------------------------------------------------------------------

struct ChildResult {
  bool timed_out = false;
  bool exited = false;
  int code = -1;
  int signal = 0;
  std::string output;  // stdout and stderr
};

// `isoflex ARGS` with stdout and stderr in `log`, in a process group of its own so that a
// timeout kills the CAD reading grandchild too.
ChildResult run_limited(const std::vector<std::string>& args, const fs::path& log) {
  std::vector<std::string> argv_s = args;
  argv_s.insert(argv_s.begin(), ISOFLEX_BINARY);
  std::vector<char*> argv;
  for (auto& a : argv_s) argv.push_back(a.data());
  argv.push_back(nullptr);
  const std::string log_s = log.string();
  ChildResult r;
  const pid_t pid = ::fork();
  if (pid < 0) {
    r.output = "fork failed";
    return r;
  }
  if (pid == 0) {  // async-signal-safe calls only until exec
    ::setpgid(0, 0);
    const int fd = ::open(log_s.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) {
      ::dup2(fd, 1);
      ::dup2(fd, 2);
    }
    ::signal(SIGINT, SIG_DFL);
    ::signal(SIGTERM, SIG_DFL);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  ::setpgid(pid, pid);  // also here: whichever runs first, the group exists before a kill
  const auto deadline = std::chrono::steady_clock::now() + kChildTimeLimit;
  auto pause = std::chrono::microseconds(100);
  for (;;) {
    int status = 0;
    const pid_t w = ::waitpid(pid, &status, WNOHANG);
    if (w == pid) {
      if (WIFEXITED(status)) {
        r.exited = true;
        r.code = WEXITSTATUS(status);
      } else if (WIFSIGNALED(status)) {
        r.signal = WTERMSIG(status);
      }
      break;
    }
    if (w < 0) break;
    if (std::chrono::steady_clock::now() > deadline) {
      r.timed_out = true;
      ::kill(-pid, SIGKILL);
      ::waitpid(pid, nullptr, 0);
      break;
    }
    std::this_thread::sleep_for(pause);
    pause = std::min(pause * 2, std::chrono::microseconds(5000));
  }
  ::kill(-pid, SIGKILL);  // a grandchild left behind (none expected)
  r.output = read_text(log);
  return r;
}

// ---- what the outputs may not contain --------------------------------------------------------

bool is_token_char(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.' || c == '+' ||
         c == '-';
}

// The first non-finite number in the files of `dir` (recursively), as "FILE: …", or "".
// nan and inf as printed by fmt/printf ("nan", "-nan", "inf", "-inf"), and in summary.json
// `null`, which is how it writes a non-finite number, except for max_energy_drift_after_loads
// (NaN by design when loads act, README). In a .vtu with binary arrays the values are read from
// the appended data and only the markup before it is searched as text.
std::string non_finite_in_outputs(const fs::path& dir) {
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    if (!entry.is_regular_file()) continue;
    std::string text = read_text(entry.path());
    const std::string name = entry.path().filename().string();
    if (entry.path().extension() == ".vtu") {
      for (const auto& array : test::data_array_names(text, "VTKFile"))
        for (const double v : test::data_array(text, array))
          if (!std::isfinite(v))
            return fs::relative(entry.path(), dir).string() + ": " + std::to_string(v) + " in " +
                   array;
      text.resize(test::detail::raw_data_begin(text));
    }
    for (std::size_t i = 0; i < text.size();) {
      if (!is_token_char(text[i])) {
        ++i;
        continue;
      }
      std::size_t j = i;
      while (j < text.size() && is_token_char(text[j])) ++j;
      std::string token = text.substr(i, j - i);
      std::transform(token.begin(), token.end(), token.begin(),
                     [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
      const std::string bare = token.find_first_not_of("+-") == std::string::npos
                                   ? token
                                   : token.substr(token.find_first_not_of("+-"));
      const bool non_finite = bare == "nan" || bare == "inf" || bare == "infinity";
      bool bad_null = false;
      if (bare == "null" && name == "summary.json") {
        const auto key_end = text.rfind("\":", i);
        const auto key_begin =
            key_end == std::string::npos ? key_end : text.rfind('"', key_end - 1);
        const std::string key = key_begin == std::string::npos
                                    ? ""
                                    : text.substr(key_begin + 1, key_end - key_begin - 1);
        bad_null = key != "max_energy_drift_after_loads";
      }
      if (non_finite || bad_null) {
        const std::size_t from = i > 80 ? i - 80 : 0;
        return fs::relative(entry.path(), dir).string() + ": '" + token + "' in …" +
               text.substr(from, std::min<std::size_t>(j - from + 40, 200)) + "…";
      }
      i = j;
    }
  }
  return "";
}

// ---- mutations -------------------------------------------------------------------------------

// Extreme and edge values for numbers: overflow, signed zero, NaN and infinities as YAML writes
// them (.nan, .inf) and as text, subnormals, integers at and past the int and int64 limits.
const std::vector<std::string> kExtremeNumbers = {"1e308",
                                                  "-1e308",
                                                  "1e309",
                                                  "-0",
                                                  "0",
                                                  "0.0",
                                                  ".nan",
                                                  ".NaN",
                                                  "nan",
                                                  ".inf",
                                                  "-.inf",
                                                  "inf",
                                                  "1e-308",
                                                  "4.9e-324",
                                                  "-1e-308",
                                                  "2147483647",
                                                  "2147483648",
                                                  "-2147483648",
                                                  "-2147483649",
                                                  "4294967296",
                                                  "1e30",
                                                  "1e-30",
                                                  "1e15",
                                                  "9223372036854775807",
                                                  "9223372036854775808",
                                                  "99999999999999999999"};
// Ordinary small values (another count, index, degree or sign). Not for dt and t_end: t_end = 10
// would make a seed of 2 steps a legitimate run of 1000, too long for this test.
const std::vector<std::string> kSmallNumbers = {"-1", "1", "2", "0.5", "-3", "3", "10"};
// Values of other types for "change the type" mutations.
const std::vector<std::string> kYamlValues = {"[1, 2, 3]",
                                              "[]",
                                              "{a: 1}",
                                              "{}",
                                              "\"text\"",
                                              "true",
                                              "~",
                                              "\"\"",
                                              "[[1, 2], [3]]",
                                              "[1e308, -1e308, .nan]",
                                              "-",
                                              "ground",
                                              "\"1/0\"",
                                              "\"sqrt(-1)\"",
                                              "\"log(0)\"",
                                              "\"t^1e9\""};
// Characters for byte insertions: YAML syntax, a tab, a NUL byte and a byte that is not UTF-8.
const std::string kYamlBytes =
    std::string(":-[]{}\"'#\t&*!|>,%@` \n") + std::string(1, '\0') + std::string(1, '\xff');

// Start and end of every number in `text` that is a token of its own (not part of a name such
// as b1), including those inside time-function strings.
std::vector<std::pair<std::size_t, std::size_t>> number_spans(const std::string& text) {
  std::vector<std::pair<std::size_t, std::size_t>> spans;
  const auto word = [&](std::size_t k) {
    return k < text.size() &&
           (std::isalnum(static_cast<unsigned char>(text[k])) || text[k] == '_' || text[k] == '.');
  };
  for (std::size_t i = 0; i < text.size(); ++i) {
    const bool digit = std::isdigit(static_cast<unsigned char>(text[i]));
    if (!digit || (i > 0 && word(i - 1))) continue;
    std::size_t b = i;
    if (b > 0 && (text[b - 1] == '-' || text[b - 1] == '+')) --b;
    std::size_t e = i;
    while (e < text.size() && (std::isdigit(static_cast<unsigned char>(text[e])) ||
                               text[e] == '.' || text[e] == 'e' || text[e] == 'E' ||
                               ((text[e] == '-' || text[e] == '+') && e > 0 &&
                                (text[e - 1] == 'e' || text[e - 1] == 'E'))))
      ++e;
    if (word(e)) {  // e.g. 2D or a name: skip it
      i = e;
      continue;
    }
    spans.emplace_back(b, e);
    i = e;
  }
  return spans;
}

std::vector<std::string> split_lines(const std::string& text) {
  std::vector<std::string> lines;
  std::size_t b = 0;
  for (std::size_t e = text.find('\n'); e != std::string::npos; b = e + 1, e = text.find('\n', b))
    lines.push_back(text.substr(b, e - b));
  if (b < text.size()) lines.push_back(text.substr(b));
  return lines;
}

std::string join_lines(const std::vector<std::string>& lines) {
  std::string text;
  for (const auto& l : lines) text += l + "\n";
  return text;
}

// Keys of the YAML text ("name:" followed by a blank or the end of the line), as spans.
std::vector<std::pair<std::size_t, std::size_t>> key_spans(const std::string& text) {
  std::vector<std::pair<std::size_t, std::size_t>> spans;
  static const std::regex key(R"(([A-Za-z_][A-Za-z0-9_]*):(?=[ \n]))");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), key); it != std::sregex_iterator();
       ++it)
    spans.emplace_back(static_cast<std::size_t>(it->position(1)),
                       static_cast<std::size_t>(it->position(1) + it->length(1)));
  return spans;
}

// Scalar values after "key: " up to the end of a flow item or line, as spans.
std::vector<std::pair<std::size_t, std::size_t>> value_spans(const std::string& text) {
  std::vector<std::pair<std::size_t, std::size_t>> spans;
  static const std::regex value(R"(: ([^,\]\}\n\[\{][^,\]\}\n]*))");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), value);
       it != std::sregex_iterator(); ++it)
    spans.emplace_back(static_cast<std::size_t>(it->position(1)),
                       static_cast<std::size_t>(it->position(1) + it->length(1)));
  return spans;
}

// One mutation of a model file; appends what it did to `log`.
std::string mutate_yaml_once(std::string text, Rng& rng, std::string& log) {
  const std::size_t kind = rng.below(100);
  if (kind < 45) {  // a number → an extreme value
    const auto spans = number_spans(text);
    if (spans.empty()) return text;
    const auto [b, e] = rng.pick(spans);
    const std::size_t line_start =
        text.rfind('\n', b) == std::string::npos ? 0 : text.rfind('\n', b);
    const std::string line = text.substr(line_start, text.find('\n', b) - line_start);
    const bool step_size =
        line.find("dt:") != std::string::npos || line.find("t_end:") != std::string::npos;
    const std::string to =
        step_size || rng.below(4) != 0 ? rng.pick(kExtremeNumbers) : rng.pick(kSmallNumbers);
    log +=
        "number '" + text.substr(b, e - b) + "' at byte " + std::to_string(b) + " -> " + to + "; ";
    return text.replace(b, e - b, to);
  }
  auto lines = split_lines(text);
  if (lines.empty()) return text;
  if (kind < 55) {  // delete a line
    const std::size_t i = rng.below(lines.size());
    log += "delete line " + std::to_string(i + 1) + "; ";
    lines.erase(lines.begin() + static_cast<std::ptrdiff_t>(i));
    return join_lines(lines);
  }
  if (kind < 62) {  // duplicate a line
    const std::size_t i = rng.below(lines.size());
    log += "duplicate line " + std::to_string(i + 1) + "; ";
    lines.insert(lines.begin() + static_cast<std::ptrdiff_t>(i), lines[i]);
    return join_lines(lines);
  }
  if (kind < 67) {  // swap two lines
    const std::size_t i = rng.below(lines.size()), j = rng.below(lines.size());
    log += "swap lines " + std::to_string(i + 1) + ", " + std::to_string(j + 1) + "; ";
    std::swap(lines[i], lines[j]);
    return join_lines(lines);
  }
  if (kind < 70) {  // indent a line by two spaces more or less
    const std::size_t i = rng.below(lines.size());
    if (rng.below(2) == 0 || lines[i].rfind("  ", 0) != 0) {
      log += "indent line " + std::to_string(i + 1) + "; ";
      lines[i] = "  " + lines[i];
    } else {
      log += "dedent line " + std::to_string(i + 1) + "; ";
      lines[i] = lines[i].substr(2);
    }
    return join_lines(lines);
  }
  if (kind < 80) {  // a key → another key of the file
    const auto spans = key_spans(text);
    if (spans.empty()) return text;
    const auto [b, e] = rng.pick(spans);
    const auto [b2, e2] = rng.pick(spans);
    const std::string to = text.substr(b2, e2 - b2);
    log += "key '" + text.substr(b, e - b) + "' at byte " + std::to_string(b) + " -> " + to + "; ";
    return text.replace(b, e - b, to);
  }
  if (kind < 90) {  // a value → a value of another type
    const auto spans = value_spans(text);
    if (spans.empty()) return text;
    const auto [b, e] = rng.pick(spans);
    const std::string to = rng.pick(kYamlValues);
    log +=
        "value '" + text.substr(b, e - b) + "' at byte " + std::to_string(b) + " -> " + to + "; ";
    return text.replace(b, e - b, to);
  }
  // A byte: inserted, deleted or replaced.
  const std::size_t at = rng.below(text.size());
  const char c = kYamlBytes[rng.below(kYamlBytes.size())];
  const std::size_t how = rng.below(3);
  log += std::string(how == 0   ? "insert"
                     : how == 1 ? "delete"
                                : "replace") +
         " byte " + std::to_string(at) +
         (how == 1 ? "" : " (" + std::to_string(static_cast<unsigned char>(c)) + ")") + "; ";
  if (how == 0) return text.insert(at, 1, c);
  if (how == 1) return text.erase(at, 1);
  text[at] = c;
  return text;
}

// 1 to 3 mutations.
std::string mutate_yaml(const std::string& text, Rng& rng, std::string& log) {
  std::string out = text;
  const std::size_t n = 1 + rng.below(3);
  for (std::size_t k = 0; k < n; ++k) out = mutate_yaml_once(out, rng, log);
  return out;
}

// Numbers for CAD files: IGES/STEP spell reals as 1.E300 or 1.0D0; huge counts and degrees.
const std::vector<std::string> kCadNumbers = {
    "0",  "-1", "1E300", "-1E300", "1.E-300", "0.", "-0.",        "2000000000", "100",
    "11", "3",  "0.5",   "1.0D0",  "1E309",   "-2", "2147483648", "1.E+15",     "99999999999"};

// One mutation of an IGES (fixed 80-column lines: data in columns 1–72, the section letter and
// sequence number after) or STEP file.
std::string mutate_cad_once(const std::string& text, bool iges, Rng& rng, std::string& log) {
  auto lines = split_lines(text);
  if (lines.empty()) return text;
  const std::size_t kind = rng.below(100);
  if (kind < 60) {  // a number in a line → another
    // Lines with numbers; in IGES only the data columns count.
    for (int attempt = 0; attempt < 20; ++attempt) {
      const std::size_t i = rng.below(lines.size());
      std::string& line = lines[i];
      const std::size_t data_end = iges ? std::min<std::size_t>(line.size(), 72) : line.size();
      std::string data = line.substr(0, data_end);
      const auto spans = number_spans(data);
      if (spans.empty()) continue;
      const auto [b, e] = rng.pick(spans);
      const std::string to = rng.pick(kCadNumbers);
      log += "line " + std::to_string(i + 1) + ": number '" + data.substr(b, e - b) + "' -> " + to +
             "; ";
      data.replace(b, e - b, to);
      if (iges) {  // keep the columns: pad or cut the data to 72 columns
        data.resize(72, ' ');
        line = data + line.substr(data_end);
      } else {
        line = data;
      }
      return join_lines(lines);
    }
    return text;
  }
  if (kind < 85) {  // delete a line
    const std::size_t i = rng.below(lines.size());
    log += "delete line " + std::to_string(i + 1) + "; ";
    lines.erase(lines.begin() + static_cast<std::ptrdiff_t>(i));
    return join_lines(lines);
  }
  if (kind < 93) {  // duplicate a line
    const std::size_t i = rng.below(lines.size());
    log += "duplicate line " + std::to_string(i + 1) + "; ";
    lines.insert(lines.begin() + static_cast<std::ptrdiff_t>(i), lines[i]);
    return join_lines(lines);
  }
  const std::size_t i = rng.below(lines.size()), j = rng.below(lines.size());
  log += "swap lines " + std::to_string(i + 1) + ", " + std::to_string(j + 1) + "; ";
  std::swap(lines[i], lines[j]);
  return join_lines(lines);
}

std::string mutate_cad(const std::string& text, bool iges, Rng& rng, std::string& log) {
  std::string out = text;
  const std::size_t n = 1 + rng.below(2);
  for (std::size_t k = 0; k < n; ++k) out = mutate_cad_once(out, iges, rng, log);
  return out;
}

// ---- seeds -----------------------------------------------------------------------------------

// `text` without comments (so that mutations land on data) and shortened for the fuzz test:
// t_end = 2 dt (2 time or load steps), at most 4 beam or shell elements per direction, at most
// 2 inserted knots per span.
std::string shortened(const std::string& text) {
  std::string out;
  for (std::string line : split_lines(text)) {
    // A comment starts at a '#' at the beginning or after a blank (the examples have no '#' in
    // strings).
    for (std::size_t k = line.find('#'); k != std::string::npos; k = line.find('#', k + 1))
      if (k == 0 || line[k - 1] == ' ') {
        line.erase(k);
        break;
      }
    while (!line.empty() && line.back() == ' ') line.pop_back();
    if (line.find_first_not_of(' ') == std::string::npos) continue;
    out += line + "\n";
  }
  static const std::regex dt_re(R"(\bdt: ([0-9.eE+-]+))");
  std::smatch m;
  const double dt = std::regex_search(out, m, dt_re) ? std::stod(m[1]) : 0.01;
  out = std::regex_replace(out, std::regex(R"(\bt_end: [0-9.eE+-]+)"),
                           "t_end: " + std::to_string(2 * dt));
  // Counts: a scalar or a pair, capped.
  const auto cap = [](const std::string& s, const std::regex& re, int max) {
    std::string r;
    auto begin = s.cbegin();
    std::smatch mm;
    while (std::regex_search(begin, s.cend(), mm, re)) {
      r.append(begin, mm[0].first);
      std::string piece = mm[0].str();
      std::string capped;
      for (std::size_t k = 0; k < piece.size();) {
        if (std::isdigit(static_cast<unsigned char>(piece[k])) && k > 0 &&
            (piece[k - 1] == ' ' || piece[k - 1] == '[')) {
          std::size_t e = k;
          while (e < piece.size() && std::isdigit(static_cast<unsigned char>(piece[e]))) ++e;
          capped += std::to_string(std::min(std::stoi(piece.substr(k, e - k)), max));
          k = e;
        } else {
          capped += piece[k++];
        }
      }
      r += capped;
      begin = mm[0].second;
    }
    r.append(begin, s.cend());
    return r;
  };
  out = cap(out, std::regex(R"(\belements: (\[\d+, \d+\]|\d+))"), 4);
  out = cap(out, std::regex(R"(\bknots_per_span: \[\d+, \d+\])"), 2);
  return out;
}

// The example models the model-file fuzzing starts from (all small once shortened).
const std::vector<std::string> kModelSeeds = {
    "heavy_top/model.yaml",
    "four_bar/model.yaml",
    "free_body_flip/model.yaml",
    "double_pendulum_3d/model.yaml",
    "slider_crank_rigid/model.yaml",
    "slider_crank_flexible/model.yaml",
    "free_flying_beam/model.yaml",
    "beam_roll_up/model_90.yaml",
    "intersecting_shells/model.yaml",
    "plate_roll_up/director_shell.yaml",
    "plate_roll_up/kl_shell.yaml",
    "scordelis_lo/director_shell.yaml",
    "scordelis_lo/kl_shell.yaml",
    "kirchhoff_plates/kl_shell.yaml",
    "kl_free_plate/model.yaml",
    "kl_plate_on_hub/model.yaml",
    "pinched_hemisphere/kl_shell_hole.yaml",
    "pinched_cylinder/kl_shell.yaml",
};

// The CAD files (tests/data/cad/README.md) and the model that reads one as a Kirchhoff–Love
// shell: a static linear run of one load step, so that a mutated geometry is also solved.
const std::vector<std::string> kCadSeeds = {
    "quarter_cylinder_R1_L2_deg2.igs",          "quarter_cylinder_R1_L2_deg2.stp",
    "quarter_cylinder_R1_L2_deg2_fullprec.igs", "quarter_cylinder_R1_L2_deg2_fullprec.stp",
    "l_angle_plate_2patch_L10_b1_b3_deg1.igs",  "l_angle_plate_2patch_L10_b1_b3_deg1.stp",
    "scordelis_lo_roof_2patch_split_x25.igs",   "scordelis_lo_roof_2patch_split_x25_fullprec.stp",
};

std::string cad_model(const std::string& cad_file) {
  return "name: cad\n"
         "solver: {analysis: static, dt: 1, t_end: 1, linear: true}\n"
         "surfaces:\n"
         "  - name: s\n"
         "    cad: {file: " +
         cad_file +
         ", patch: 0}\n"
         "    refine: {elevate: [1, 1], knots_per_span: [1, 1]}\n"
         "kl_shells:\n"
         "  - {name: k, surface: s, material: {E: 1000, nu: 0.3, thickness: 0.01}}\n"
         "kl_supports:\n"
         "  - {shell: k, edge: u0, clamped: true}\n"
         "kl_loads:\n"
         "  - {shell: k, area_force: [0, 0, -1]}\n";
}

// ---- one input -------------------------------------------------------------------------------

// How the inputs of a test ended, e.g. "check 0" or "run 3" → count, printed at its end so that a
// run shows what was exercised.
using Tally = std::map<std::string, int>;

std::string tally_text(const Tally& t) {
  std::string s;
  for (const auto& [k, n] : t) s += (s.empty() ? "" : ", ") + k + ": " + std::to_string(n);
  return s;
}

// Runs `check` and, if it accepts the model, `run` on the model file `model` (in `dir`); returns
// what went wrong ("" if nothing).
std::string examine(const fs::path& dir, const fs::path& model, Tally* tally = nullptr) {
  const fs::path log = dir / "log.txt";
  // "error: FILE:LINE: " with FILE the model file as given on the command line.
  const std::regex located(
      "(^|\\n)error: " +
      std::regex_replace(model.string(), std::regex(R"([.^$|()\[\]{}*+?\\])"), R"(\$&)") +
      ":[0-9]+: ");
  const auto judge = [&](const char* what, const ChildResult& r, bool may_fail) -> std::string {
    if (r.timed_out) return std::string(what) + ": no end within the time limit (killed)";
    if (!r.exited) return std::string(what) + ": killed by signal " + std::to_string(r.signal);
    if (r.code == 2 && !std::regex_search(r.output, located))
      return std::string(what) + ": exit 2 without a located message (FILE:LINE:)";
    if (r.code != 0 && r.code != 2 && !(may_fail && r.code == 3))
      return std::string(what) + ": exit code " + std::to_string(r.code);
    return "";
  };
  // `check` only reads and compiles: 0 or 2 (README "Exit codes").
  const ChildResult c = run_limited({"check", model.string()}, log);
  if (tally) {
    ++(*tally)["check exit " + std::to_string(c.code)];
    if (c.output.find("did not finish within") != std::string::npos) ++(*tally)["CAD time limit"];
  }
  if (std::string bad = judge("check", c, false); !bad.empty()) return bad + "\n" + c.output;
  if (c.code != 0) return "";
  const fs::path out = dir / "out";
  fs::remove_all(out);
  const ChildResult r =
      run_limited({"run", model.string(), "-o", out.string(), "--threads", "1"}, log);
  if (tally) ++(*tally)["run exit " + std::to_string(r.code)];
  if (std::string bad = judge("run", r, true); !bad.empty()) return bad + "\n" + r.output;
  if (r.code == 2 && fs::exists(out) && !fs::is_empty(out))
    return "run: exit 2 but files written in " + out.string() + "\n" + r.output;
  if (r.code == 3 &&
      read_text(out / "summary.json").find("\"status\": \"failed\"") == std::string::npos)
    return "run: exit 3 without summary.json \"status\": \"failed\"\n" + r.output;
  if (r.code == 0)
    if (std::string bad = non_finite_in_outputs(out); !bad.empty())
      return "run: exit 0 with a non-finite number in " + bad + "\n" + r.output;
  return "";
}

// Saves a failing input to fuzz-findings/ in the build folder and fails the test with it.
void report(const std::string& id, const std::string& problem, const std::string& mutations,
            const std::string& model_text, const std::string& cad_name = "",
            const std::string& cad_text = "") {
  const fs::path findings = fs::path(ISOFLEX_FUZZ_FINDINGS_DIR) / id;
  fs::create_directories(findings);
  write_text(findings / "model.yaml", model_text);
  if (!cad_name.empty()) write_text(findings / cad_name, cad_text);
  ADD_FAILURE() << id << ": " << problem << "\nmutations: " << mutations << "\nsaved in "
                << findings.string() << " (reproduce: " << ISOFLEX_BINARY << " check|run "
                << (findings / "model.yaml").string() << ")\n--- model.yaml ---\n"
                << model_text
                << (cad_name.empty() ? ""
                                     : "--- " + cad_name + " (first 3000 bytes) ---\n" +
                                           cad_text.substr(0, 3000));
}

// Model files: `count` mutants of the shortened examples, from `seed`.
void fuzz_models(const std::string& name, std::uint64_t seed, int count) {
  const TempDir dir(fs::temp_directory_path() /
                    ("isoflex_fuzz_" + name + "_" + std::to_string(::getpid())));
  std::vector<std::string> seeds;
  for (const auto& s : kModelSeeds) {
    const std::string text = read_text(fs::path(ISOFLEX_SOURCE_DIR) / "examples" / s);
    ASSERT_FALSE(text.empty()) << s;
    seeds.push_back(shortened(text));
  }
  Rng rng(seed);
  Tally tally;
  int failures = 0;
  for (int k = 0; k < count && failures < 10; ++k) {
    const std::size_t s = rng.below(seeds.size());
    std::string log = kModelSeeds[s] + ": ";
    const std::string text = mutate_yaml(seeds[s], rng, log);
    const fs::path model = dir.path() / "m.yaml";
    write_text(model, text);
    if (const std::string bad = examine(dir.path(), model, &tally); !bad.empty()) {
      report(name + "_" + std::to_string(k), bad, log, text);
      ++failures;
    }
  }
  std::cout << name << ": " << tally_text(tally) << "\n";
}

}  // namespace

// The shortened seeds themselves run cleanly (exit 0, finite outputs): otherwise the mutants
// would test nothing but the failure of the seed.
TEST(MutationFuzz, SeedsRunCleanly) {
  const TempDir dir(fs::temp_directory_path() /
                    ("isoflex_fuzz_seeds_" + std::to_string(::getpid())));
  for (const auto& s : kModelSeeds) {
    const fs::path model = dir.path() / "m.yaml";
    const std::string text = shortened(read_text(fs::path(ISOFLEX_SOURCE_DIR) / "examples" / s));
    write_text(model, text);
    EXPECT_EQ(examine(dir.path(), model), "") << s;
    EXPECT_TRUE(fs::exists(dir.path() / "out" / "summary.json")) << s;
    EXPECT_NE(read_text(dir.path() / "out" / "summary.json").find("\"status\": \"completed\""),
              std::string::npos)
        << s << "\n"
        << text;
  }
  for (const auto& c : kCadSeeds) {
    const fs::path cad = dir.path() / ("cad" + fs::path(c).extension().string());
    fs::copy_file(fs::path(ISOFLEX_SOURCE_DIR) / "tests/data/cad" / c, cad,
                  fs::copy_options::overwrite_existing);
    const fs::path model = dir.path() / "m.yaml";
    write_text(model, cad_model(cad.filename().string()));
    EXPECT_EQ(examine(dir.path(), model), "") << c;
    EXPECT_NE(read_text(dir.path() / "out" / "summary.json").find("\"status\": \"completed\""),
              std::string::npos)
        << c;
    fs::remove(cad);
  }
}

// The checks of the outputs can fail: a NaN in a CSV file and a null energy in summary.json are
// found, the documented null of max_energy_drift_after_loads is not.
TEST(MutationFuzz, NonFiniteOutputsAreFound) {
  const TempDir dir(fs::temp_directory_path() / ("isoflex_fuzz_nf_" + std::to_string(::getpid())));
  write_text(dir.path() / "summary.json",
             "{\n  \"energy_final\": 1.5,\n  \"max_energy_drift_after_loads\": null\n}\n");
  write_text(dir.path() / "history.csv", "t,a\n0,1\n0.1,2.5e-3\n");
  EXPECT_EQ(non_finite_in_outputs(dir.path()), "");
  write_text(dir.path() / "history.csv", "t,a\n0,1\n0.1,-nan\n");
  EXPECT_NE(non_finite_in_outputs(dir.path()), "");
  write_text(dir.path() / "history.csv", "t,a\n0,1\n0.1,inf\n");
  EXPECT_NE(non_finite_in_outputs(dir.path()), "");
  write_text(dir.path() / "history.csv", "t,a\n0,1\n");
  write_text(dir.path() / "summary.json", "{\n  \"energy_final\": null\n}\n");
  EXPECT_NE(non_finite_in_outputs(dir.path()), "");
}

TEST(MutationFuzz, ModelFilesA) {
  ::setenv("ISOFLEX_CAD_TIME_LIMIT", kCadTimeLimitSeconds, 1);
  fuzz_models("models_a", 0x15F0220001ull, 400);
}

TEST(MutationFuzz, ModelFilesB) {
  ::setenv("ISOFLEX_CAD_TIME_LIMIT", kCadTimeLimitSeconds, 1);
  fuzz_models("models_b", 0x15F0220002ull, 400);
}

// CAD files: mutants of tests/data/cad read through a model file's surfaces[].cad.file (a
// crash, a hang or an error of the reader must be a located error of the model file).
TEST(MutationFuzz, CadFiles) {
  ::setenv("ISOFLEX_CAD_TIME_LIMIT", kCadTimeLimitSeconds, 1);
  const TempDir dir(fs::temp_directory_path() / ("isoflex_fuzz_cad_" + std::to_string(::getpid())));
  std::vector<std::string> seeds;
  for (const auto& c : kCadSeeds) {
    seeds.push_back(read_text(fs::path(ISOFLEX_SOURCE_DIR) / "tests/data/cad" / c));
    ASSERT_FALSE(seeds.back().empty()) << c;
  }
  Rng rng(0x15F022CADull);
  Tally tally;
  int failures = 0;
  for (int k = 0; k < 100 && failures < 10; ++k) {
    const std::size_t s = rng.below(seeds.size());
    const bool iges = fs::path(kCadSeeds[s]).extension() == ".igs";
    std::string log = kCadSeeds[s] + ": ";
    const std::string cad_text = mutate_cad(seeds[s], iges, rng, log);
    const std::string cad_name = iges ? "cad.igs" : "cad.stp";
    write_text(dir.path() / cad_name, cad_text);
    const std::string model_text = cad_model(cad_name);
    const fs::path model = dir.path() / "m.yaml";
    write_text(model, model_text);
    if (const std::string bad = examine(dir.path(), model, &tally); !bad.empty()) {
      report("cad_" + std::to_string(k), bad, log, model_text, cad_name, cad_text);
      ++failures;
    }
    fs::remove(dir.path() / cad_name);
  }
  std::cout << "cad: " << tally_text(tally) << "\n";
}

}  // namespace isoflex::test
