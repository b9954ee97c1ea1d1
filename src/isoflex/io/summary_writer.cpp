#include "isoflex/io/summary_writer.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <system_error>

#include "isoflex/io/output_error.hpp"

namespace isoflex::io {

namespace {

std::string json_number(double v) {
  if (!std::isfinite(v)) return "null";
  return fmt::format("{:.17g}", v);
}

std::string json_vec3(const Vec3& v) {
  return fmt::format("[{}, {}, {}]", json_number(v.x()), json_number(v.y()), json_number(v.z()));
}

}  // namespace

std::string json_string(std::string_view text) {
  std::string out;
  out.reserve(text.size() + 2);
  out += '"';
  for (const char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\b':
        out += "\\b";
        break;
      case '\f':
        out += "\\f";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (c < 0x20 || c == 0x7f) {
          fmt::format_to(std::back_inserter(out), "\\u{:04x}", static_cast<unsigned>(c));
        } else {
          out += ch;  // UTF-8 passes through unchanged
        }
    }
  }
  out += '"';
  return out;
}

std::string summary_json(const RunSummary& s) {
  std::string out = "{\n";
  auto it = std::back_inserter(out);
  auto key = [&](std::string_view name) { fmt::format_to(it, "  {}: ", json_string(name)); };
  auto str = [&](std::string_view name, std::string_view v) {
    key(name);
    fmt::format_to(it, "{},\n", json_string(v));
  };
  auto integer = [&](std::string_view name, int v) {
    key(name);
    fmt::format_to(it, "{},\n", v);
  };
  auto real = [&](std::string_view name, double v) {
    key(name);
    fmt::format_to(it, "{},\n", json_number(v));
  };

  str("model", s.model);
  if (!s.set.empty()) {
    key("set");
    std::string list;
    for (const std::string& v : s.set) list += (list.empty() ? "" : ", ") + json_string(v);
    fmt::format_to(it, "[{}],\n", list);
  }
  str("formulation", s.formulation);
  integer("n_coordinates", s.n_coordinates);
  integer("n_constraints", s.n_constraints);
  integer("n_unknowns", s.n_unknowns);
  integer("n_redundant_constraints", s.n_redundant_constraints);
  integer("steps", s.steps);
  integer("newton_iterations_total", s.newton_iterations_total);
  if (s.newton_failed_starts) integer("newton_failed_starts", *s.newton_failed_starts);
  if (s.subdivided_steps) integer("subdivided_steps", *s.subdivided_steps);
  real("dt", s.dt);
  real("t_end", s.t_end);
  real("wall_time_s", s.wall_time_s);
  integer("threads", s.threads);
  if (s.threads_note) str("threads_note", *s.threads_note);
  if (s.mpi_ranks) integer("mpi_ranks", *s.mpi_ranks);
  real("max_constraint_violation", s.max_constraint_violation);
  real("energy_initial", s.energy_initial);
  real("energy_final", s.energy_final);
  real("max_energy_drift_after_loads", s.max_energy_drift_after_loads);
  if (s.dissipated_energy) real("dissipated_energy", *s.dissipated_energy);
  if (s.external_work) real("external_work", *s.external_work);
  if (s.driver_work) real("driver_work", *s.driver_work);
  if (s.initial_velocity_projection)
    real("initial_velocity_projection", *s.initial_velocity_projection);
  if (s.initial_equilibrium_load_steps)
    integer("initial_equilibrium_load_steps", *s.initial_equilibrium_load_steps);
  if (s.krylov_iterations_total) integer("krylov_iterations_total", *s.krylov_iterations_total);
  if (s.saddle_point_fallbacks) integer("saddle_point_fallbacks", *s.saddle_point_fallbacks);
  if (s.linear_solver) {
    key("linear_solver");
    fmt::format_to(it, "{},\n", json_string(*s.linear_solver));
  }
  if (s.linear_solver_fallbacks) integer("linear_solver_fallbacks", *s.linear_solver_fallbacks);
  if (s.restart_file) {
    key("restart");
    fmt::format_to(it, "{{\"file\": {}, \"from_step\": {}}},\n", json_string(*s.restart_file),
                   s.restart_from_step);
  }

  key("probes");
  if (s.probes.empty()) {
    out += "{},\n";
  } else {
    out += "{\n";
    for (std::size_t i = 0; i < s.probes.size(); ++i) {
      const auto& p = s.probes[i];
      fmt::format_to(it, "    {}: {{\"position\": {}, \"displacement\": {}, \"velocity\": {}}}{}\n",
                     json_string(p.name), json_vec3(p.position), json_vec3(p.displacement),
                     json_vec3(p.velocity), i + 1 < s.probes.size() ? "," : "");
    }
    out += "  },\n";
  }

  str("status", s.status);
  key("message");
  fmt::format_to(it, "{}\n}}\n", json_string(s.message));
  return out;
}

void write_summary_json(const std::filesystem::path& file, const RunSummary& s) {
  write_file_atomic(file, summary_json(s));
}

void write_file_atomic(const std::filesystem::path& file, std::string_view content) {
  namespace fs = std::filesystem;
  if (file.has_parent_path()) {
    std::error_code ec;
    fs::create_directories(file.parent_path(), ec);
    if (ec) throw OutputError(file.parent_path(), ec.message(), "create directory");
  }
  // Errors name `file`, the one the user knows; the temporary file is removed.
  fs::path tmp = file;
  tmp += ".tmp";
  std::FILE* f = std::fopen(tmp.c_str(), "wb");
  if (f == nullptr) throw OutputError::from_errno(file, errno);
  int error = 0;
  if (std::fwrite(content.data(), 1, content.size(), f) != content.size()) error = errno;
  if (std::fclose(f) != 0 && error == 0) error = errno;
  std::error_code ec;
  if (error == 0) fs::rename(tmp, file, ec);
  if (error != 0 || ec) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    if (error != 0) throw OutputError::from_errno(file, error);
    throw OutputError(file, ec.message());
  }
}

}  // namespace isoflex::io
