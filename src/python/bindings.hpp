// The Python module nscd_sim._engine (docs/python.md): what each binding file
// defines, and the two exception types they share.
#pragma once

#include <pybind11/pybind11.h>

namespace nscd_python {

// nscd_sim.SceneError (a ValueError): the loader refused the scene, a setting or
// the config; str(e) is the line nscd_run prints, "FILE:LINE: what".
// nscd_sim.SimulationError (a RuntimeError): a step produced a non-finite state.
struct Exceptions {
  pybind11::object scene_error;
  pybind11::object simulation_error;
};
const Exceptions& exceptions();

void bindExceptions(pybind11::module_& m);  // exceptions.cpp
void bindState(pybind11::module_& m);       // state.cpp: nscd_sim.State
void bindSimulator(pybind11::module_& m);   // simulator.cpp: nscd_sim.Simulator

}  // namespace nscd_python
