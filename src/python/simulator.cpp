// nscd_sim.Simulator: a scene loaded with setting overrides and command
// schedules, stepped with the GIL released, its outputs as NumPy structured arrays.
// The stepping follows nscd_run exactly (the schedules applied at the end of each
// step, nscd::prepareScheduledStep; the same CSV columns), so the numbers are the
// CLI's bit for bit.
#include <atomic>
#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "nscd_sim/command_schedule.hpp"
#include "nscd_sim/key_figures.hpp"
#include "nscd_sim/scene_loader.hpp"
#include "nscd_sim/scheduled_step.hpp"
#include "nscd_sim/simulator.hpp"
#include "nscd_sim/state_file.hpp"
#include "records.hpp"

namespace py = pybind11;

namespace nscd_python {

namespace {

// ------------------------------------------------------------ argument conversion

// repr(float(v)): the shortest text that reads back to the same double.
// A str or os.PathLike as a path.
std::string fsPath(const py::object& path) {
  return py::str(py::module_::import("os").attr("fspath")(path)).cast<std::string>();
}

std::string floatText(const py::handle& v) {
  return py::repr(py::module_::import("builtins").attr("float")(v)).cast<std::string>();
}

// A setting's value as the text `--set key=value` would carry: floats by repr
// (shortest text that reads back to the same double), bools true/false,
// sequences space-separated (gravity).
std::string settingText(const py::handle& v, const std::string& key) {
  if (py::isinstance<py::bool_>(v)) return v.cast<bool>() ? "true" : "false";
  if (py::isinstance<py::str>(v)) return v.cast<std::string>();
  if (py::isinstance<py::int_>(v)) return py::str(v).cast<std::string>();
  if (py::hasattr(v, "__float__") && !py::hasattr(v, "__len__")) return floatText(v);
  if (py::hasattr(v, "__iter__")) {
    std::string text;
    for (py::handle item : v) text += (text.empty() ? "" : " ") + settingText(item, key);
    return text;
  }
  throw py::type_error("settings['" + key + "']: expected a number, bool, string or sequence, got " +
                       py::str(py::type::of(v).attr("__name__")).cast<std::string>());
}

// settings: None, a mapping key -> value, or an iterable of "key=value" texts.
std::vector<nscd::SettingOverride> settingOverrides(const py::object& settings) {
  std::vector<nscd::SettingOverride> out;
  if (settings.is_none()) return out;
  if (py::isinstance<py::dict>(settings) || py::hasattr(settings, "items")) {
    for (py::handle item : settings.attr("items")()) {
      py::tuple kv = py::reinterpret_borrow<py::tuple>(item);
      if (!py::isinstance<py::str>(kv[0])) throw py::type_error("settings: keys must be strings");
      const std::string key = kv[0].cast<std::string>();
      out.push_back({key, settingText(kv[1], key), "settings"});
    }
    return out;
  }
  if (py::isinstance<py::str>(settings))
    throw py::type_error("settings: expected a dict or a list of 'key=value' texts, got one string");
  for (py::handle item : settings) {
    if (!py::isinstance<py::str>(item))
      throw py::type_error("settings: expected 'key=value' texts in the list");
    const std::string s = item.cast<std::string>();
    const size_t eq = s.find('=');
    if (eq == std::string::npos || eq == 0)
      throw std::invalid_argument("settings: '" + s + "': expected key=value");
    out.push_back({s.substr(0, eq), s.substr(eq + 1), "settings"});
  }
  return out;
}

std::string numberText(const py::handle& v, const std::string& what) {
  if (py::isinstance<py::str>(v) || !py::hasattr(v, "__float__"))
    throw py::type_error(what + ": expected a number");
  return floatText(v);
}

// commands: None, one "NAME=t0:v0,..." text, a list of them, or a mapping
// NAME -> "t0:v0,..." or NAME -> [(t0, v0), ...]. Returns nscd_run --command texts.
std::vector<std::string> commandTexts(const py::object& commands) {
  std::vector<std::string> out;
  if (commands.is_none()) return out;
  if (py::isinstance<py::str>(commands)) return {commands.cast<std::string>()};
  if (py::isinstance<py::dict>(commands) || py::hasattr(commands, "items")) {
    for (py::handle item : commands.attr("items")()) {
      py::tuple kv = py::reinterpret_borrow<py::tuple>(item);
      if (!py::isinstance<py::str>(kv[0])) throw py::type_error("commands: actuator names must be strings");
      const std::string name = kv[0].cast<std::string>();
      if (py::isinstance<py::str>(kv[1])) {
        out.push_back(name + "=" + kv[1].cast<std::string>());
        continue;
      }
      std::string text;
      for (py::handle point : kv[1]) {
        if (py::isinstance<py::str>(point) || !py::hasattr(point, "__len__") || py::len(point) != 2)
          throw py::type_error("commands['" + name + "']: expected (time, value) pairs");
        py::sequence tv = py::reinterpret_borrow<py::sequence>(point);
        text += (text.empty() ? "" : ",") + numberText(tv[0], "commands['" + name + "'] time") + ":" +
                numberText(tv[1], "commands['" + name + "'] value");
      }
      out.push_back(name + "=" + text);
    }
    return out;
  }
  for (py::handle item : commands) {
    if (!py::isinstance<py::str>(item))
      throw py::type_error("commands: expected 'NAME=t0:v0,t1:v1,...' texts in the list");
    out.push_back(item.cast<std::string>());
  }
  return out;
}

// ------------------------------------------------------------ the simulator

// One call at a time: a second thread calling in while a step runs without the
// GIL gets an exception, not a data race.
class BusyGuard {
 public:
  explicit BusyGuard(std::atomic<bool>& busy) : busy_(busy) {
    if (busy_.exchange(true))
      throw std::runtime_error("Simulator: in use by another thread (one call at a time per Simulator)");
  }
  ~BusyGuard() { busy_ = false; }
  BusyGuard(const BusyGuard&) = delete;
  BusyGuard& operator=(const BusyGuard&) = delete;

