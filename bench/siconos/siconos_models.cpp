// The comparison models built with the Siconos kernel: LagrangianLinearTIDS
// bodies, Moreau-Jean (MoreauJeanOSI + TimeStepping) or the combined projection
// (MoreauJeanCombinedProjectionOSI + TimeSteppingCombinedProjection with
// MLCPProjectOnConstraints), FrictionContact one-step problems.
#include <SiconosKernel.hpp>
#include <Friction_cst.h>
#include <SolverOptions.h>
#include <mlcp_cst.h>

#include <cmath>

#include "models.hpp"
#include "run_loop.hpp"

namespace nscd_siconos {

namespace {

// Pin-in-hole gap of the planar arm, q = (x_c, y_c, theta) of the centre of mass.
// Hole centre p = c - R(theta) (0, -l) = (x_c - l sin, y_c + l cos); gap = cr - |p|.
// Output rows: normal (the gap), tangent (zero at position level; its Jacobian
// row is the sliding velocity of the arm's material point at the contact).
class PinInHoleR : public LagrangianScleronomousR {
 public:
  PinInHoleR(double l, double rj, double cr) : l_(l), rj_(rj), cr_(cr) {}

  void initialize(Interaction& inter) override {
    LagrangianScleronomousR::initialize(inter);
    if (!_jachq) _jachq.reset(new SimpleMatrix(2, 3));
  }

  void computeh(const BlockVector& q, BlockVector&, SiconosVector& y) override {
    double px, py, ux, uy;
    hole(q, px, py, ux, uy);
    y(0) = cr_ - std::hypot(px, py);
    y(1) = 0;
  }

  void computeJachq(const BlockVector& q, BlockVector&) override {
    double px, py, ux, uy;
    hole(q, px, py, ux, uy);
    const double th = q.getValue(2), s = std::sin(th), c = std::cos(th);
    // Contact point on the hole wall: p - (rj + cr) u; its offset from the centre of mass.
    const double R = rj_ + cr_;
    const double rx = -l_ * s - R * ux, ry = l_ * c - R * uy;
    const double nx = -ux, ny = -uy;  // normal on the arm (gap grows along it)
    const double tx = -ny, ty = nx;   // in-plane tangent z x n
    // Row = d . (v_c + omega z x r) for direction d: [dx, dy, dx (-ry) + dy rx].
    SimpleMatrix& J = *_jachq;
    J(0, 0) = nx; J(0, 1) = ny; J(0, 2) = -nx * ry + ny * rx;
    J(1, 0) = tx; J(1, 1) = ty; J(1, 2) = -tx * ry + ty * rx;
  }

