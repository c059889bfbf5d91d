// Stage 1c: the free velocity, v_free = v_k + Ŵ rhs (what the bodies would do
// without constraints), with the gyroscopic torques.
#include "step_stages.hpp"

namespace nscd {

namespace {

// Gyroscopic torques -w x J w, by backward Euler per body: the w that solves
// J (w - w_f) + h w x J w = 0 (Newton from w_f, the free velocity without them),
// applied as the impulse J (w - w_f) through the iteration matrix. The explicit
// torque gains kinetic energy at O(h^2) every step of a tumbling body; backward
// Euler cannot (w.J.w = w.J.w_f <= |w|_J |w_f|_J).
void addGyroscopicImpulses(const Model& m, double h, StepWorkspace& ws) {
  bool any = false;
  ws.gyro_impulse.setZero();
  for (int i = 0; i < ws.nbodies; ++i) {
    const Vec3 wf = ws.vfree.segment<3>(6 * i + 3);
    const Mat3& J = m.bodies[i].inertia;
    if (wf.cross(J * wf).squaredNorm() == 0) continue;  // about a principal axis (or at rest)
    Vec3 w = wf;
    for (int it = 0; it < 3; ++it) {
      const Vec3 Jw = J * w;
      const Vec3 r = J * (w - wf) + h * w.cross(Jw);
      const Mat3 jac = J + h * (skew(w) * J - skew(Jw));
      w -= jac.partialPivLu().solve(r);
    }
    ws.gyro_impulse.segment<3>(6 * i + 3) = J * (w - wf);
    any = true;
  }
  if (any) addIterationInverseTimes(ws, ws.gyro_impulse, ws.vfree);
}

}  // namespace

void computeFreeVelocity(const Model& m, double h, StepWorkspace& ws) {
  ws.vfree = ws.vk;
  addIterationInverseTimes(ws, ws.rhs, ws.vfree);
  addGyroscopicImpulses(m, h, ws);
}

}  // namespace nscd