 private:
  std::atomic<bool>& busy_;
};

struct StepFailure {
  bool failed = false;
  std::string message;
};

class PySimulator {
 public:
  PySimulator(const std::string& scene, const py::object& settings, const py::object& config,
              const py::object& commands)
      : scene_(scene) {
    std::vector<nscd::SettingOverride> overrides;
    if (!config.is_none()) overrides = nscd::readSettingsYaml(py::str(config).cast<std::string>());
    for (nscd::SettingOverride& o : settingOverrides(settings)) overrides.push_back(std::move(o));
    nscd::Model model = nscd::loadScene(scene, overrides);  // SceneError -> nscd_sim.SceneError
    texts_ = commandTexts(commands);
    schedules_ = bindSchedules(texts_, model);
    try {
      sim_ = std::make_unique<nscd::Simulator>(std::move(model));
    } catch (const std::runtime_error& e) {  // assembly failed: bad input, as nscd_run says
      throw nscd::SceneError(e.what());
    }
    buildFields();
    nscd::applySchedules(schedules_, 0.0, *sim_);
  }

  const nscd::Model& model() const { return sim_->model(); }
  double dt() const { return model().settings.dt; }
  bool adaptive() const { return model().settings.step_control == nscd::StepControl::Adaptive; }

  void setCommands(const py::object& commands) {
    BusyGuard g(busy_);
    std::vector<std::string> texts = commandTexts(commands);
    schedules_ = bindSchedules(texts, model());
    texts_ = std::move(texts);
    nscd::applySchedules(schedules_, adaptive() ? sim_->state().t : steps_ * dt(), *sim_);
  }

