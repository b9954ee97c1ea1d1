#include "isoflex/io/hdf5_results.hpp"

#include <fmt/format.h>
#include <hdf5.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <optional>
#include <string_view>
#include <utility>

#include "isoflex/io/history_writer.hpp"
#include "isoflex/io/output_error.hpp"

#ifndef ISOFLEX_VERSION
#define ISOFLEX_VERSION ""
#endif

namespace isoflex::io {

namespace {

// The version of the layout (hdf5_results.hpp), the root attribute `isoflex_results` that marks
// a results file.
constexpr int kLayoutVersion = 1;

// Rows of a series chunk: about 8 KB per chunk, so that the flush after every snapshot rewrites
// little while a long run does not need a chunk per row.
hsize_t chunk_rows(hsize_t row_size) {
  return std::clamp<hsize_t>(1024 / std::max<hsize_t>(row_size, 1), 1, 1024);
}

// The cause of the HDF5 call that failed last, from the error stack (then cleared): the system's
// text where the innermost entry has one (the sec2 driver writes "errno = 28, error message =
// 'No space left on device'"), else the innermost description.
std::string hdf5_cause() {
  struct Found {
    std::string system, innermost;
  } found;
  H5Ewalk2(
      H5E_DEFAULT, H5E_WALK_DOWNWARD,
      [](unsigned, const H5E_error2_t* e, void* data) -> herr_t {
        auto& f = *static_cast<Found*>(data);
        const std::string_view desc = e->desc ? e->desc : "";
        constexpr std::string_view key = "error message = '";
        if (const auto at = desc.find(key); at != std::string_view::npos) {
          const auto begin = at + key.size();
          f.system = std::string(desc.substr(begin, desc.find('\'', begin) - begin));
        }
        if (!desc.empty()) f.innermost = std::string(desc);
        return 0;
      },
      &found);
  H5Eclear2(H5E_DEFAULT);
  if (!found.system.empty()) return found.system;
  return found.innermost.empty() ? "HDF5 error" : found.innermost;
}

// isoflex reports HDF5's errors itself (OutputError, RestartError): the library's printing of its
// error stack to stderr is switched off for the process. And HDF5 does not close its files at
// exit: after a failed write (a full disk) H5Fclose fails, and HDF5 1.10.8's closing of that file
// again at exit crashed in H5F__close_cb (exit code 139 instead of 4).
void silence_hdf5() {
  static const bool done = [] {
    H5dont_atexit();  // effective before the library's first use only
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    return true;
  }();
  (void)done;
}

// An HDF5 identifier, closed with its closing function.
class Handle {
 public:
  using Close = herr_t (*)(hid_t);
  Handle() = default;
  Handle(hid_t id, Close close) : id_(id), close_(close) {}
  ~Handle() { reset(); }
  Handle(Handle&& o) noexcept : id_(std::exchange(o.id_, -1)), close_(o.close_) {}
  Handle& operator=(Handle&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = std::exchange(o.id_, -1);
      close_ = o.close_;
    }
    return *this;
  }
  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }
  // Closes; the status of the closing function (< 0: failed).
  herr_t reset() {
    herr_t status = 0;
    if (id_ >= 0 && close_) status = close_(id_);
    id_ = -1;
    return status;
  }

 private:
  hid_t id_ = -1;
  Close close_ = nullptr;
};

