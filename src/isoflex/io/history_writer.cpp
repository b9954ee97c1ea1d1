#include "isoflex/io/history_writer.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <iterator>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>

#include "isoflex/io/output_error.hpp"

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
    if (ec) throw OutputError(file.parent_path(), ec.message(), "create directory");
  }
  fd_ = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd_ < 0) throw OutputError::from_errno(file, errno);
  pending_ = header;
  pending_ += '\n';
  flush();
}

CsvFile::~CsvFile() {
  if (fd_ >= 0) ::close(fd_);
}

CsvFile::CsvFile(CsvFile&& other) noexcept
    : path_(std::move(other.path_)),
      fd_(std::exchange(other.fd_, -1)),
      pending_(std::move(other.pending_)),
      written_(other.written_) {}

CsvFile& CsvFile::operator=(CsvFile&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    path_ = std::move(other.path_);
    fd_ = std::exchange(other.fd_, -1);
    pending_ = std::move(other.pending_);
    written_ = other.written_;
  }
  return *this;
}

void CsvFile::flush() {
  if (fd_ < 0 || pending_.empty()) return;
  // Plain write(2) rather than stdio: after a failed write stdio keeps part of the rows in its
  // buffer and writes it out later, so the file could not be cut back to complete rows.
  std::size_t done = 0;
  while (done < pending_.size()) {
    const ssize_t n = ::write(fd_, pending_.data() + done, pending_.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int error = n < 0 ? errno : EIO;
      pending_.clear();
      // Part of a row on disk: cut it off (devices such as /dev/full cannot be, nor need to be).
      if (done > 0 && ::ftruncate(fd_, static_cast<off_t>(written_)) == 0)
        ::lseek(fd_, static_cast<off_t>(written_), SEEK_SET);
      throw OutputError::from_errno(path_, error);
    }
    done += static_cast<std::size_t>(n);
  }
  written_ += static_cast<long long>(done);
  pending_.clear();
}

namespace {

// The path-parameter column of a static run with path following (Snapshot::path), "" for none.
std::string path_column(const model::Model& m) {
  if (m.solver.analysis != model::Analysis::statics) return {};
  switch (m.solver.path.method) {
    case model::PathMethod::arc_length:
      return "arc_length";
    case model::PathMethod::displacement:
      return "control_displacement";
    case model::PathMethod::load:
      break;
  }
  return {};
}

std::string joined(const std::vector<std::string>& names) {
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : ",") + n;
  return s;
}

}  // namespace

HistoryColumns::HistoryColumns(const model::Model& m)
    : HistoryColumns(model::has_material_damping(m), path_column(m), model::has_external_loads(m),
                     model::has_drivers(m)) {}

HistoryColumns::HistoryColumns(bool dissipated_energy, const std::string& path_column,
                               bool external_work, bool driver_work)
    : dissipated_(dissipated_energy),
      external_work_(external_work),
      driver_work_(driver_work),
      path_(!path_column.empty()) {
  for (std::string_view h = kHistoryHeader; !h.empty();) {
    const auto comma = h.find(',');
    names_.emplace_back(h.substr(0, comma));
    h = comma == std::string_view::npos ? std::string_view() : h.substr(comma + 1);
  }
  if (dissipated_) names_.push_back("dissipated_energy");
  if (external_work_) names_.push_back("external_work");
  if (driver_work_) names_.push_back("driver_work");
  if (path_) names_.push_back(path_column);
}

void HistoryColumns::append_values(const integrate::Snapshot& s, std::vector<double>& out) const {
  const Vec3& p = s.linear_momentum;
  const Vec3& L = s.angular_momentum;
  out.insert(out.end(),
             {s.t, s.kinetic_energy, s.potential_energy, s.total_energy, p.x(), p.y(), p.z(), L.x(),
              L.y(), L.z(), s.constraint_violation, double(s.newton_iterations), s.residual});
  if (dissipated_) out.push_back(s.dissipated_energy);
  if (external_work_) out.push_back(s.external_work);
  if (driver_work_) out.push_back(s.driver_work);
  if (path_) out.push_back(s.path);
}

HistoryWriter::HistoryWriter(const std::filesystem::path& outdir, const model::Model& m)
    : HistoryWriter(outdir, HistoryColumns(m)) {}

HistoryWriter::HistoryWriter(const std::filesystem::path& outdir, HistoryColumns columns)
    : columns_(std::move(columns)),
      file_(outdir / "history.csv", joined(columns_.names()).c_str()) {}