  void setCommand(const std::string& name, double value) {
    BusyGuard g(busy_);
    const int a = model().findActuator(name);
    if (a < 0) throw std::invalid_argument(noActuator(name, model()));
    if (!std::isfinite(value))
      throw std::invalid_argument("set_command('" + name + "'): the value must be finite");
    for (const nscd::BoundSchedule& b : schedules_)
      if (b.actuator == a)
        throw std::invalid_argument("set_command('" + name +
                                    "'): a schedule drives this actuator (set_commands replaces schedules)");
    sim_->setCommand(a, value);
  }

  long step(long n) {
    BusyGuard g(busy_);
    if (n < 0) throw std::invalid_argument("step: the number of steps must be >= 0");
    StepFailure failure;
    long taken = 0;
    {
      py::gil_scoped_release nogil;
      for (; taken < n && !failure.failed; ++taken) failure = stepOnce(INFINITY);
    }
    if (failure.failed) raiseSimulationError(failure.message, py::none());
    return taken;
  }

  py::array run(double duration, long every, bool include_start) {
    BusyGuard g(busy_);
    if (!std::isfinite(duration) || duration < 0)
      throw std::invalid_argument("run: duration must be a finite number >= 0 (got " +
                                  py::repr(py::float_(duration)).cast<std::string>() + ")");
    if (every < 1) throw std::invalid_argument("run: every must be >= 1");
    if (duration / dt() > 1e12) throw std::invalid_argument("run: duration / dt is too many steps");
    // Fixed steps: round(duration / dt) of them (as nscd_run); adaptive: until the
    // sim time has advanced by duration, the last step ending there.
    const long steps = static_cast<long>(std::llround(duration / dt()));
    const double until = sim_->state().t + duration;
    const size_t n = fields_.size();
    std::vector<double> values;
    if (!adaptive()) values.reserve(((include_start ? 1 : 0) + static_cast<size_t>(steps / every)) * n);
    size_t rows = 0;
    StepFailure failure;
    {
      py::gil_scoped_release nogil;
      std::vector<double> figures;
      auto record = [&] {
        values.resize((rows + 1) * n);
        fillRow(&values[n * rows++], figures);
      };
      if (include_start) record();
      for (long k = 1; adaptive() ? sim_->state().t < until : k <= steps; ++k) {
        failure = stepOnce(until);
        if (failure.failed) break;
        if (k % every == 0) record();
      }
    }
    py::array record = recordArray(fields_, values, rows);
    if (failure.failed) raiseSimulationError(failure.message, record);
    return record;
  }

  nscd::State state() {
    BusyGuard g(busy_);
    return sim_->state();
  }

  void setState(const nscd::State& s) {
    BusyGuard g(busy_);
    sim_->setState(s);  // std::invalid_argument -> ValueError
    steps_ = std::llround(s.t / dt());
  }

  // State files (nscd_run --save-state / --initial-state); nscd::StateFileError ->
  // nscd_sim.StateFileError.
  void saveState(const py::object& path) {
    BusyGuard g(busy_);
    nscd::writeStateFile(fsPath(path), *sim_, "written by nscd_sim.Simulator('" + scene_ + "').save_state");
  }

  void loadState(const py::object& path) {
    BusyGuard g(busy_);
    const nscd::State s = nscd::readStateFile(fsPath(path), *sim_);
    sim_->setState(s);
    steps_ = std::llround(s.t / dt());
  }

  void reset() {
    BusyGuard g(busy_);
    sim_->reset();
    steps_ = 0;
    nscd::applySchedules(schedules_, 0.0, *sim_);
  }

  // ---------------------------------------------------------- outputs now
  py::array bodies() {
    BusyGuard g(busy_);
    const nscd::Model& m = model();
    std::vector<Field> f;
    for (const char* c : kBodyColumns) f.push_back({c});
    std::vector<double> v(m.bodies.size() * f.size());
    std::vector<std::string> names;
    for (size_t i = 0; i < m.bodies.size(); ++i) {
      bodyValues(static_cast<int>(i), &v[i * f.size()]);
      names.push_back(m.bodies[i].name);
    }
    return withNames(recordArray(f, v, m.bodies.size()), names);
  }

