// isoflex._isoflex.Simulation: app::Simulation for Python, with the history of its steps as the
// columns of history.csv (docs/python.md).
#include "isoflex/app/simulation.hpp"

#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>
#include <memory>
#include <optional>
#include <stdexcept>

#include "bindings.hpp"
#include "isoflex/geometry/nurbs_surface.hpp"
#include "isoflex/io/history_writer.hpp"

namespace isoflex::python {

namespace {

// A read-only numpy view of `x`, kept alive by `owner`. Valid while x keeps its storage:
// app::Simulation assigns each new state into the old one (same sizes, same buffers).
py::array_t<double> view(const VecX& x, py::handle owner) {
  py::array_t<double> a({x.size()}, {sizeof(double)}, x.data(), owner);
  py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}

py::array_t<double> vec3(const Vec3& x) {
  py::array_t<double> a(3);
  std::copy(x.data(), x.data() + 3, a.mutable_data());
  return a;
}

// An (rows × cols) array of the values, row by row.
py::array_t<double> table(const std::vector<double>& values, std::size_t cols) {
  const std::size_t rows = cols ? values.size() / cols : 0;
  py::array_t<double> a({rows, cols});
  std::copy(values.begin(), values.end(), a.mutable_data());
  return a;
}

class PySimulation {
 public:
  PySimulation(const model::Model& m, int threads)
      : sim_(m, threads), columns_(sim_.model()), probes_(sim_.model().probes.size()) {
    record();
  }

  app::Simulation& sim() { return sim_; }
  const integrate::Snapshot& current() const { return sim_.snapshot(); }

  // One step with the GIL released; a Newton failure raises isoflex.NewtonFailure.
  py::dict step() {
    integrate::StepStats st;
    const int step = sim_.state().step + 1;
    const double time = sim_.state().t + sim_.model().solver.dt;
    try {
      py::gil_scoped_release nogil;
      st = sim_.step();
      record();
    } catch (const integrate::NewtonFailure& e) {
      throw_newton_failure(e, step, time);
    }
    py::dict d;
    d["iterations"] = st.iterations;
    d["residual"] = st.residual;
    d["substeps"] = st.substeps;
    d["failed_starts"] = st.failed_starts;
    return d;
  }

  // Steps to t_end (the model's by default); after each step Python's signal handlers run
  // (Ctrl-C raises KeyboardInterrupt between two steps) and then the callback.
  py::dict run(std::optional<double> t_end, const std::function<void()>& callback) {
    const double dt = sim_.model().solver.dt;
    const double end = t_end.value_or(sim_.model().solver.t_end);
    const long steps = std::lround((end - sim_.state().t) / dt);
    for (long i = 0; i < steps; ++i) {
      step();
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
      if (callback) callback();
    }
    return results();
  }

  // The load stepping of a static model; the callback after every load step. The solver runs
  // without the GIL, which each load step takes back for the signal handlers and the callback.
  py::dict solve(const std::function<void()>& callback) {
    std::optional<py::error_already_set> python_error;
    struct Stop {};
    try {
      py::gil_scoped_release nogil;
      sim_.solve_static([&] {
        record();
        py::gil_scoped_acquire gil;
        try {
          if (PyErr_CheckSignals() != 0) throw py::error_already_set();
          if (callback) callback();
        } catch (py::error_already_set& e) {
          python_error.emplace(std::move(e));
          throw Stop{};
        }
      });
    } catch (const Stop&) {
      throw std::move(*python_error);
    } catch (const integrate::NewtonFailure& e) {
      throw_newton_failure(e, sim_.state().step + 1, std::nan(""));
    }
    return results();
  }

  // The history of every state so far (the initial one first): history.csv's columns, and per
  // probe its position, displacement and velocity as (N, 3) arrays.
  py::dict results() const {
    py::dict d;
    const std::size_t cols = columns_.names().size();
    const std::size_t rows = history_.size() / cols;
    for (std::size_t c = 0; c < cols; ++c) {
      py::array_t<double> a(rows);
      double* out = a.mutable_data();
      for (std::size_t r = 0; r < rows; ++r) out[r] = history_[r * cols + c];
      d[py::str(columns_.names()[c])] = a;
    }
    py::dict probes;
    for (std::size_t p = 0; p < probes_.size(); ++p) {
      std::vector<double> pos, disp, vel;
      for (std::size_t r = 0; r < probes_[p].size(); r += 9) {
        pos.insert(pos.end(), probes_[p].begin() + r, probes_[p].begin() + r + 3);
        disp.insert(disp.end(), probes_[p].begin() + r + 3, probes_[p].begin() + r + 6);
        vel.insert(vel.end(), probes_[p].begin() + r + 6, probes_[p].begin() + r + 9);
      }
      py::dict q;
      q["position"] = table(pos, 3);
      q["displacement"] = table(disp, 3);
      q["velocity"] = table(vel, 3);
      probes[py::str(sim_.model().probes[p].name)] = q;
    }
    d["probes"] = probes;
    return d;
  }