 private:
  void hole(const BlockVector& q, double& px, double& py, double& ux, double& uy) const {
    const double th = q.getValue(2);
    px = q.getValue(0) - l_ * std::sin(th);
    py = q.getValue(1) + l_ * std::cos(th);
    const double n = std::hypot(px, py);
    if (n > 1e-300) {
      ux = px / n;
      uy = py / n;
    } else {  // centred: any direction (the contact is open then)
      ux = 0;
      uy = -1;
    }
  }
  double l_, rj_, cr_;
};

SP::SiconosVector vec(std::initializer_list<double> v) {
  SP::SiconosVector x(new SiconosVector(static_cast<unsigned>(v.size())));
  unsigned i = 0;
  for (double a : v) (*x)(i++) = a;
  return x;
}

// The system of one body `ds` and one interaction (`law`, `rel`) on [0, T], and its
// time stepping (scheme and solver settings of `o`), initialised.
SP::TimeStepping makeSimulation(SP::DynamicalSystem ds, SP::NonSmoothLaw law, SP::Relation rel,
                                double T, const RunOptions& o, int dim) {
  SP::Interaction inter(new Interaction(law, rel));
  SP::NonSmoothDynamicalSystem nsds(new NonSmoothDynamicalSystem(0, T));
  nsds->insertDynamicalSystem(ds);
  nsds->link(inter, ds);
  SP::TimeDiscretisation td(new TimeDiscretisation(0, o.h));
  SP::FrictionContact fc(new FrictionContact(
      dim, dim == 2 ? SICONOS_FRICTION_2D_NSGS : SICONOS_FRICTION_3D_NSGS));
  fc->numericsSolverOptions()->dparam[SICONOS_DPARAM_TOL] = o.tolerance;
  fc->numericsSolverOptions()->iparam[SICONOS_IPARAM_MAX_ITER] = o.max_iterations;
  SP::TimeStepping s;
  if (o.scheme == Scheme::MoreauJean) {
    SP::MoreauJeanOSI osi(new MoreauJeanOSI(0.5));
    s.reset(new TimeStepping(nsds, td, osi, fc));
  } else {
    SP::MoreauJeanCombinedProjectionOSI osi(new MoreauJeanCombinedProjectionOSI(0.5));
    SP::MLCPProjectOnConstraints pos(new MLCPProjectOnConstraints(SICONOS_MLCP_ENUM, 1.0));
    SP::TimeSteppingCombinedProjection cp(
        new TimeSteppingCombinedProjection(nsds, td, osi, fc, pos, 2));
    cp->setConstraintTol(1e-9);
    cp->setConstraintTolUnilateral(1e-9);
    cp->setProjectionMaxIteration(20);
    s = cp;
  }
  if (!o.siconos_newton) s->setNewtonOptions(SICONOS_TS_LINEAR);
  s->initialize();
  return s;
}

void step(TimeStepping& s) {
  s.computeOneStep();
  s.nextStep();
}

}  // namespace

RunResult runBallSiconos(const BallParams& p, const RunOptions& o) {
  return guardedRun([&](RunResult& res) {
    // q = (x, y, z, phi_x, phi_y, phi_z) with world-frame rotation rates: exact for a
    // sphere of isotropic inertia, whose orientation enters nothing here.
    const double I = 0.4 * p.m * p.r * p.r;
    SP::SimpleMatrix M(new SimpleMatrix(6, 6));
    M->zero();
    for (int i = 0; i < 3; ++i) {
      (*M)(i, i) = p.m;
      (*M)(i + 3, i + 3) = I;
    }
    SP::LagrangianLinearTIDS ball(new LagrangianLinearTIDS(
        vec({0, 0, p.h0 + p.r, 0, 0, 0}), vec({0, 0, 0, 0, 0, 0}), M));
    ball->setFExtPtr(vec({0, 0, -p.m * p.g, 0, 0, 0}));
    // Rows: gap z - r; sliding velocity of the lowest point along x and y.
    SP::SimpleMatrix H(new SimpleMatrix(3, 6));
    H->zero();
    (*H)(0, 2) = 1;
    (*H)(1, 0) = 1;
    (*H)(1, 4) = -p.r;
    (*H)(2, 1) = 1;
    (*H)(2, 3) = p.r;
    SP::Relation rel(new LagrangianLinearTIR(H, vec({-p.r, 0, 0})));
    SP::NonSmoothLaw law(new NewtonImpactFrictionNSL(p.e, 0.0, p.mu, 3));
    SP::TimeStepping s = makeSimulation(ball, law, rel, p.T, o, 3);

    const SiconosVector& q = *ball->q();
    const SiconosVector& v = *ball->velocity();
    ApexDetector apex(p.g);
    runSampled(
        res, p.T, o,
        [&] {
          step(*s);
          apex.update(q.getValue(2) - p.r, v.getValue(2), res.apex);
        },
        [&] { return Sample{q.getValue(2) - p.r, q.getValue(0), p.r - q.getValue(2)}; });
  });
}

RunResult runPendulumSiconos(const PendulumParams& p, const RunOptions& o) {
  return guardedRun([&](RunResult& res) {
    SP::SimpleMatrix M(new SimpleMatrix(3, 3));
    M->zero();
    (*M)(0, 0) = p.m;
    (*M)(1, 1) = p.m;
    (*M)(2, 2) = p.I;
    // Hole centred on the pin at rest: centre of mass at R(theta0) (0, -l).
    const double s0 = std::sin(p.theta0), c0 = std::cos(p.theta0);
    SP::LagrangianLinearTIDS arm(
        new LagrangianLinearTIDS(vec({p.l * s0, -p.l * c0, p.theta0}), vec({0, 0, 0}), M));
    arm->setFExtPtr(vec({0, -p.m * p.g, 0}));
    SP::Relation rel(new PinInHoleR(p.l, p.rj, p.cr));
    SP::NonSmoothLaw law(new NewtonImpactFrictionNSL(0.0, 0.0, p.mu, 2));
    SP::TimeStepping s = makeSimulation(arm, law, rel, p.T, o, 2);

    const SiconosVector& q = *arm->q();
    runSampled(
        res, p.T, o, [&] { step(*s); },
        [&] {
          const double th = q.getValue(2);
          const double px = q.getValue(0) - p.l * std::sin(th), py = q.getValue(1) + p.l * std::cos(th);
          const double ecc = std::hypot(px, py);
          return Sample{th, ecc / p.cr, ecc - p.cr};
        });
  });
}

}  // namespace nscd_siconos