  py::array joints() {
    BusyGuard g(busy_);
    const nscd::Model& m = model();
    std::vector<double> v;
    std::vector<std::string> names;
    for (size_t j = 0; j < m.joints.size(); ++j) {
      if (m.joints[j].type == nscd::JointType::Fixed) continue;
      names.push_back(m.joints[j].name);
      v.push_back(sim_->jointPosition(static_cast<int>(j)));
      v.push_back(sim_->jointVelocity(static_cast<int>(j)));
    }
    return withNames(recordArray({{"q"}, {"qd"}}, v, names.size()), names);
  }

  py::array clearanceJoints() {
    BusyGuard g(busy_);
    const nscd::Model& m = model();
    std::vector<double> v;
    std::vector<std::string> names;
    for (size_t c = 0; c < m.clearance_joints.size(); ++c) {
      const int i = static_cast<int>(c);
      names.push_back(m.clearance_joints[c].name);
      v.insert(v.end(), {sim_->clearanceEccentricity(i), sim_->clearanceEccentricityAngle(i),
                         sim_->clearanceNormalForce(i)});
    }
    return withNames(recordArray({{"ecc"}, {"ecc_angle"}, {"fn"}}, v, names.size()), names);
  }

  py::array contacts() {
    BusyGuard g(busy_);
    const nscd::Model& m = model();
    std::vector<double> v;
    std::vector<std::string> names;
    for (size_t c = 0; c < m.contacts.size(); ++c) {
      const int i = static_cast<int>(c);
      names.push_back(m.contacts[c].name);
      v.insert(v.end(), {sim_->contactGap(i), sim_->contactNormalForce(i), sim_->contactTangentialForce(i)});
    }
    return withNames(recordArray({{"gap"}, {"fn"}, {"ft"}}, v, names.size()), names);
  }

  py::array contactPoints() {
    BusyGuard g(busy_);
    const nscd::Model& m = model();
    const std::vector<Field> f = {{"clearance", FieldType::Bool}, {"source", FieldType::Int32},
                                  {"feature", FieldType::Int32},  {"body_a", FieldType::Int32},
                                  {"body_b", FieldType::Int32},   {"px"}, {"py"}, {"pz"},
                                  {"nx"}, {"ny"}, {"nz"}, {"gap"}, {"fn"}, {"ftx"}, {"fty"}, {"ftz"},
                                  {"sliding", FieldType::Bool}};
    const std::vector<nscd::ContactReport>& points = sim_->contactPoints();
    std::vector<double> v;
    std::vector<std::string> names;
    for (const nscd::ContactReport& p : points) {
      names.push_back(p.clearance ? m.clearance_joints[p.source].name : m.contacts[p.source].name);
      v.insert(v.end(), {double(p.clearance), double(p.source), double(p.feature), double(p.body_a),
                         double(p.body_b), p.point.x(), p.point.y(), p.point.z(), p.normal.x(),
                         p.normal.y(), p.normal.z(), p.gap, p.fn, p.ft.x(), p.ft.y(), p.ft.z(),
                         double(p.sliding)});
    }
    return withNames(recordArray(f, v, points.size()), names);
  }

