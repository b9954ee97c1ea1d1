#include "bindings.hpp"

PYBIND11_MODULE(_isoflex, m) {
  m.doc() = "isoflex: flexible multibody dynamics and isogeometric shells (docs/python.md)";
  isoflex::python::bind_errors(m);
  isoflex::python::bind_model(m);
  isoflex::python::bind_simulation(m);
}
