// nscd_sim.SceneError, nscd_sim.StateFileError and nscd_sim.SimulationError.
#include <pybind11/pybind11.h>

#include "bindings.hpp"
#include "nscd_sim/scene_loader.hpp"
#include "nscd_sim/state_file.hpp"

namespace py = pybind11;

namespace nscd_python {

namespace {
Exceptions* g_exceptions = nullptr;
}

const Exceptions& exceptions() { return *g_exceptions; }

void bindExceptions(py::module_& m) {
  // Leaked on purpose: the types live as long as the interpreter.
  g_exceptions = new Exceptions();
  g_exceptions->scene_error = py::reinterpret_borrow<py::object>(
      py::register_exception<nscd::SceneError>(m, "SceneError", PyExc_ValueError).ptr());
  g_exceptions->scene_error.attr("__module__") = "nscd_sim";  // pickles as nscd_sim.SceneError
  g_exceptions->scene_error.attr("__doc__") =
      "The scene, a setting or the config was refused; str(e) is nscd_run's line 'FILE:LINE: what'.";
  py::object state_file_error = py::reinterpret_borrow<py::object>(
      py::register_exception<nscd::StateFileError>(m, "StateFileError", PyExc_ValueError).ptr());
  state_file_error.attr("__module__") = "nscd_sim";
  state_file_error.attr("__doc__") =
      "A state file could not be read or written, or belongs to another scene; str(e) is "
      "nscd_run's line 'FILE:LINE: what'.";
  g_exceptions->simulation_error = py::reinterpret_steal<py::object>(PyErr_NewExceptionWithDoc(
      "nscd_sim.SimulationError",
      "A step produced a non-finite state; the attribute `record` holds the rows recorded "
      "before it (Simulator.run), or None.",
      PyExc_RuntimeError, nullptr));
  m.attr("SimulationError") = g_exceptions->simulation_error;
}

}  // namespace nscd_python