  py::dict stats() {
    BusyGuard g(busy_);
    const nscd::StepStats& s = sim_->stats();
    py::dict d;
    d["iterations"] = s.iterations;
    d["residual"] = s.residual;
    d["converged"] = s.converged;
    d["active_contacts"] = s.active_contacts;
    d["rows"] = s.rows;
    d["projection_passes"] = s.projection_passes;
    d["projection_least_distance"] = s.projection_least_distance;
    d["max_penetration"] = s.max_penetration;
    d["plastic_fallback"] = s.plastic_fallback;
    d["late_contacts"] = s.late_contacts;
    d["plastic_retry"] = s.plastic_retry;
    d["longer_solve"] = s.longer_solve;
    d["substeps"] = s.substeps;
    d["halvings"] = s.halvings;
    d["frictionless_fallback"] = s.frictionless_fallback;
    d["energy_capped"] = s.energy_capped;
    d["cold_retry"] = s.cold_retry;
    // How many of the step's solves each solver stage finished, and the rescues
    // it took (docs/solver.md).
    py::dict stages, rescues;
    for (int i = 0; i < nscd::kSolverStageCount; ++i)
      stages[nscd::solverStageName(static_cast<nscd::SolverStage>(i))] = s.solves_by_stage[i];
    for (int i = 0; i < nscd::kStepRescueCount; ++i)
      rescues[nscd::stepRescueName(static_cast<nscd::StepRescue>(i))] =
          nscd::stepTookRescue(s, static_cast<nscd::StepRescue>(i));
    d["solver_stages"] = stages;
    d["rescues"] = rescues;
    d["projection_energy_removed"] = s.projection_energy_removed;
    d["iteration_matrix_fallback"] = s.iteration_matrix_fallback;
    d["h"] = s.h;
    d["rejected"] = s.rejected;
    d["error"] = s.error;
    d["extrapolated"] = s.extrapolated;
    return d;
  }

  py::dict energy() {
    BusyGuard g(busy_);
    const nscd::EnergyReport e = sim_->energy();
    py::dict d;
    d["kinetic"] = e.kinetic;
    d["gravity"] = e.gravity;
    d["springs"] = e.springs;
    d["total"] = e.total();
    return d;
  }

  py::dict keyFigures() {
    BusyGuard g(busy_);
    std::vector<double> v;
    nscd::keyFigureValues(*sim_, v);
    const std::vector<std::string> names = nscd::keyFigureNames(model());
    py::dict d;
    for (size_t i = 0; i < names.size(); ++i) d[py::str(names[i])] = v[i];
    return d;
  }

  double time() {
    BusyGuard g(busy_);
    return sim_->state().t;
  }
  long steps() {
    BusyGuard g(busy_);
    return steps_;
  }
  const std::string& scene() const { return scene_; }
  const std::vector<std::string>& scheduleTexts() const { return texts_; }
  std::vector<std::string> fieldNames() const {
    std::vector<std::string> n;
    for (const Field& f : fields_) n.push_back(f.name);
    return n;
  }

 private:
  static constexpr const char* kBodyColumns[13] = {"x",  "y",  "z",  "qw", "qx", "qy", "qz",
                                                   "vx", "vy", "vz", "wx", "wy", "wz"};

  static std::string noActuator(const std::string& name, const nscd::Model& m) {
    std::string names;
    for (const nscd::Actuator& a : m.actuators) names += (names.empty() ? "" : ", ") + a.name;
    return "the scene has no actuator '" + name + "' (actuators: " + (names.empty() ? "none" : names) + ")";
  }

  static std::vector<nscd::BoundSchedule> bindSchedules(const std::vector<std::string>& texts,
                                                        const nscd::Model& model) {
    try {
      return nscd::bindCommandSchedules(texts, model);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string("commands: ") + e.what());
    }
  }

