#include <cmath>
#include <exception>

#include "bindings.hpp"
#include "isoflex/io/cad/cad_error.hpp"
#include "isoflex/io/model_error.hpp"
#include "isoflex/io/output_error.hpp"
#include "isoflex/system/compile_error.hpp"

namespace isoflex::python {

namespace {

// The exception types, made once per process (the module is initialised once).
struct ErrorTypes {
  py::object base, model, compile, newton, output, cad;
};

ErrorTypes& types() {
  static ErrorTypes* t = new ErrorTypes();  // never destroyed: Python owns the objects at exit
  return *t;
}

py::object new_type(py::module_& m, const char* name, py::handle base, const char* doc) {
  py::object type = py::reinterpret_steal<py::object>(PyErr_NewExceptionWithDoc(
      (std::string("isoflex.") + name).c_str(), doc, base.ptr(), nullptr));
  m.attr(name) = type;
  return type;
}

py::object new_type(py::module_& m, const char* name, py::handle base, py::handle builtin,
                    const char* doc) {
  const py::tuple bases = py::make_tuple(base, builtin);
  py::object type = py::reinterpret_steal<py::object>(PyErr_NewExceptionWithDoc(
      (std::string("isoflex.") + name).c_str(), doc, bases.ptr(), nullptr));
  m.attr(name) = type;
  return type;
}

// Sets the Python error `type(message)` with the attributes.
void raise(const py::object& type, const std::string& message, const py::dict& attributes) {
  py::object error = type(message);
  for (const auto& [key, value] : attributes) error.attr(key) = value;
  PyErr_SetObject(type.ptr(), error.ptr());
}

}  // namespace

void throw_newton_failure(const integrate::NewtonFailure& e, int step, double time) {
  py::dict a;
  a["step"] = step;
  a["time"] = time;
  a["residual"] = e.residual();
  a["message"] = std::string(e.what());
  raise(types().newton, e.what(), a);
  throw py::error_already_set();
}

void bind_errors(py::module_& m) {
  ErrorTypes& t = types();
  t.base = new_type(m, "Error", PyExc_Exception, "Every error of isoflex.");
  t.model = new_type(m, "ModelError", t.base, PyExc_ValueError,
                     "A model that cannot be read: file, line (0: none), key (the dotted path "
                     "of the entry, '' for none) and message.");
  t.compile = new_type(m, "CompileError", t.base, PyExc_ValueError,
                       "A model that was read but cannot be set up as a system.");
  t.newton = new_type(m, "NewtonFailure", t.base, PyExc_RuntimeError,
                      "A step Newton could not solve: step, time (what the step was to reach), "
                      "residual (where the last attempt stopped; nan when none). The simulation "
                      "keeps the state of the last step.");
  t.output = new_type(m, "OutputError", t.base, PyExc_OSError,
                      "An output file that cannot be written: file.");
  t.cad = new_type(m, "CadError", t.base, PyExc_ValueError, "A CAD file that cannot be read.");
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const io::ModelError& e) {
      py::dict a;
      a["file"] = e.file();
      a["line"] = e.line();
      a["key"] = e.key();
      a["message"] = e.message();
      raise(types().model, e.what(), a);
    } catch (const system::CompileError& e) {
      raise(types().compile, e.what(), py::dict());
    } catch (const integrate::NewtonFailure& e) {
      py::dict a;
      a["step"] = py::none();
      a["time"] = py::none();
      a["residual"] = e.residual();
      a["message"] = std::string(e.what());
      raise(types().newton, e.what(), a);
    } catch (const io::OutputError& e) {
      raise(types().output, e.what(), py::dict());
    } catch (const io::CadError& e) {
      raise(types().cad, e.what(), py::dict());
    }
  });
}

}  // namespace isoflex::python