// The file access of both writing and reading: no file locking (a results file can be read while
// a run writes it, and restarted from), and every object closed with the file.
Handle file_access() {
  Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  if (!fapl.valid()) return fapl;
#if H5_VERSION_GE(1, 10, 7)
  H5Pset_file_locking(fapl.get(), 0, 1);
#endif
  H5Pset_fclose_degree(fapl.get(), H5F_CLOSE_STRONG);
  // The 1.8 file format: groups hold their links and attributes in their header (a step group
  // of the 1.0 format takes 0.8 KB more for a symbol table and heap). Not the 1.10 format: a
  // file its writer did not close (a killed run) would need `h5clear -s` before it opens.
  H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_V18, H5F_LIBVER_V18);
  // Nothing of the file is read again while a run writes it: the metadata cache need not grow to
  // HDF5's default 32 MB (1000 steps of the slider-crank: 69 → 53 MB peak RSS, the same time).
  H5AC_cache_config_t cache;
  cache.version = H5AC__CURR_CACHE_CONFIG_VERSION;
  if (H5Pget_mdc_config(fapl.get(), &cache) >= 0) {
    cache.set_initial_size = 1;
    cache.initial_size = std::size_t(1) << 20;
    cache.min_size = std::size_t(1) << 20;
    cache.max_size = std::size_t(8) << 20;
    H5Pset_mdc_config(fapl.get(), &cache);
  }
  return fapl;
}

// A name for an HDF5 link: `/` separates groups, "." and "" are no names. Others are kept.
std::string link_name(const std::string& name) {
  std::string s = name;
  std::replace(s.begin(), s.end(), '/', '_');
  if (s.empty() || s == "." || s == "..") s = "_" + s;
  return s;
}

// The names of `names` as links in one group: link_name, with "-k" (k the index) appended to one
// that an earlier name already took.
std::vector<std::string> link_names(const std::vector<std::string>& names) {
  std::vector<std::string> out;
  for (std::size_t k = 0; k < names.size(); ++k) {
    std::string s = link_name(names[k]);
    while (std::find(out.begin(), out.end(), s) != out.end()) s += fmt::format("-{}", k);
    out.push_back(s);
  }
  return out;
}

std::string step_group(int step) {
  return fmt::format("{:09d}", step);
}

// Writing: every failure is an OutputError naming the file.
class Writer {
 public:
  explicit Writer(std::filesystem::path file) : file_(std::move(file)) {}
  const std::filesystem::path& file() const { return file_; }

  [[noreturn]] void fail() const { throw OutputError(file_, hdf5_cause()); }
  hid_t check(hid_t id) const {
    if (id < 0) fail();
    return id;
  }
  void check_status(herr_t status) const {
    if (status < 0) fail();
  }

  Handle group(hid_t parent, const std::string& name) const {
    // The attributes of a step (16) stay in the group's header: beyond 8 (the default) HDF5
    // moves them to a fractal heap with a B-tree, +1.3 KB per step.
    const Handle gcpl(check(H5Pcreate(H5P_GROUP_CREATE)), H5Pclose);
    check_status(H5Pset_attr_phase_change(gcpl.get(), 24, 20));
    check_status(H5Pset_est_link_info(gcpl.get(), 8, 14));
    return Handle(check(H5Gcreate2(parent, name.c_str(), H5P_DEFAULT, gcpl.get(), H5P_DEFAULT)),
                  H5Gclose);
  }

  void attribute(hid_t object, const char* name, hid_t file_type, hid_t memory_type,
                 const void* value) const {
    const Handle space(check(H5Screate(H5S_SCALAR)), H5Sclose);
    const Handle a(
        check(H5Acreate2(object, name, file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT)),
        H5Aclose);
    check_status(H5Awrite(a.get(), memory_type, value));
  }
  void attribute(hid_t object, const char* name, double v) const {
    attribute(object, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &v);
  }
  void attribute(hid_t object, const char* name, int v) const {
    attribute(object, name, H5T_STD_I32LE, H5T_NATIVE_INT, &v);
  }
  // A variable-length UTF-8 string (h5py reads it as str).
  void attribute(hid_t object, const char* name, const std::string& v) const {
    const Handle type(check(H5Tcopy(H5T_C_S1)), H5Tclose);
    check_status(H5Tset_size(type.get(), H5T_VARIABLE));
    check_status(H5Tset_cset(type.get(), H5T_CSET_UTF8));
    const char* text = v.c_str();
    attribute(object, name, type.get(), type.get(), &text);
  }