  // The CSV's columns (nscd_run, docs/interfaces.md), then the step statistics,
  // the energies and the joint velocities.
  void buildFields() {
    const nscd::Model& m = model();
    fields_.push_back({"t"});
    for (const nscd::Body& b : m.bodies)
      for (const char* c : kBodyColumns) fields_.push_back({b.name + "." + c});
    for (const std::string& n : nscd::keyFigureNames(m)) fields_.push_back({n});
    fields_.push_back({"iters", FieldType::Int32});
    fields_.push_back({"residual"});
    if (adaptive()) {  // the CSV's step columns (nscd_run, adaptive step control)
      fields_.push_back({"h"});
      fields_.push_back({"error"});
      fields_.push_back({"rejected", FieldType::Int32});
      fields_.push_back({"extrapolated", FieldType::Bool});
    }
    csv_fields_ = fields_.size();
    fields_.push_back({"converged", FieldType::Bool});
    fields_.push_back({"active_contacts", FieldType::Int32});
    fields_.push_back({"rows", FieldType::Int32});
    fields_.push_back({"projection_passes", FieldType::Int32});
    fields_.push_back({"late_contacts", FieldType::Int32});
    fields_.push_back({"max_penetration"});
    fields_.push_back({"plastic_fallback", FieldType::Bool});
    fields_.push_back({"frictionless_fallback", FieldType::Bool});
    fields_.push_back({"energy_capped", FieldType::Bool});
    fields_.push_back({"energy_kinetic"});
    fields_.push_back({"energy_gravity"});
    fields_.push_back({"energy_springs"});
    for (const nscd::Joint& j : m.joints)
      if (j.type != nscd::JointType::Fixed) fields_.push_back({j.name + ".qd"});
  }

  // x y z qw qx qy qz vx vy vz, then the angular velocity in the world frame
  // (computed as the CSV writer does).
  void bodyValues(int i, double* out) const {
    const nscd::BodyState& b = sim_->state().bodies[i];
    const nscd::Vec3 w = b.q * b.w;
    const double v[13] = {b.x.x(), b.x.y(), b.x.z(), b.q.w(), b.q.x(), b.q.y(), b.q.z(),
                          b.v.x(), b.v.y(), b.v.z(), w.x(),   w.y(),   w.z()};
    for (int c = 0; c < 13; ++c) out[c] = v[c];
  }

  void fillRow(double* row, std::vector<double>& figures) const {
    const nscd::Model& m = model();
    size_t c = 0;
    row[c++] = sim_->state().t;
    for (size_t i = 0; i < m.bodies.size(); ++i, c += 13) bodyValues(static_cast<int>(i), row + c);
    nscd::keyFigureValues(*sim_, figures);
    for (double v : figures) row[c++] = v;
    const nscd::StepStats& s = sim_->stats();
    row[c++] = s.iterations;
    row[c++] = s.residual;
    if (adaptive()) {
      row[c++] = s.h;
      row[c++] = s.error;
      row[c++] = s.rejected;
      row[c++] = s.extrapolated;
    }
    row[c++] = s.converged;
    row[c++] = s.active_contacts;
    row[c++] = s.rows;
    row[c++] = s.projection_passes;
    row[c++] = s.late_contacts;
    row[c++] = s.max_penetration;
    row[c++] = s.plastic_fallback;
    row[c++] = s.frictionless_fallback;
    row[c++] = s.energy_capped;
    const nscd::EnergyReport e = sim_->energy();
    row[c++] = e.kinetic;
    row[c++] = e.gravity;
    row[c++] = e.springs;
    for (size_t j = 0; j < m.joints.size(); ++j)
      if (m.joints[j].type != nscd::JointType::Fixed) row[c++] = sim_->jointVelocity(static_cast<int>(j));
  }

  // Step k = steps_ + 1, its commands set to the schedules' values at its end (as
  // nscd_run: k dt with fixed steps; adaptive steps end no later than `until`).
  StepFailure stepOnce(double until) {
    nscd::prepareScheduledStep(*sim_, schedules_, steps_ + 1, until);
    const nscd::StepStatus st = sim_->step();
    ++steps_;
    StepFailure f;
    if (st == nscd::StepStatus::NonFinite) {
      const nscd::StepStats& s = sim_->stats();
      char buf[256];
      std::snprintf(buf, sizeof buf,
                    "simulation failed at t=%g s: non-finite state (last solver residual %g after %d iterations)",
                    sim_->state().t, s.residual, s.iterations);
      f.failed = true;
      f.message = buf;
    }
    return f;
  }

