// nscd_sim.State: a copy of nscd::State (everything that moves). Copyable,
// picklable bit for bit, compared bit for bit (==).
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "bindings.hpp"
#include "nscd_sim/simulator.hpp"

namespace py = pybind11;

namespace nscd_python {

namespace {

// 2: with the adaptive step control's memory (step_next, step_error); 1 is read too.
constexpr int kPickleVersion = 2;
constexpr int kBodyColumns = 13;  // x y z, qw qx qy qz, vx vy vz, wx wy wz (body frame)

py::array_t<double> vectorArray(const std::vector<double>& v) {
  py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
  if (!v.empty()) std::memcpy(a.mutable_data(), v.data(), v.size() * sizeof(double));
  return a;
}

py::array_t<double> bodyArray(const nscd::State& s) {
  py::array_t<double> a({static_cast<py::ssize_t>(s.bodies.size()), py::ssize_t(kBodyColumns)});
  auto r = a.mutable_unchecked<2>();
  for (size_t i = 0; i < s.bodies.size(); ++i) {
    const nscd::BodyState& b = s.bodies[i];
    const double row[kBodyColumns] = {b.x.x(), b.x.y(), b.x.z(), b.q.w(), b.q.x(), b.q.y(), b.q.z(),
                                      b.v.x(), b.v.y(), b.v.z(), b.w.x(), b.w.y(), b.w.z()};
    for (int c = 0; c < kBodyColumns; ++c) r(i, c) = row[c];
  }
  return a;
}

// A C-contiguous float64 copy of `o` with `cols` columns (0: one-dimensional).
py::array_t<double, py::array::c_style | py::array::forcecast> doubles(const py::handle& o,
                                                                      const char* what, int cols) {
  auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(o);
  if (!a) throw std::invalid_argument(std::string("State: ") + what + " is not an array of numbers");
  if (cols == 0 ? a.ndim() != 1 : (a.ndim() != 2 || a.shape(1) != cols))
    throw std::invalid_argument(std::string("State: ") + what + " has the wrong shape");
  return a;
}

std::vector<double> toVector(const py::handle& o, const char* what) {
  auto a = doubles(o, what, 0);
  return std::vector<double>(a.data(), a.data() + a.shape(0));
}

py::tuple pickleState(const nscd::State& s) {
  py::array_t<double> warm({static_cast<py::ssize_t>(s.warm.size()), py::ssize_t(3)});
  auto w = warm.mutable_unchecked<2>();
  for (size_t i = 0; i < s.warm.size(); ++i)
    for (int c = 0; c < 3; ++c) w(i, c) = s.warm[i][c];
  py::array_t<uint8_t> valid(static_cast<py::ssize_t>(s.warm_valid.size()));
  for (size_t i = 0; i < s.warm_valid.size(); ++i) valid.mutable_data()[i] = s.warm_valid[i] ? 1 : 0;
  return py::make_tuple(kPickleVersion, s.t, bodyArray(s), vectorArray(s.commands),
                        vectorArray(s.prev_commands), warm, valid, vectorArray(s.warm_bilateral),
                        vectorArray(s.ring_hint), vectorArray(s.joint_position), s.step_next, s.step_error);
}

nscd::State unpickleState(const py::tuple& t) {
  const int version = t.size() > 0 ? py::cast<int>(t[0]) : 0;
  if (!((version == 1 && t.size() == 10) || (version == 2 && t.size() == 12)))
    throw std::invalid_argument("State: not a pickled nscd_sim.State of version 1 or 2");
  nscd::State s;
  s.t = py::cast<double>(t[1]);
  auto bodies = doubles(t[2], "bodies", kBodyColumns);
  auto b = bodies.unchecked<2>();
  s.bodies.resize(bodies.shape(0));
  for (size_t i = 0; i < s.bodies.size(); ++i) {
    nscd::BodyState& x = s.bodies[i];
    x.x = nscd::Vec3(b(i, 0), b(i, 1), b(i, 2));
    x.q = nscd::Quat(b(i, 3), b(i, 4), b(i, 5), b(i, 6));
    x.v = nscd::Vec3(b(i, 7), b(i, 8), b(i, 9));
    x.w = nscd::Vec3(b(i, 10), b(i, 11), b(i, 12));
  }
  s.commands = toVector(t[3], "commands");
  s.prev_commands = toVector(t[4], "prev_commands");
  auto warm = doubles(t[5], "warm", 3);
  auto w = warm.unchecked<2>();
  s.warm.resize(warm.shape(0));
  for (size_t i = 0; i < s.warm.size(); ++i) s.warm[i] = nscd::Vec3(w(i, 0), w(i, 1), w(i, 2));
  const std::vector<double> valid = toVector(t[6], "warm_valid");
  s.warm_valid.assign(valid.size(), 0);
  for (size_t i = 0; i < valid.size(); ++i) s.warm_valid[i] = valid[i] != 0;
  s.warm_bilateral = toVector(t[7], "warm_bilateral");
  s.ring_hint = toVector(t[8], "ring_hint");
  s.joint_position = toVector(t[9], "joint_position");
  if (version == 2) {
    s.step_next = py::cast<double>(t[10]);
    s.step_error = py::cast<double>(t[11]);
  }
  return s;
}

bool sameBits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
}

// Bit for bit (a NaN equals the same NaN): what "bit-identical" means in the tests.
bool sameState(const nscd::State& a, const nscd::State& b) {
  if (std::memcmp(&a.t, &b.t, sizeof(double)) != 0 || a.bodies.size() != b.bodies.size() ||
      a.warm.size() != b.warm.size() || a.warm_valid != b.warm_valid)
    return false;
  for (size_t i = 0; i < a.bodies.size(); ++i) {
    const nscd::BodyState &x = a.bodies[i], &y = b.bodies[i];
    if (std::memcmp(x.x.data(), y.x.data(), 3 * sizeof(double)) ||
        std::memcmp(x.q.coeffs().data(), y.q.coeffs().data(), 4 * sizeof(double)) ||
        std::memcmp(x.v.data(), y.v.data(), 3 * sizeof(double)) ||
        std::memcmp(x.w.data(), y.w.data(), 3 * sizeof(double)))
      return false;
  }
  for (size_t i = 0; i < a.warm.size(); ++i)
    if (std::memcmp(a.warm[i].data(), b.warm[i].data(), 3 * sizeof(double))) return false;
  return sameBits(a.commands, b.commands) && sameBits(a.prev_commands, b.prev_commands) &&
         sameBits(a.warm_bilateral, b.warm_bilateral) && sameBits(a.ring_hint, b.ring_hint) &&
         sameBits(a.joint_position, b.joint_position) &&
         std::memcmp(&a.step_next, &b.step_next, sizeof(double)) == 0 &&
         std::memcmp(&a.step_error, &b.step_error, sizeof(double)) == 0;
}

}  // namespace

