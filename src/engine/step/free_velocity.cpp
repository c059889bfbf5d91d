// Stage 1c: the free velocity, v_free = v_k + Ŵ rhs (what the bodies would do
// without constraints), with the gyroscopic torques.
#include <cmath>
#include <utility>

#include "step_stages.hpp"

namespace nscd {

namespace {

// a.partialPivLu().solve(x) for a 3 x 3, operation for operation as Eigen 3.4
// computes it (PartialPivLU.h: unblocked_lu, the first largest |pivot|, the column
// divided by the pivot, the rank-1 update; SolveTriangular.h: the unrolled unit-lower
// then upper solves, each row's products summed left to right), without the
// decomposition's set-up (its L1 norm, the permutation object): the same bits.
Vec3 partialPivLuSolve3(Mat3 a, Vec3 x) {
  int t[2];
  for (int k = 0; k < 2; ++k) {
    int p = k;
    double big = std::abs(a(k, k));
    for (int i = k + 1; i < 3; ++i) {
      const double v = std::abs(a(i, k));
      if (v > big) {
        big = v;
        p = i;
      }
    }
    t[k] = p;
    if (big != 0) {
      if (p != k) a.row(k).swap(a.row(p));
      const double pivot = a(k, k);
      for (int i = k + 1; i < 3; ++i) a(i, k) /= pivot;
    }
    for (int j = k + 1; j < 3; ++j)
      for (int i = k + 1; i < 3; ++i) a(i, j) -= a(i, k) * a(k, j);
  }
  for (int k = 0; k < 2; ++k) std::swap(x(k), x(t[k]));
  x(1) -= a(1, 0) * x(0);
  x(2) -= a(2, 0) * x(0) + a(2, 1) * x(1);
  x(2) /= a(2, 2);
  x(1) -= a(1, 2) * x(2);
  x(1) /= a(1, 1);
  x(0) -= a(0, 1) * x(1) + a(0, 2) * x(2);
  x(0) /= a(0, 0);
  return x;
}

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
      w -= partialPivLuSolve3(jac, r);
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