  // Displacement of the deformed Kirchhoff–Love patch `shell` from its reference surface at the
  // parameters (u[i], v[i]) of the surface's own domain: an (N, 3) array.
  py::array_t<double> kl_displacement(const std::string& shell, const std::vector<double>& u,
                                      const std::vector<double>& v) const {
    if (u.size() != v.size())
      throw std::invalid_argument("kl_displacement: u and v must have the same length");
    for (const integrate::KLPatchValue& p : current().kl_patches) {
      if (p.shell != shell) continue;
      const geometry::NurbsSurface& ref = p.patch->reference();
      geometry::NurbsSurface cur = ref;
      for (std::size_t i = 0; i < cur.points.size(); ++i)
        cur.points[i] = p.x.segment<3>(3 * static_cast<Eigen::Index>(i));
      std::vector<double> out;
      for (std::size_t i = 0; i < u.size(); ++i) {
        const bool inside = u[i] >= ref.u.front() && u[i] <= ref.u.back() &&
                            v[i] >= ref.v.front() && v[i] <= ref.v.back();
        if (!inside)
          throw std::invalid_argument(
              "kl_displacement: (" + std::to_string(u[i]) + ", " + std::to_string(v[i]) +
              ") is outside the parameter domain of " + shell + " [" +
              std::to_string(ref.u.front()) + ", " + std::to_string(ref.u.back()) + "] x [" +
              std::to_string(ref.v.front()) + ", " + std::to_string(ref.v.back()) + "]");
        const Vec3 d =
            geometry::evaluate(cur, u[i], v[i]).x - geometry::evaluate(ref, u[i], v[i]).x;
        out.insert(out.end(), d.data(), d.data() + 3);
      }
      return table(out, 3);
    }
    throw std::invalid_argument("kl_displacement: no Kirchhoff-Love shell named " + shell);
  }

 private:
  // The current snapshot and its history row.
  void record() {
    const integrate::Snapshot& current = sim_.snapshot();
    columns_.append_values(current, history_);
    for (std::size_t p = 0; p < probes_.size() && p < current.probes.size(); ++p) {
      const integrate::ProbeValue& v = current.probes[p];
      for (const Vec3* x : {&v.position, &v.displacement, &v.velocity})
        probes_[p].insert(probes_[p].end(), x->data(), x->data() + 3);
    }
  }

  app::Simulation sim_;
  io::HistoryColumns columns_;
  std::vector<double> history_;              // rows of columns_
  std::vector<std::vector<double>> probes_;  // per probe: position, displacement, velocity rows
};

py::dict energies(const integrate::Snapshot& s) {
  py::dict d;
  d["kinetic"] = s.kinetic_energy;
  d["potential"] = s.potential_energy;
  d["total"] = s.total_energy;
  d["dissipated"] = s.dissipated_energy;
  d["external_work"] = s.external_work;
  d["driver_work"] = s.driver_work;
  return d;
}

}  // namespace

void bind_simulation(py::module_& m) {
  py::class_<integrate::State>(m, "State",
                               "The state of a simulation: read-only numpy views that follow it "
                               "(copy them to keep a value).")
      .def_property_readonly("q",
                             [](py::object s) { return view(s.cast<integrate::State&>().q, s); })
      .def_property_readonly("v",
                             [](py::object s) { return view(s.cast<integrate::State&>().v, s); })
      .def_property_readonly(
          "lambda_", [](py::object s) { return view(s.cast<integrate::State&>().lambda, s); })
      .def_property_readonly("t", [](const integrate::State& s) { return s.t; })
      .def_property_readonly("step", [](const integrate::State& s) { return s.step; });

  py::class_<PySimulation>(m, "Simulation")
      .def(py::init<const model::Model&, int>(), py::arg("model"), py::arg("threads") = 0)
      .def_property_readonly(
          "state", [](PySimulation& s) -> const integrate::State& { return s.sim().state(); },
          py::return_value_policy::reference_internal)
      .def_property_readonly("n", [](PySimulation& s) { return s.sim().system().n(); })
      .def_property_readonly("unknowns", [](PySimulation& s) { return s.sim().unknowns(); })
      .def_property_readonly("static", [](PySimulation& s) { return s.sim().statics(); })
      .def("step", &PySimulation::step)
      .def("run", &PySimulation::run, py::arg("t_end") = py::none(),
           py::arg("callback") = py::none())
      .def("solve", &PySimulation::solve, py::arg("callback") = py::none())
      .def("results", &PySimulation::results)
      .def_property_readonly("energies", [](PySimulation& s) { return energies(s.current()); })
      .def_property_readonly("momenta",
                             [](PySimulation& s) {
                               py::dict d;
                               d["linear"] = vec3(s.current().linear_momentum);
                               d["angular"] = vec3(s.current().angular_momentum);
                               return d;
                             })
      .def_property_readonly("constraint_violation",
                             [](PySimulation& s) { return s.current().constraint_violation; })
      .def_property_readonly("probes",
                             [](PySimulation& s) {
                               py::dict d;
                               for (const integrate::ProbeValue& p : s.current().probes) {
                                 py::dict q;
                                 q["position"] = vec3(p.position);
                                 q["displacement"] = vec3(p.displacement);
                                 q["velocity"] = vec3(p.velocity);
                                 d[py::str(p.name)] = q;
                               }
                               return d;
                             })
      .def("beam_resultants",
           [](PySimulation& s) {
             // per beam: n and m of its elements, (E, 3) each, in the element's directors
             std::map<std::string, std::pair<std::vector<double>, std::vector<double>>> by;
             for (const integrate::BeamElementValue& e : s.current().beam_elements) {
               auto& [n, mm] = by[e.beam];
               n.insert(n.end(), e.n.data(), e.n.data() + 3);
               mm.insert(mm.end(), e.m.data(), e.m.data() + 3);
             }
             py::dict d;
             for (const auto& [beam, nm] : by) {
               py::dict r;
               r["n"] = table(nm.first, 3);
               r["m"] = table(nm.second, 3);
               d[py::str(beam)] = r;
             }
             return d;
           })
      .def("kl_displacement", &PySimulation::kl_displacement, py::arg("shell"), py::arg("u"),
           py::arg("v"));
}

}  // namespace isoflex::python