void bindState(py::module_& m) {
  py::class_<nscd::State>(m, "State",
                          "Everything that moves (Simulator.state()); with the scene it determines "
                          "the rest of a run. Copyable, picklable; == compares bit for bit.")
      .def(py::init<>())
      .def_readonly("t", &nscd::State::t, "sim time, s")
      .def_property_readonly(
          "bodies", &bodyArray,
          "(n_bodies, 13) float64: x y z (centre of mass, world), qw qx qy qz (body to world), "
          "vx vy vz (world), wx wy wz (angular velocity, BODY frame)")
      .def_property_readonly("commands", [](const nscd::State& s) { return vectorArray(s.commands); },
                             "actuator commands")
      .def_property_readonly("joint_position", [](const nscd::State& s) { return vectorArray(s.joint_position); },
                             "per joint (every joint, fixed ones too), the coordinate followed across turns")
      .def_readonly("step_next", &nscd::State::step_next,
                    "adaptive step control: the length the next step tries, s (0: none yet)")
      .def_readonly("step_error", &nscd::State::step_error,
                    "adaptive step control: the error estimate of the last step kept (0: none)")
      .def("copy", [](const nscd::State& s) { return nscd::State(s); })
      .def("__copy__", [](const nscd::State& s) { return nscd::State(s); })
      .def("__deepcopy__", [](const nscd::State& s, py::dict) { return nscd::State(s); })
      .def("__eq__", [](const nscd::State& a, const nscd::State& b) { return sameState(a, b); })
      .def("__ne__", [](const nscd::State& a, const nscd::State& b) { return !sameState(a, b); })
      .def("__repr__",
           [](const nscd::State& s) {
             return "<nscd_sim.State t=" + py::repr(py::float_(s.t)).cast<std::string>() + " bodies=" +
                    std::to_string(s.bodies.size()) + ">";
           })
      .def(py::pickle([](const nscd::State& s) { return pickleState(s); },
                      [](const py::tuple& t) { return unpickleState(t); }));
  // __eq__ without __hash__: unhashable, as a mutable value should be.
  m.attr("State").attr("__hash__") = py::none();
}

}  // namespace nscd_python