  // A 1-D dataset of the doubles of x (length 0 for an empty x). Up to 16 KB in the dataset's
  // header (compact layout: no block of its own to allocate; 10 % of the run time of the
  // slider-crank's states, n = 468), larger ones contiguous (a header holds at most 64 KB).
  void vector(hid_t group, const char* name, const VecX& x) const {
    const hsize_t size = static_cast<hsize_t>(x.size());
    const Handle space(check(H5Screate_simple(1, &size, nullptr)), H5Sclose);
    const Handle dcpl(check(H5Pcreate(H5P_DATASET_CREATE)), H5Pclose);
    if (size <= 2048) check_status(H5Pset_layout(dcpl.get(), H5D_COMPACT));
    const Handle d(check(H5Dcreate2(group, name, H5T_IEEE_F64LE, space.get(), H5P_DEFAULT,
                                    dcpl.get(), H5P_DEFAULT)),
                   H5Dclose);
    if (size > 0)
      check_status(H5Dwrite(d.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, x.data()));
  }

 private:
  std::filesystem::path file_;
};

// A dataset growing by one row per snapshot: N × `row` doubles, chunked, unlimited along N.
class Series {
 public:
  Series(const Writer& w, hid_t parent, const std::string& name, std::vector<hsize_t> row)
      : w_(&w) {
    dims_.push_back(0);
    dims_.insert(dims_.end(), row.begin(), row.end());
    hsize_t row_size = 1;
    for (const hsize_t r : row) row_size *= r;
    std::vector<hsize_t> max = dims_, chunk = dims_;
    max[0] = H5S_UNLIMITED;
    chunk[0] = chunk_rows(row_size);
    const int rank = static_cast<int>(dims_.size());
    const Handle space(w.check(H5Screate_simple(rank, dims_.data(), max.data())), H5Sclose);
    const Handle dcpl(w.check(H5Pcreate(H5P_DATASET_CREATE)), H5Pclose);
    w.check_status(H5Pset_chunk(dcpl.get(), rank, chunk.data()));
    data_ = Handle(w.check(H5Dcreate2(parent, name.c_str(), H5T_IEEE_F64LE, space.get(),
                                      H5P_DEFAULT, dcpl.get(), H5P_DEFAULT)),
                   H5Dclose);
  }

  // Appends one row (the doubles of `row` in C order).
  void append(const double* row) {
    std::vector<hsize_t> start(dims_.size(), 0), count = dims_;
    start[0] = dims_[0];
    count[0] = 1;
    ++dims_[0];
    w_->check_status(H5Dset_extent(data_.get(), dims_.data()));
    const Handle file_space(w_->check(H5Dget_space(data_.get())), H5Sclose);
    w_->check_status(H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start.data(), nullptr,
                                         count.data(), nullptr));
    const Handle memory_space(
        w_->check(H5Screate_simple(static_cast<int>(count.size()), count.data(), nullptr)),
        H5Sclose);
    w_->check_status(H5Dwrite(data_.get(), H5T_NATIVE_DOUBLE, memory_space.get(), file_space.get(),
                              H5P_DEFAULT, row));
  }

 private:
  const Writer* w_;
  std::vector<hsize_t> dims_;
  Handle data_;
};

std::string analysis_of(const model::Model& m) {
  if (m.solver.analysis == model::Analysis::statics) return "static";
  return m.solver.cosimulation ? "cosimulation" : "dynamic";
}

}  // namespace

struct Hdf5ResultsWriter::Impl {
  Writer w;
  Handle file;
  Handle history_group, steps_group;
  HistoryColumns columns;
  std::vector<Series> history;
  std::vector<double> values;
  struct Probe {
    Series position, displacement, velocity;
  };
  std::vector<Probe> probes;
  struct Beam {
    std::string name;
    int elements = 0;
    std::optional<Series> n, m;
  };
  std::vector<Beam> beams;
  bool series_made = false;
  int state_every = 1;
  bool first = true;
  bool failed = false;
  // The last snapshot's state when it was not written (state_every > 1): on_finish writes it.
  std::optional<integrate::State> unsaved;
  int unsaved_iterations = 0;
  double unsaved_residual = 0.0, unsaved_path = 0.0;