// {:.17g} writes the iteration count as the integer it is.
void HistoryWriter::on_snapshot(const integrate::Snapshot& s) {
  values_.clear();
  columns_.append_values(s, values_);
  std::string& row = file_.pending();
  for (std::size_t k = 0; k < values_.size(); ++k)
    fmt::format_to(std::back_inserter(row), "{}{:.17g}", k ? "," : "", values_[k]);
  row += '\n';
  file_.flush();
}

void HistoryWriter::on_finish() {
  file_.flush();
}

void CsvRowsWriter::on_snapshot(const integrate::Snapshot& s) {
  if (!file_) return;
  rows(s, file_.pending());
  file_.flush();
}

void CsvRowsWriter::on_finish() {
  file_.flush();
}

namespace {

std::filesystem::path file_if(bool any, const std::filesystem::path& file) {
  return any ? file : std::filesystem::path();
}

}  // namespace

ProbeWriter::ProbeWriter(const std::filesystem::path& outdir, const model::Model& model)
    : CsvRowsWriter(file_if(!model.probes.empty(), outdir / "probes.csv"), kProbesHeader) {}

void ProbeWriter::rows(const integrate::Snapshot& s, std::string& out) const {
  for (const auto& pr : s.probes) {
    const Vec3& x = pr.position;
    const Vec3& u = pr.displacement;
    const Vec3& v = pr.velocity;
    fmt::format_to(std::back_inserter(out),
                   "{:.17g},{},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},"
                   "{:.17g}\n",
                   s.t, csv_field(pr.name), x.x(), x.y(), x.z(), u.x(), u.y(), u.z(), v.x(), v.y(),
                   v.z());
  }
}

ResultantsWriter::ResultantsWriter(const std::filesystem::path& outdir, const model::Model& model)
    : CsvRowsWriter(file_if(!model.beams.empty(), outdir / "resultants.csv"), kResultantsHeader) {}

void ResultantsWriter::rows(const integrate::Snapshot& s, std::string& out) const {
  for (const auto& e : s.beam_elements)
    fmt::format_to(
        std::back_inserter(out), "{:.17g},{},{},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g}\n",
        s.t, csv_field(e.beam), e.element, e.n.x(), e.n.y(), e.n.z(), e.m.x(), e.m.y(), e.m.z());
}

ForcesWriter::ForcesWriter(const std::filesystem::path& outdir, const model::Model& model)
    : CsvRowsWriter(file_if(!model.springs.empty() || !model.bushings.empty() ||
                                std::any_of(model.joints.begin(), model.joints.end(),
                                            [](const model::Joint& j) { return j.spring; }),
                            outdir / "forces.csv"),
                    kForcesHeader) {}

void ForcesWriter::rows(const integrate::Snapshot& s, std::string& out) const {
  for (const auto& f : s.springs)
    fmt::format_to(std::back_inserter(out), "{:.17g},{},{:.17g},{:.17g},{:.17g},{:.17g}\n", s.t,
                   csv_field(f.name), f.length, f.elongation, f.rate, f.force);
}

namespace {

bool any_driver(const model::Model& model) {
  return std::any_of(model.joints.begin(), model.joints.end(),
                     [](const model::Joint& j) { return !j.driver.empty(); });
}

}  // namespace

ReactionsWriter::ReactionsWriter(const std::filesystem::path& outdir, const model::Model& model)
    : CsvRowsWriter(file_if(!model.joints.empty() || !model.kl_surface_joints.empty(),
                            outdir / "reactions.csv"),
                    (std::string(kReactionsHeader) + (any_driver(model) ? ",driver" : "")).c_str()),
      driver_(any_driver(model)) {}

void ReactionsWriter::rows(const integrate::Snapshot& s, std::string& out) const {
  const auto v = [](const Vec3& a) {
    return fmt::format("{:.17g},{:.17g},{:.17g}", a.x(), a.y(), a.z());
  };
  for (const auto& r : s.reactions) {
    fmt::format_to(std::back_inserter(out), "{:.17g},{},{},{},{},{},{}", s.t, csv_field(r.joint),
                   v(r.point), v(r.force), v(r.moment), v(r.force_local), v(r.moment_local));
    if (driver_) {
      out += ',';
      if (r.driver) fmt::format_to(std::back_inserter(out), "{:.17g}", *r.driver);
    }
    out += '\n';
  }
}

}  // namespace isoflex::io
