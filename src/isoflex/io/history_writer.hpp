#pragma once
// Time histories as CSV, one row per snapshot, numbers with 17 significant digits, written after
// every snapshot so that a running or interrupted simulation can be inspected.
//   history.csv: t,kinetic_energy,potential_energy,total_energy,px,py,pz,Lx,Ly,Lz,
//                constraint_violation,newton_iterations,residual[,dissipated_energy][,path]
//                (dissipated_energy for a model with material damping,
//                model::has_material_damping; the path column of a static run with path
//                following, named arc_length or control_displacement: Snapshot::path; t is the
//                load factor of a static run)
//   probes.csv:  t,probe,x,y,z,ux,uy,uz,vx,vy,vz (one row per probe and snapshot)
//   resultants.csv: t,beam,element,n1,n2,n3,m1,m2,m3 (one row per beam element and snapshot;
//                stress resultants in director components, DNSM-III (69))
//   forces.csv:  t,spring,length,elongation,rate,force (one row per spring–damper and snapshot:
//                the distance ζ, ζ − L, ζ̇ and N = k (ζ − L) + c ζ̇, tension > 0)
//   reactions.csv: t,joint,x,y,z,Fx,Fy,Fz,Mx,My,Mz,F1,F2,F3,M1,M2,M3 (one row per joint between
//                frame nodes and snapshot with multipliers: the force and moment on body_b about
//                the joint point (x, y, z), global and in body_b's joint frame)
#include <filesystem>
#include <string>

#include "isoflex/integrate/snapshot.hpp"
#include "isoflex/model/model.hpp"

namespace isoflex::io {

inline constexpr const char* kHistoryHeader =
    "t,kinetic_energy,potential_energy,total_energy,px,py,pz,Lx,Ly,Lz,constraint_violation,"
    "newton_iterations,residual";
inline constexpr const char* kProbesHeader = "t,probe,x,y,z,ux,uy,uz,vx,vy,vz";
inline constexpr const char* kResultantsHeader = "t,beam,element,n1,n2,n3,m1,m2,m3";
inline constexpr const char* kForcesHeader = "t,spring,length,elongation,rate,force";
inline constexpr const char* kReactionsHeader = "t,joint,x,y,z,Fx,Fy,Fz,Mx,My,Mz,F1,F2,F3,M1,M2,M3";

// An output file of rows: the writers append rows to pending(), flush() writes them. A failed
// write (a full disk) cuts the file back to the last row written completely, so that the file
// stays a valid CSV file, and throws io::OutputError naming the file and the cause.
class CsvFile {
 public:
  CsvFile() = default;
  // Creates missing directories, truncates the file and writes `header`. Throws io::OutputError
  // when it cannot be opened or written.
  CsvFile(const std::filesystem::path& file, const char* header);
  ~CsvFile();
  CsvFile(const CsvFile&) = delete;
  CsvFile& operator=(const CsvFile&) = delete;
  CsvFile(CsvFile&& other) noexcept;
  CsvFile& operator=(CsvFile&& other) noexcept;

  explicit operator bool() const { return fd_ >= 0; }
  // Rows not yet written, each ending in '\n'.
  std::string& pending() { return pending_; }
  // Writes the pending rows (one write call unless the system splits it); on failure drops them,
  // cuts off any part of them that reached the file and throws io::OutputError.
  void flush();

 private:
  std::filesystem::path path_;
  int fd_ = -1;
  std::string pending_;
  long long written_ = 0;  // bytes of complete rows in the file
};

// The columns of history.csv for a model (the header above, with the optional columns the model
// has) and their values in a snapshot: the file and the history of a run in the Python module
// (python/) are the same numbers.
class HistoryColumns {
 public:
  explicit HistoryColumns(const model::Model& m);
  // The optional columns: dissipated_energy, external_work, driver_work, and the path column
  // path_column ("" for none).
  explicit HistoryColumns(bool dissipated_energy, const std::string& path_column = {},
                          bool external_work = false, bool driver_work = false);
  const std::vector<std::string>& names() const { return names_; }
  // Appends the snapshot's value of every column, in order.
  void append_values(const integrate::Snapshot& s, std::vector<double>& out) const;

 private:
  std::vector<std::string> names_;
  bool dissipated_ = false, external_work_ = false, driver_work_ = false, path_ = false;
};

// Writes outdir/history.csv.
class HistoryWriter : public integrate::Observer {
 public:
  HistoryWriter(const std::filesystem::path& outdir, const model::Model& m);
  HistoryWriter(const std::filesystem::path& outdir, HistoryColumns columns);
  // As HistoryColumns(dissipated_energy, …).
  HistoryWriter(const std::filesystem::path& outdir, bool dissipated_energy,
                const std::string& path_column = {}, bool external_work = false,
                bool driver_work = false)
      : HistoryWriter(outdir,
                      HistoryColumns(dissipated_energy, path_column, external_work, driver_work)) {}
  void on_snapshot(const integrate::Snapshot& s) override;
  void on_finish() override;

 private:
  HistoryColumns columns_;
  CsvFile file_;
  std::vector<double> values_;
};

// A CSV file of rows per snapshot: the writers below say which rows (none and no file when the
// model has nothing of their kind).
class CsvRowsWriter : public integrate::Observer {
 public:
  void on_snapshot(const integrate::Snapshot& s) override;
  void on_finish() override;

 protected:
  // No file (and no rows) for an empty path.
  CsvRowsWriter(const std::filesystem::path& file, const char* header) {
    if (!file.empty()) file_ = CsvFile(file, header);
  }
  // Appends the rows of s to out, each ending in '\n'.
  virtual void rows(const integrate::Snapshot& s, std::string& out) const = 0;

 private:
  CsvFile file_;
};

// outdir/probes.csv when the model has probes.
class ProbeWriter final : public CsvRowsWriter {
 public:
  ProbeWriter(const std::filesystem::path& outdir, const model::Model& model);

 private:
  void rows(const integrate::Snapshot& s, std::string& out) const override;
};

// outdir/resultants.csv when the model has beams.
class ResultantsWriter final : public CsvRowsWriter {
 public:
  ResultantsWriter(const std::filesystem::path& outdir, const model::Model& model);

 private:
  void rows(const integrate::Snapshot& s, std::string& out) const override;
};

// outdir/forces.csv when the model has springs.
class ForcesWriter final : public CsvRowsWriter {
 public:
  ForcesWriter(const std::filesystem::path& outdir, const model::Model& model);

 private:
  void rows(const integrate::Snapshot& s, std::string& out) const override;
};

// outdir/reactions.csv when the model has joints; with joint drivers a last column `driver`
// (the driving torque or force of a driven revolute or prismatic joint, empty for the others).
class ReactionsWriter final : public CsvRowsWriter {
 public:
  ReactionsWriter(const std::filesystem::path& outdir, const model::Model& model);

 private:
  void rows(const integrate::Snapshot& s, std::string& out) const override;
  bool driver_ = false;
};

}  // namespace isoflex::io