  Impl(std::filesystem::path path, const model::Model& m)
      : w(std::move(path)), columns(m), state_every(std::max(1, m.output.hdf5_state_every)) {}

  // The probe and resultant series, from the first snapshot's probes and beam elements.
  void make_series(const integrate::Snapshot& s) {
    series_made = true;
    if (!s.probes.empty()) {
      const Handle g = w.group(file.get(), "probes");
      std::vector<std::string> names;
      for (const auto& p : s.probes) names.push_back(p.name);
      const auto links = link_names(names);
      for (std::size_t k = 0; k < links.size(); ++k) {
        const Handle pg = w.group(g.get(), links[k]);
        w.attribute(pg.get(), "name", names[k]);
        probes.push_back({Series(w, pg.get(), "position", {3}),
                          Series(w, pg.get(), "displacement", {3}),
                          Series(w, pg.get(), "velocity", {3})});
      }
    }
    for (const auto& e : s.beam_elements) {
      if (beams.empty() || beams.back().name != e.beam) beams.push_back({e.beam, 0, {}, {}});
      ++beams.back().elements;
    }
    if (!beams.empty()) {
      const Handle g = w.group(file.get(), "resultants");
      std::vector<std::string> names;
      for (const auto& b : beams) names.push_back(b.name);
      const auto links = link_names(names);
      for (std::size_t k = 0; k < beams.size(); ++k) {
        const Handle bg = w.group(g.get(), links[k]);
        w.attribute(bg.get(), "name", names[k]);
        const hsize_t E = static_cast<hsize_t>(beams[k].elements);
        beams[k].n.emplace(w, bg.get(), "n", std::vector<hsize_t>{E, 3});
        beams[k].m.emplace(w, bg.get(), "m", std::vector<hsize_t>{E, 3});
      }
    }
  }

  void append_series(const integrate::Snapshot& s) {
    values.clear();
    columns.append_values(s, values);
    for (std::size_t k = 0; k < history.size(); ++k) history[k].append(&values[k]);
    if (s.probes.size() != probes.size())
      throw OutputError(w.file(), "the number of probes changed during the run");
    for (std::size_t k = 0; k < probes.size(); ++k) {
      probes[k].position.append(s.probes[k].position.data());
      probes[k].displacement.append(s.probes[k].displacement.data());
      probes[k].velocity.append(s.probes[k].velocity.data());
    }
    std::size_t at = 0;
    for (Beam& b : beams) {
      std::vector<double> n, m;
      for (int e = 0; e < b.elements; ++e, ++at) {
        if (at >= s.beam_elements.size() || s.beam_elements[at].beam != b.name)
          throw OutputError(w.file(), "the beam elements changed during the run");
        const auto& v = s.beam_elements[at];
        n.insert(n.end(), v.n.data(), v.n.data() + 3);
        m.insert(m.end(), v.m.data(), v.m.data() + 3);
      }
      b.n->append(n.data());
      b.m->append(m.data());
    }
  }

  void write_state(const integrate::State& st, int iterations, double residual, double path) {
    const Handle g = w.group(steps_group.get(), step_group(st.step));
    const std::array<std::pair<const char*, const VecX*>, 8> vectors{
        {{"q", &st.q},
         {"v", &st.v},
         {"last_unknowns", &st.last_unknowns},
         {"a", &st.a},
         {"aux", &st.aux},
         {"lambda", &st.lambda},
         {"q_prev", &st.q_prev},
         {"v_prev", &st.v_prev}}};
    for (const auto& [name, x] : vectors) w.vector(g.get(), name, *x);
    w.attribute(g.get(), "step", st.step);
    w.attribute(g.get(), "t", st.t);
    w.attribute(g.get(), "grid_start", st.grid_start);
    w.attribute(g.get(), "grid_dt", st.grid_dt);
    w.attribute(g.get(), "grid_steps", st.grid_steps);
    w.attribute(g.get(), "last_dt", st.last_dt);
    w.attribute(g.get(), "last_start", st.last_start);
    w.attribute(g.get(), "dissipated", st.dissipated);
    w.attribute(g.get(), "external_work", st.external_work);
    w.attribute(g.get(), "driver_work", st.driver_work);
    w.attribute(g.get(), "newton_iterations", iterations);
    w.attribute(g.get(), "residual", residual);
    w.attribute(g.get(), "path", path);
  }