  [[noreturn]] static void raiseSimulationError(const std::string& message, const py::object& record) {
    py::object err = exceptions().simulation_error(message);
    err.attr("record") = record;
    PyErr_SetObject(exceptions().simulation_error.ptr(), err.ptr());
    throw py::error_already_set();
  }

  std::string scene_;
  std::unique_ptr<nscd::Simulator> sim_;
  std::vector<std::string> texts_;
  std::vector<nscd::BoundSchedule> schedules_;
  long steps_ = 0;  // steps since t = 0: (fixed steps) step k's commands are the schedules' at k dt
  std::vector<Field> fields_;
  size_t csv_fields_ = 0;  // the first csv_fields_ fields are nscd_run's CSV columns
  std::atomic<bool> busy_{false};

 public:
  size_t csvFieldCount() const { return csv_fields_; }
};

// The names of a model's elements (clearance joints, contacts, springs, actuators).
template <class Element>
std::vector<std::string> namesOf(const std::vector<Element>& elements) {
  std::vector<std::string> names;
  for (const Element& e : elements) names.push_back(e.name);
  return names;
}

using PySimulatorClass = py::class_<PySimulator>;

// A few of the settings in force, as Simulator.settings gives them.
py::dict settingsDict(const nscd::Settings& st) {
  py::dict d;
  d["dt"] = st.dt;
  d["theta"] = st.theta;
  d["tolerance"] = st.tolerance;
  d["max_iterations"] = st.max_iterations;
  d["projection"] = st.projection;
  d["projection_tolerance"] = st.projection_tolerance;
  d["step_control"] = st.step_control == nscd::StepControl::Adaptive ? "adaptive" : "fixed";
  d["rtol"] = st.rtol;
  d["atol"] = st.atol;
  d["dt_min"] = st.dt_min;
  d["max_order"] = st.max_order;
  return d;
}

// Construction, stepping, state and commands.
void bindRunning(PySimulatorClass& c) {
  c.def(py::init<const std::string&, const py::object&, const py::object&, const py::object&>(),
           py::arg("scene"), py::arg("settings") = py::none(), py::arg("config") = py::none(),
           py::arg("commands") = py::none(),
           "Loads SCENE (URDF + <nscd>). settings: {key: value} or ['key=value', ...], applied "
           "after config (a YAML file), as nscd_run's --config and --set. commands: actuator "
           "schedules as nscd_run --command ('probe=0:0,0.0007:0', a list of them, or "
           "{'probe': [(0, 0), (0.0007, 0)]}); the scene's own schedules apply to the others. "
           "Raises SceneError (str: 'FILE:LINE: what') or ValueError.")
      .def("step", &PySimulator::step, py::arg("n") = 1,
           "Takes n steps (GIL released); returns n. Raises SimulationError on a non-finite state.")
      .def("run", &PySimulator::run, py::arg("duration"), py::arg("every") = 1,
           py::arg("include_start") = true,
           "Takes round(duration / dt) steps (adaptive step control: steps until the time has "
           "advanced by duration) (GIL released) and returns a structured array: one "
           "record for the state at the start (include_start) and one every `every` steps; fields "
           "in record_fields. Raises SimulationError (its .record: the rows before the failure).")
      .def("state", &PySimulator::state, "A copy of the current State.")
      .def("set_state", &PySimulator::setState, py::arg("state"),
           "Continues from a State of this scene; the last step's outputs are cleared.")
      .def("save_state", &PySimulator::saveState, py::arg("path"),
           "Writes the current State to a state file (nscd_run --save-state's format, bit for bit). "
           "Raises StateFileError if it cannot be written.")
      .def("load_state", &PySimulator::loadState, py::arg("path"),
           "Continues from a state file of this scene (nscd_run --initial-state's), as set_state. "
           "Raises StateFileError ('FILE:LINE: what') for a file of another scene, a damaged one "
           "or a non-finite value.")
      .def("reset", &PySimulator::reset, "Back to the initial state (t = 0).")
      .def("set_commands", &PySimulator::setCommands, py::arg("commands"),
           "Replaces the schedules given so far (same forms as the constructor's commands).")
      .def("set_command", &PySimulator::setCommand, py::arg("actuator"), py::arg("value"),
           "Sets an actuator's command now (one that no schedule drives).");
}

// The structured arrays and dicts of the current state and the last step.
void bindQueries(PySimulatorClass& c) {
  c.def("bodies", &PySimulator::bodies,
           "Structured array, one record per free body: name, x y z, qw qx qy qz, vx vy vz, "
           "wx wy wz (world frame).")
      .def("joints", &PySimulator::joints,
           "Structured array, one record per joint that is not fixed: name, q, qd.")
      .def("clearance_joints", &PySimulator::clearanceJoints,
           "Structured array, one record per clearance joint: name, ecc, ecc_angle, fn.")
      .def("contacts", &PySimulator::contacts,
           "Structured array, one record per named contact: name, gap, fn, ft (last step).")
      .def("contact_points", &PySimulator::contactPoints,
           "Structured array, one record per active contact point of the last step.")
      .def("stats", &PySimulator::stats, "The last step's statistics (dict).")
      .def("energy", &PySimulator::energy, "kinetic, gravity, springs, total energy, J (dict).")
      .def("key_figures", &PySimulator::keyFigures,
           "The CSV's columns after the bodies' at the current state, {name: value}.");
}

// Time, steps, dt, scene, commands, record fields and settings.
void bindProperties(PySimulatorClass& c) {
  c.def_property_readonly("time", &PySimulator::time, "sim time, s")
      .def_property_readonly("steps", &PySimulator::steps, "steps since t = 0")
      .def_property_readonly("dt", &PySimulator::dt, "time step, s")
      .def_property_readonly("scene", &PySimulator::scene)
      .def_property_readonly("commands", &PySimulator::scheduleTexts,
                             "the schedules given, as nscd_run --command texts")
      .def_property_readonly("record_fields", &PySimulator::fieldNames, "field names of run()'s records")
      .def_property_readonly("csv_field_count", &PySimulator::csvFieldCount,
                             "the first csv_field_count record fields are nscd_run's CSV columns")
      .def_property_readonly("settings", [](PySimulator& s) { return settingsDict(s.model().settings); },
                             "a few of the settings in force");
}

// The model's element names.
void bindNames(PySimulatorClass& c) {
  c.def_property_readonly("body_names", [](PySimulator& s) {
        std::vector<std::string> n;
        for (const nscd::Body& b : s.model().bodies) n.push_back(b.name);
        return n;
      })
      .def_property_readonly("joint_names", [](PySimulator& s) {
        std::vector<std::string> n;
        for (const nscd::Joint& j : s.model().joints)
          if (j.type != nscd::JointType::Fixed) n.push_back(j.name);
        return n;
      }, "joints that are not fixed")
      .def_property_readonly("clearance_joint_names", [](PySimulator& s) { return namesOf(s.model().clearance_joints); })
      .def_property_readonly("contact_names", [](PySimulator& s) { return namesOf(s.model().contacts); })
      .def_property_readonly("spring_names", [](PySimulator& s) { return namesOf(s.model().springs); })
      .def_property_readonly("actuator_names", [](PySimulator& s) { return namesOf(s.model().actuators); });
}

}  // namespace

void bindSimulator(py::module_& m) {
  PySimulatorClass c(m, "Simulator",
                     "A scene loaded with setting overrides and command schedules (docs/python.md).");
  bindRunning(c);
  bindQueries(c);
  bindProperties(c);
  bindNames(c);
}

}  // namespace nscd_python
