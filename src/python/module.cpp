// nscd_sim._engine: the engine from Python. python/nscd_sim/__init__.py re-exports it.
#include <pybind11/pybind11.h>

#include "bindings.hpp"

PYBIND11_MODULE(_engine, m) {
  m.doc() = "nscd_sim engine: load a scene, step it, read its outputs (docs/python.md)";
  nscd_python::bindExceptions(m);
  nscd_python::bindState(m);
  nscd_python::bindSimulator(m);
}