  void flush() { w.check_status(H5Fflush(file.get(), H5F_SCOPE_LOCAL)); }

  // Every object but the file.
  void close() {
    history.clear();
    probes.clear();
    beams.clear();
    steps_group.reset();
    history_group.reset();
  }
};

Hdf5ResultsWriter::Hdf5ResultsWriter(const std::filesystem::path& outdir, const model::Model& m,
                                     const ResultsFileRun& run)
    : impl_(std::make_unique<Impl>(outdir / kFileName, m)) {
  silence_hdf5();
  Impl& I = *impl_;
  const Writer& w = I.w;
  const Handle fapl = file_access();
  if (!fapl.valid()) w.fail();
  I.file = Handle(w.check(H5Fcreate(w.file().c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get())),
                  H5Fclose);
  const hid_t root = I.file.get();
  w.attribute(root, "isoflex_results", kLayoutVersion);
  w.attribute(root, "isoflex_version", std::string(ISOFLEX_VERSION));
  w.attribute(root, "model_file", m.file);
  w.attribute(root, "model_name", m.name);
  w.attribute(root, "analysis", analysis_of(m));
  w.attribute(root, "formulation", run.formulation);
  w.attribute(root, "dt", m.solver.dt);
  w.attribute(root, "t_end", m.solver.t_end);
  w.attribute(root, "n", run.n);
  w.attribute(root, "m", run.m);
  w.attribute(root, "energy_initial", run.energy_initial);
  w.attribute(root, "state_every", I.state_every);
  if (!run.restart_file.empty()) {
    w.attribute(root, "restart_file", run.restart_file);
    w.attribute(root, "restart_from_step", run.restart_from_step);
  }
  I.history_group = w.group(root, "history");
  for (const std::string& c : I.columns.names())
    I.history.emplace_back(w, I.history_group.get(), c, std::vector<hsize_t>{});
  I.steps_group = w.group(root, "steps");
  I.flush();
}

Hdf5ResultsWriter::~Hdf5ResultsWriter() = default;

void Hdf5ResultsWriter::on_snapshot(const integrate::Snapshot& s) {
  Impl& I = *impl_;
  if (I.failed || !I.file.valid()) return;
  try {
    if (!I.series_made) I.make_series(s);
    I.append_series(s);
    if (state_) {
      if (I.first || state_->step % I.state_every == 0) {
        I.write_state(*state_, s.newton_iterations, s.residual, s.path);
        I.unsaved.reset();
      } else {
        I.unsaved = *state_;
        I.unsaved_iterations = s.newton_iterations;
        I.unsaved_residual = s.residual;
        I.unsaved_path = s.path;
      }
    }
    I.first = false;
    state_ = nullptr;
    I.flush();
  } catch (const OutputError&) {
    I.failed = true;
    throw;
  }
}

void Hdf5ResultsWriter::on_finish() {
  Impl& I = *impl_;
  if (!I.file.valid()) return;
  std::optional<OutputError> error;
  if (!I.failed && I.unsaved) {
    try {
      I.write_state(*I.unsaved, I.unsaved_iterations, I.unsaved_residual, I.unsaved_path);
    } catch (const OutputError& e) {
      error = e;
      I.failed = true;
    }
  }
  I.close();
  if (I.file.reset() < 0 && !I.failed && !error) error = OutputError(I.w.file(), hdf5_cause());
  if (error) throw *error;
}

// Reading -------------------------------------------------------------------------------------

namespace {

class Reader {
 public:
  explicit Reader(std::filesystem::path file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw RestartError(fmt::format("{}: {}", file_.string(), what));
  }

