// Stage 7: energy bookkeeping. Kinetic and potential energies (reports, the
// safeguards' measures), and the projection's correction: the projection moves
// positions only, so potential energy it adds (it lifts a body that drifted into
// a contact; the exact motion never did) beyond the work the inputs did in the
// step (a driven table pushing a spring-loaded part: the drift into the table is
// that work, delivered late) is a discretisation artefact, taken back from the
// kinetic energy of the bodies whose motion is not prescribed. Springs applied as
// body-fixed loads are not conservative: no potential, their work is input work.
#include <algorithm>
#include <cmath>

#include "step_stages.hpp"

namespace nscd {
namespace {

// Kinetic energy of one body (v world, w body frame).
double bodyKineticEnergy(const Body& body, const Vec3& v, const Vec3& w) {
  return 0.5 * (body.mass * v.squaredNorm() + w.dot(body.inertia * w));
}

// Takes `amount` (J) out of the kinetic energy of the state by one common
// factor on every velocity but the prescribed bodies' (homogeneous velocity
// constraints among them stay satisfied); all of it if there is less. Returns
// what was taken.
double removeKineticEnergy(const Model& m, const std::vector<char>& prescribed, State& s, double amount) {
  double k = 0;
  for (size_t i = 0; i < m.bodies.size(); ++i)
    if (!prescribed[i]) k += bodyKineticEnergy(m.bodies[i], s.bodies[i].v, s.bodies[i].w);
  if (!(k > 0)) return 0;
  const double f = amount < k ? std::sqrt(1 - amount / k) : 0.0;
  for (size_t i = 0; i < m.bodies.size(); ++i) {
    if (prescribed[i]) continue;
    s.bodies[i].v *= f;
    s.bodies[i].w *= f;
  }
  return std::min(amount, k);
}

}  // namespace

double kineticEnergyOf(const Model& m, const Eigen::VectorXd& v) {
  double k = 0;
  for (size_t b = 0; b < m.bodies.size(); ++b)
    k += bodyKineticEnergy(m.bodies[b], v.segment<3>(6 * b), v.segment<3>(6 * b + 3));
  return k;
}

double kineticEnergyOf(const Model& m, const State& s) {
  double k = 0;
  for (size_t i = 0; i < m.bodies.size(); ++i)
    k += bodyKineticEnergy(m.bodies[i], s.bodies[i].v, s.bodies[i].w);
  return k;
}

EnergyReport potentialEnergyOf(const Model& m, const State& s) {
  EnergyReport e;
  for (size_t i = 0; i < m.bodies.size(); ++i)
    e.gravity -= m.bodies[i].mass * m.settings.gravity.dot(s.bodies[i].x);
  for (size_t i = 0; i < m.springs.size(); ++i) {
    const Spring& sp = m.springs[i];
    // A spring applied as body-fixed loads has no potential: the loads' work is
    // not the change of 1/2 k stretch^2. It is counted as input work instead.
    if (!sp.loads.empty()) continue;
    const double stretch = springStretchAt(m, s, static_cast<int>(i));
    e.springs += 0.5 * sp.stiffness * stretch * stretch;
  }
  return e;
}

double inputWorkOfStep(const Model& m, double h, const StepWorkspace& ws, const StepOutputs& out, const State& s) {
  double work = 0;
  for (size_t i = 0; i < m.actuators.size(); ++i) {
    const Actuator& ac = m.actuators[i];
    if (ac.type == ActuatorType::Prescribed)
      work += out.actuator_effort[i] * ws.rates[i] * h;
    else if (ac.type == ActuatorType::Position)
      work += out.actuator_effort[i] * jointVelocity(m, s, ac.joint) * h;
  }
  for (size_t i = 0; i < m.springs.size(); ++i)
    if (!m.springs[i].loads.empty()) work += springLoadPowerAt(m, s, static_cast<int>(i)) * h;
  return std::max(0.0, work);
}

double takeBackProjectionEnergy(const Model& m, const StepWorkspace& ws, double potential_before, State& s) {
  const double gain = potentialEnergyOf(m, s).total() - potential_before;
  return gain > 0 ? removeKineticEnergy(m, ws.facts.prescribed_body, s, gain) : 0.0;
}

}  // namespace nscd
