#pragma once
// The parts of the extension module isoflex._isoflex (docs/python.md); the Python package
// python/isoflex/__init__.py builds the user-facing API on them.
#include <pybind11/pybind11.h>

#include <string>

#include "isoflex/integrate/newton_loop.hpp"

namespace isoflex::python {

namespace py = pybind11;

// Exception types (isoflex.Error and its subclasses) and the translation of the C++ errors.
void bind_errors(py::module_& m);
void bind_model(py::module_& m);
void bind_simulation(py::module_& m);

// Raises isoflex.NewtonFailure with the step, the time it was to reach and the residual.
[[noreturn]] void throw_newton_failure(const integrate::NewtonFailure& e, int step, double time);

}  // namespace isoflex::python