  void open() {
    silence_hdf5();
    std::error_code ec;
    if (!std::filesystem::exists(file_, ec)) fail("no such file");
    if (std::filesystem::is_directory(file_, ec)) fail("is a directory, not a results file");
    if (H5Fis_hdf5(file_.c_str()) <= 0)
      fail("not an HDF5 file (--restart takes the results.h5 of a run with output.hdf5: true)");
    const Handle fapl = file_access();
    file = Handle(H5Fopen(file_.c_str(), H5F_ACC_RDONLY, fapl.get()), H5Fclose);
    if (!file.valid()) fail("cannot be opened: " + hdf5_cause());
    if (H5Aexists(file.get(), "isoflex_results") <= 0)
      fail("not an isoflex results file (no attribute isoflex_results at its root)");
    const int version = integer(file.get(), "isoflex_results", "/");
    if (version != kLayoutVersion)
      fail(fmt::format("results file layout {}, this isoflex reads layout {}", version,
                       kLayoutVersion));
    if (H5Lexists(file.get(), "steps", H5P_DEFAULT) <= 0)
      fail("not an isoflex results file (no group /steps)");
  }

  std::vector<int> steps() const {
    std::vector<std::string> names;
    const herr_t status = H5Literate_by_name(
        file.get(), "steps", H5_INDEX_NAME, H5_ITER_INC, nullptr,
        [](hid_t, const char* name, const H5L_info_t*, void* data) -> herr_t {
          static_cast<std::vector<std::string>*>(data)->emplace_back(name);
          return 0;
        },
        &names, H5P_DEFAULT);
    if (status < 0) fail("cannot list /steps: " + hdf5_cause());
    std::vector<int> out;
    for (const std::string& n : names) {
      int k = 0;
      const auto [end, ec] = std::from_chars(n.data(), n.data() + n.size(), k);
      if (ec == std::errc() && end == n.data() + n.size()) out.push_back(k);
    }
    std::sort(out.begin(), out.end());
    return out;
  }

  int integer(hid_t object, const char* name, const std::string& where) const {
    int v = 0;
    read_attribute(object, name, H5T_NATIVE_INT, &v, where);
    return v;
  }
  double real(hid_t object, const char* name, const std::string& where) const {
    double v = 0;
    read_attribute(object, name, H5T_NATIVE_DOUBLE, &v, where);
    return v;
  }
  std::string text(hid_t object, const char* name, const std::string& where) const {
    const Handle a(H5Aopen(object, name, H5P_DEFAULT), H5Aclose);
    if (!a.valid()) fail(fmt::format("{}: no attribute {}", where, name));
    const Handle type(H5Aget_type(a.get()), H5Tclose);
    if (H5Tget_class(type.get()) != H5T_STRING || H5Tis_variable_str(type.get()) <= 0)
      fail(fmt::format("{}: attribute {} is not a string", where, name));
    char* value = nullptr;
    if (H5Aread(a.get(), type.get(), &value) < 0)
      fail(fmt::format("{}: cannot read attribute {}: {}", where, name, hdf5_cause()));
    std::string s = value ? value : "";
    H5free_memory(value);
    return s;
  }

  VecX vector(hid_t group, const char* name, const std::string& where) const {
    const std::string path = where + "/" + name;
    const Handle d(H5Dopen2(group, name, H5P_DEFAULT), H5Dclose);
    if (!d.valid()) fail(fmt::format("{}: missing", path));
    const Handle space(H5Dget_space(d.get()), H5Sclose);
    if (H5Sget_simple_extent_ndims(space.get()) != 1) fail(fmt::format("{}: not 1-D", path));
    hsize_t size = 0;
    H5Sget_simple_extent_dims(space.get(), &size, nullptr);
    VecX x(static_cast<Eigen::Index>(size));
    if (size > 0 &&
        H5Dread(d.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, x.data()) < 0)
      fail(fmt::format("{}: cannot be read: {}", path, hdf5_cause()));
    return x;
  }

  Handle file;

