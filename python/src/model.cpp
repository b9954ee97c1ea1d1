// Reading models, `check` and `cad-info` for Python (isoflex.Model, isoflex.check,
// isoflex.cad_info in python/isoflex/__init__.py).
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>

#include "bindings.hpp"
#include "isoflex/app/commands.hpp"
#include "isoflex/integrate/static_equilibrium.hpp"
#include "isoflex/io/cad/cad_checks.hpp"
#include "isoflex/io/cad/cad_reader.hpp"
#include "isoflex/io/model_reader.hpp"
#include "isoflex/system/memory_estimate.hpp"
#include "isoflex/system/system.hpp"

namespace isoflex::python {

namespace {

// What a function printing to a FILE* printed (open_memstream).
class CapturedText {
 public:
  CapturedText() : file_(open_memstream(&data_, &size_)) {
    if (!file_) throw std::runtime_error("cannot capture text (open_memstream)");
  }
  ~CapturedText() {
    if (file_) std::fclose(file_);
    std::free(data_);
  }
  CapturedText(const CapturedText&) = delete;
  CapturedText& operator=(const CapturedText&) = delete;
  std::FILE* file() { return file_; }
  std::string text() {
    std::fflush(file_);
    return std::string(data_, size_);
  }

 private:
  char* data_ = nullptr;
  std::size_t size_ = 0;
  std::FILE* file_;
};

model::Model read(const std::optional<std::string>& path, const std::optional<std::string>& text,
                  const std::string& name,
                  const std::vector<std::pair<std::string, std::string>>& overrides) {
  io::ReadOptions options;
  for (const auto& [key, value] : overrides) options.overrides.push_back({key, value});
  if (path) return io::read_model(*path, options);
  if (text) return io::read_model_string(*text, name, options);
  throw std::invalid_argument("read_model: give a path or a YAML text");
}

// The figures of `isoflex check` (app/commands.cpp) as numbers.
py::dict check_figures(const model::Model& m) {
  const system::System sys = system::System::compile(m);
  py::dict d;
  d["n"] = sys.n();
  d["m"] = sys.m_selected();
  d["internal_rows"] = sys.internal_rows();
  d["redundant"] = sys.redundant_rows().size();
  d["tree_coordinates"] = sys.k();
  d["loop_rows_kept"] = sys.cut_rank();
  d["nodes"] = sys.node_count();
  d["bodies"] = m.bodies.size();
  d["memory_bytes"] = static_cast<long long>(std::llround(system::estimate_memory(m).total()));
  if (m.solver.analysis == model::Analysis::statics) {
    const integrate::StaticEquilibrium eq(sys, m.solver);
    d["analysis"] = "static";
    d["dof"] = eq.dof();
    d["unknowns"] = eq.unknowns();
  } else {
    d["analysis"] = "dynamic";
    const system::LinearConstraints& lin = sys.linear_constraints();
    d["dof"] =
        sys.n() - sys.m_selected() - static_cast<int>(lin.eliminated.size()) - lin.multipliers();
    if (m.solver.integrator == model::Integrator::energy_momentum) {
      py::dict u;
      u["constrained"] = sys.n() + sys.m_selected();
      u["nullspace"] = sys.n();
      u["reparametrized"] = sys.k();
      d["unknowns"] = u;
    } else {
      d["unknowns"] = sys.n() + sys.m_selected();
    }
    d["initial_velocity_projection"] = sys.initial_velocity_projection_error();
  }
  py::list warnings;
  for (const std::string& w : model::gravity_warnings(m)) warnings.append(w);
  d["warnings"] = warnings;
  return d;
}

py::dict check(const model::Model& m) {
  CapturedText out, err;
  const int code = app::check_model(m, out.file(), err.file());
  const std::string error = err.text();
  if (code != 0) {
    // check_model printed "error: MESSAGE"; the cause as the exception's text
    std::string message = error.rfind("error: ", 0) == 0 ? error.substr(7) : error;
    while (!message.empty() && message.back() == '\n') message.pop_back();
    PyErr_SetString(py::module_::import("isoflex._isoflex").attr("CompileError").ptr(),
                    message.c_str());
    throw py::error_already_set();
  }
  py::dict d = check_figures(m);
  d["report"] = out.text();
  return d;
}

py::list knots_list(const std::vector<double>& k) {
  return py::cast(k);
}

py::dict cad_info(const std::string& file) {
  const io::CadModel model = io::read_cad(file);
  py::dict d;
  d["file"] = file;
  d["format"] = io::to_string(model.format);
  d["length_unit"] = model.length_unit;
  py::list patches;
  int errors = 0, warnings = 0, notes = 0;
  for (const io::CadPatch& p : model.patches) {
    const geometry::NurbsSurface& s = p.surface;
    py::dict q;
    q["index"] = p.index;
    q["name"] = p.name;
    q["entity"] = p.entity;
    q["surface_type"] = p.surface_type;
    q["converted"] = p.converted;
    q["trimmed"] = p.trimmed;
    q["reversed_orientation"] = p.reversed_orientation;
    q["degrees"] = py::make_tuple(s.u.degree(), s.v.degree());
    q["control_points"] = py::make_tuple(s.n_u(), s.n_v());
    q["knots_u"] = knots_list(s.u.knots());
    q["knots_v"] = knots_list(s.v.knots());
    q["rational"] = s.is_rational();
    py::list findings;
    for (const io::Finding& f : io::check_patch(p)) {
      ++(f.severity == io::Severity::error     ? errors
         : f.severity == io::Severity::warning ? warnings
                                               : notes);
      py::dict g;
      g["severity"] = io::to_string(f.severity);
      g["issue"] = f.issue;
      g["fix"] = f.fix;
      findings.append(g);
    }
    q["findings"] = findings;
    patches.append(q);
  }
  d["patches"] = patches;
  d["errors"] = errors;
  d["warnings"] = warnings;
  d["notes"] = notes;
  return d;
}

std::vector<std::string> names_of(const auto& entries) {
  std::vector<std::string> names;
  for (const auto& e : entries) names.push_back(e.name);
  return names;
}

}  // namespace

void bind_model(py::module_& m) {
  py::class_<model::Model, std::shared_ptr<model::Model>>(
      m, "ModelData", "A model as read and checked (the C++ model::Model); see isoflex.Model.")
      .def_property_readonly("file", [](const model::Model& x) { return x.file; })
      .def_property_readonly("analysis",
                             [](const model::Model& x) {
                               return x.solver.analysis == model::Analysis::statics ? "static"
                                                                                    : "dynamic";
                             })
      .def_property_readonly("dt", [](const model::Model& x) { return x.solver.dt; })
      .def_property_readonly("t_end", [](const model::Model& x) { return x.solver.t_end; })
      .def_property_readonly(
          "formulation",
          [](const model::Model& x) { return model::to_string(x.solver.formulation); })
      .def_property_readonly("bodies", [](const model::Model& x) { return names_of(x.bodies); })
      .def_property_readonly("beams", [](const model::Model& x) { return names_of(x.beams); })
      .def_property_readonly("kl_shells",
                             [](const model::Model& x) { return names_of(x.kl_shells); })
      .def_property_readonly("probes", [](const model::Model& x) { return names_of(x.probes); });
  m.def(
      "read_model",
      [](const std::optional<std::string>& path, const std::optional<std::string>& text,
         const std::string& name,
         const std::vector<std::pair<std::string, std::string>>& overrides) {
        return std::make_shared<model::Model>(read(path, text, name, overrides));
      },
      py::arg("path") = py::none(), py::arg("text") = py::none(), py::arg("name") = "<text>",
      py::arg("overrides") = std::vector<std::pair<std::string, std::string>>{});
  m.def("check", &check, py::arg("model"));
  m.def("cad_info", &cad_info, py::arg("file"));
}

}  // namespace isoflex::python
