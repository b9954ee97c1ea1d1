#pragma once
// Time histories as CSV, one row per snapshot, numbers with 17 significant digits, flushed after
// every row so that a running or interrupted simulation can be inspected.
//   history.csv: t,kinetic_energy,potential_energy,total_energy,px,py,pz,Lx,Ly,Lz,
//                constraint_violation,newton_iterations,residual
//   probes.csv:  t,probe,x,y,z,ux,uy,uz,vx,vy,vz (one row per probe and snapshot)
//   resultants.csv: t,beam,element,n1,n2,n3,m1,m2,m3 (one row per beam element and snapshot;
//                stress resultants in director components, DNSM-III (69))
#include <cstdio>
#include <filesystem>

#include "isoflex/integrate/snapshot.hpp"
#include "isoflex/model/model.hpp"

namespace isoflex::io {

inline constexpr const char* kHistoryHeader =
    "t,kinetic_energy,potential_energy,total_energy,px,py,pz,Lx,Ly,Lz,constraint_violation,"
    "newton_iterations,residual";
inline constexpr const char* kProbesHeader = "t,probe,x,y,z,ux,uy,uz,vx,vy,vz";
inline constexpr const char* kResultantsHeader = "t,beam,element,n1,n2,n3,m1,m2,m3";

// Owns an output file opened for writing (closed on destruction).
class CsvFile {
 public:
  CsvFile() = default;
  // Creates missing directories, truncates the file and writes `header`. Throws
  // std::runtime_error when it cannot be opened.
  CsvFile(const std::filesystem::path& file, const char* header);
  ~CsvFile();
  CsvFile(const CsvFile&) = delete;
  CsvFile& operator=(const CsvFile&) = delete;
  CsvFile(CsvFile&& other) noexcept;
  CsvFile& operator=(CsvFile&& other) noexcept;

  std::FILE* get() const { return f_; }
  explicit operator bool() const { return f_ != nullptr; }
  void flush();  // throws std::runtime_error on a write error (e.g. disk full)

 private:
  std::filesystem::path path_;
  std::FILE* f_ = nullptr;
};

// Writes outdir/history.csv.
class HistoryWriter : public integrate::Observer {
 public:
  explicit HistoryWriter(const std::filesystem::path& outdir);
  void on_snapshot(const integrate::Snapshot& s) override;
  void on_finish() override;

 private:
  CsvFile file_;
};

// Writes outdir/probes.csv; creates no file (and ignores all snapshots) when the model has no
// probes.
class ProbeWriter : public integrate::Observer {
 public:
  ProbeWriter(const std::filesystem::path& outdir, const model::Model& model);
  void on_snapshot(const integrate::Snapshot& s) override;
  void on_finish() override;

 private:
  CsvFile file_;
};

// Writes outdir/resultants.csv; creates no file when the model has no beams.
class ResultantsWriter : public integrate::Observer {
 public:
  ResultantsWriter(const std::filesystem::path& outdir, const model::Model& model);
  void on_snapshot(const integrate::Snapshot& s) override;
  void on_finish() override;

 private:
  CsvFile file_;
};

}  // namespace isoflex::io
