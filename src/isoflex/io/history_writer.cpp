#include "isoflex/io/history_writer.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>

namespace isoflex::io {

namespace {

// A CSV field, quoted when it contains a separator, quote or line break.
std::string csv_field(std::string_view text) {
  if (text.find_first_of(",\"\r\n") == std::string_view::npos) return std::string(text);
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"') out += '"';
    out += c;
  }
  out += '"';
  return out;
}

}  // namespace

CsvFile::CsvFile(const std::filesystem::path& file, const char* header) : path_(file) {
  if (file.has_parent_path()) {
    std::error_code ec;
    std::filesystem::create_directories(file.parent_path(), ec);
    if (ec) {
      throw std::runtime_error(
          fmt::format("cannot create directory {}: {}", file.parent_path().string(), ec.message()));
    }
  }
  f_ = std::fopen(file.c_str(), "w");
  if (f_ == nullptr) {
    throw std::runtime_error(
        fmt::format("cannot write {}: {}", file.string(), std::strerror(errno)));
  }
  fmt::print(f_, "{}\n", header);
  flush();
}

CsvFile::~CsvFile() {
  if (f_ != nullptr) std::fclose(f_);
}

CsvFile::CsvFile(CsvFile&& other) noexcept
    : path_(std::move(other.path_)), f_(std::exchange(other.f_, nullptr)) {}

CsvFile& CsvFile::operator=(CsvFile&& other) noexcept {
  if (this != &other) {
    if (f_ != nullptr) std::fclose(f_);
    path_ = std::move(other.path_);
    f_ = std::exchange(other.f_, nullptr);
  }
  return *this;
}

void CsvFile::flush() {
  if (f_ == nullptr) return;
  if (std::fflush(f_) != 0 || std::ferror(f_) != 0) {
    throw std::runtime_error(
        fmt::format("cannot write {}: {}", path_.string(), std::strerror(errno)));
  }
}

HistoryWriter::HistoryWriter(const std::filesystem::path& outdir)
    : file_(outdir / "history.csv", kHistoryHeader) {}

void HistoryWriter::on_snapshot(const integrate::Snapshot& s) {
  const Vec3& p = s.linear_momentum;
  const Vec3& L = s.angular_momentum;
  fmt::print(file_.get(),
             "{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},"
             "{:.17g},{},{:.17g}\n",
             s.t, s.kinetic_energy, s.potential_energy, s.total_energy, p.x(), p.y(), p.z(), L.x(),
             L.y(), L.z(), s.constraint_violation, s.newton_iterations, s.residual);
  file_.flush();
}

void HistoryWriter::on_finish() {
  file_.flush();
}

ProbeWriter::ProbeWriter(const std::filesystem::path& outdir, const model::Model& model) {
  if (!model.probes.empty()) file_ = CsvFile(outdir / "probes.csv", kProbesHeader);
}

void ProbeWriter::on_snapshot(const integrate::Snapshot& s) {
  if (!file_) return;
  for (const auto& pr : s.probes) {
    const Vec3& x = pr.position;
    const Vec3& u = pr.displacement;
    const Vec3& v = pr.velocity;
    fmt::print(file_.get(),
               "{:.17g},{},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},"
               "{:.17g}\n",
               s.t, csv_field(pr.name), x.x(), x.y(), x.z(), u.x(), u.y(), u.z(), v.x(), v.y(),
               v.z());
  }
  file_.flush();
}

void ProbeWriter::on_finish() {
  file_.flush();
}

ResultantsWriter::ResultantsWriter(const std::filesystem::path& outdir, const model::Model& model) {
  if (!model.beams.empty()) file_ = CsvFile(outdir / "resultants.csv", kResultantsHeader);
}

void ResultantsWriter::on_snapshot(const integrate::Snapshot& s) {
  if (!file_) return;
  for (const auto& e : s.beam_elements)
    fmt::print(file_.get(), "{:.17g},{},{},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g}\n", s.t,
               csv_field(e.beam), e.element, e.n.x(), e.n.y(), e.n.z(), e.m.x(), e.m.y(), e.m.z());
  file_.flush();
}

void ResultantsWriter::on_finish() {
  file_.flush();
}

}  // namespace isoflex::io
