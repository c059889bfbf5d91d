// Stage 5: position update of the theta-scheme. Quaternions advance by the
// exponential map of the body-frame rotation vector (unit by construction).
#include "step_stages.hpp"

namespace nscd {

void stateVelocities(const State& s, Eigen::VectorXd& v) {
  for (size_t i = 0; i < s.bodies.size(); ++i) {
    v.segment<3>(6 * i) = s.bodies[i].v;
    v.segment<3>(6 * i + 3) = s.bodies[i].w;
  }
}

void setStateVelocities(State& s, const Eigen::VectorXd& v) {
  for (size_t i = 0; i < s.bodies.size(); ++i) {
    s.bodies[i].v = v.segment<3>(6 * i);
    s.bodies[i].w = v.segment<3>(6 * i + 3);
  }
}

void advanceState(const Model& m, double h, const StepWorkspace& ws, State& s) {
  integratePositions(s, ws.vk, ws.vnew, h, m.settings.theta);
  setStateVelocities(s, ws.vnew);
  s.t += h;
  s.prev_commands = s.commands;
}

void integratePositions(State& s, const Eigen::VectorXd& vk, const Eigen::VectorXd& vnew,
                        double h, double theta) {
  for (size_t i = 0; i < s.bodies.size(); ++i) {
    BodyState& b = s.bodies[i];
    const Vec6 vm = theta * vnew.segment<6>(6 * i) + (1.0 - theta) * vk.segment<6>(6 * i);
    b.x += h * vm.head<3>();
    b.q = (b.q * expMap(h * vm.tail<3>())).normalized();
  }
}

void predictState(const State& s, double ahead, State& out) {
  out.t = s.t + ahead;
  for (size_t i = 0; i < s.bodies.size(); ++i) {
    const BodyState& b = s.bodies[i];
    BodyState& p = out.bodies[i];
    p = b;
    p.x += ahead * b.v;
    p.q = (b.q * expMap(ahead * b.w)).normalized();
  }
}

void applyDisplacement(State& s, const Eigen::VectorXd& dq) {
  for (size_t i = 0; i < s.bodies.size(); ++i) {
    BodyState& b = s.bodies[i];
    b.x += dq.segment<3>(6 * i);
    b.q = (b.q * expMap(dq.segment<3>(6 * i + 3))).normalized();
  }
}

}  // namespace nscd