 private:
  void read_attribute(hid_t object, const char* name, hid_t type, void* value,
                      const std::string& where) const {
    const Handle a(H5Aopen(object, name, H5P_DEFAULT), H5Aclose);
    if (!a.valid()) fail(fmt::format("{}: no attribute {}", where, name));
    if (H5Aread(a.get(), type, value) < 0)
      fail(fmt::format("{}: cannot read attribute {}: {}", where, name, hdf5_cause()));
  }

  std::filesystem::path file_;
};

}  // namespace

std::vector<int> saved_steps(const std::filesystem::path& file) {
  Reader r(file);
  r.open();
  return r.steps();
}

std::string describe_steps(const std::vector<int>& steps) {
  if (steps.empty()) return "none";
  if (steps.size() <= 8) {
    std::string s;
    for (const int k : steps) s += (s.empty() ? "" : ", ") + std::to_string(k);
    return s;
  }
  // A regular grid from the first step (state_every), maybe with a last step off it.
  const int d = steps[1] - steps[0];
  std::size_t regular = 1;
  while (regular < steps.size() && steps[regular] - steps[regular - 1] == d) ++regular;
  if (regular + 1 >= steps.size()) {
    std::string s = fmt::format("{} to {}{}", steps[0], steps[regular - 1],
                                d == 1 ? std::string() : fmt::format(" every {}", d));
    if (regular < steps.size()) s += fmt::format(", and {}", steps.back());
    return s;
  }
  return fmt::format("{}, {}, {}, …, {} ({} steps)", steps[0], steps[1], steps[2], steps.back(),
                     steps.size());
}

SavedState read_saved_state(const std::filesystem::path& file, int step) {
  Reader r(file);
  r.open();
  const std::vector<int> steps = r.steps();
  if (!std::binary_search(steps.begin(), steps.end(), step))
    r.fail(fmt::format("no state of step {} saved; the file has the states of steps {}", step,
                       describe_steps(steps)));
  SavedState out;
  const hid_t root = r.file.get();
  out.analysis = r.text(root, "analysis", "/");
  out.formulation = r.text(root, "formulation", "/");
  out.model_file = r.text(root, "model_file", "/");
  out.n = r.integer(root, "n", "/");
  out.m = r.integer(root, "m", "/");
  out.energy_initial = r.real(root, "energy_initial", "/");
  out.dt = r.real(root, "dt", "/");

  const std::string where = "/steps/" + step_group(step);
  const Handle g(H5Gopen2(root, where.c_str(), H5P_DEFAULT), H5Gclose);
  if (!g.valid()) r.fail(fmt::format("{}: cannot be opened: {}", where, hdf5_cause()));
  integrate::State& s = out.state;
  s.q = r.vector(g.get(), "q", where);
  s.v = r.vector(g.get(), "v", where);
  s.last_unknowns = r.vector(g.get(), "last_unknowns", where);
  s.a = r.vector(g.get(), "a", where);
  s.aux = r.vector(g.get(), "aux", where);
  s.lambda = r.vector(g.get(), "lambda", where);
  s.q_prev = r.vector(g.get(), "q_prev", where);
  s.v_prev = r.vector(g.get(), "v_prev", where);
  s.step = r.integer(g.get(), "step", where);
  s.t = r.real(g.get(), "t", where);
  s.grid_start = r.real(g.get(), "grid_start", where);
  s.grid_dt = r.real(g.get(), "grid_dt", where);
  s.grid_steps = r.integer(g.get(), "grid_steps", where);
  s.last_dt = r.real(g.get(), "last_dt", where);
  s.last_start = r.integer(g.get(), "last_start", where);
  s.dissipated = r.real(g.get(), "dissipated", where);
  s.external_work = r.real(g.get(), "external_work", where);
  s.driver_work = r.real(g.get(), "driver_work", where);
  out.newton_iterations = r.integer(g.get(), "newton_iterations", where);
  out.residual = r.real(g.get(), "residual", where);
  out.path = r.real(g.get(), "path", where);
  if (s.step != step) r.fail(fmt::format("{}: attribute step is {}, not {}", where, s.step, step));
  return out;
}

}  // namespace isoflex::io
