// Stage 7: energy bookkeeping. Kinetic and potential energies (reports, the
// safeguards' measures), and the projection's correction. The projection moves
// positions only, so potential energy it adds (it lifts a body that drifted into
// a contact; the exact motion never did) beyond the work the inputs did in the
// step (a driven table pushing a spring-loaded part: the drift into the table is
// that work, delivered late) is a discretisation artefact, taken back from the
// kinetic energy of the bodies whose motion is not prescribed, but only as far as
// the step as a whole gained energy: often the drift's released potential was
// already dissipated by the step's impulses (a spring-loaded part stopped at a
// stop, its positions lagging with theta = 1/2), and the projection only restores
// it; taking it from the kinetic energy again stopped the whole C-60 mechanism
// every other step (docs/c60_convergence.md, section 3). Where the projection
// left contacts, what is taken comes first from the contacts still approaching,
// by a plastic impact on them; taking it along the whole mechanism's correction
// instead gave every body the correction carried a velocity along its share (a
// C-60 handle at rest set turning, the latch load 12 % high for the rest of the
// trip: section 3). With ideal joints alone it comes first from the velocity
// against the correction, the joints' drift. The rest by one common factor.
// Springs applied as body-fixed loads are not conservative: no potential, their
// work is input work.
#include <algorithm>
#include <cmath>

#include "step_stages.hpp"

namespace nscd {
namespace {

// Kinetic energy of one body (v world, w body frame).
double bodyKineticEnergy(const Body& body, const Vec3& v, const Vec3& w) {
  return 0.5 * (body.mass * v.squaredNorm() + w.dot(body.inertia * w));
}

// Takes up to `amount` (J) out of the velocity's component, in the mass metric,
// along the projection's correction d (from `unprojected` to s) when the velocity
// points against d (into what the projection corrected); at most all of that
// component. d is a motion of the whole mechanism the joints allow (the
// projection solves for every row at once), so is what is left. Returns what was taken.
// turn: scratch, one per body (each body's turn, its logarithm taken once).
double removeAgainstCorrection(const Model& m, const std::vector<char>& prescribed,
                               const std::vector<BodyState>& unprojected, std::vector<Vec3>& turn, State& s,
                               double amount) {
  double dmd = 0, dmv = 0;
  for (size_t i = 0; i < m.bodies.size(); ++i) {
    if (prescribed[i]) continue;
    const Body& b = m.bodies[i];
    const Vec3 dx = s.bodies[i].x - unprojected[i].x;
    const Vec3& dr = turn[i] = logMap(unprojected[i].q.conjugate() * s.bodies[i].q);  // body frame, as w
    dmd += b.mass * dx.squaredNorm() + dr.dot(b.inertia * dr);
    dmv += b.mass * dx.dot(s.bodies[i].v) + dr.dot(b.inertia * s.bodies[i].w);
  }
  if (!(dmd > 0) || !(dmv < 0)) return 0;
  const double c = dmv / dmd;            // velocity = c d + a part orthogonal to d
  const double along = 0.5 * c * c * dmd;  // the kinetic energy of c d
  const double taken = std::min(amount, along);
  const double cut = c * (1 - std::sqrt(std::max(0.0, 1 - taken / along)));
  for (size_t i = 0; i < m.bodies.size(); ++i) {
    if (prescribed[i]) continue;
    s.bodies[i].v -= cut * (s.bodies[i].x - unprojected[i].x);
    s.bodies[i].w -= cut * turn[i];
  }
  return taken;
}

// Takes up to `amount` (J) out of the kinetic energy by an impulse at the rows of
// the projection's last check (ws.blocks, gathered at s): the plastic impact
// 0 <= p _|_ G v + W p + max(gap, 0) / h >= 0 on the contact rows (an open row
// only if it approaches faster than its gap closes in a step of h), ideal
// joints' rows brought to zero relative velocity, prescribed motions' rows left
// as they are; v += alpha M^-1 G^T p, alpha <= 1 the fraction that takes
// `amount` when the whole impact would take more. Bodies
// reach each other only through rows that approach, as in an impact: a body the
// correction merely carried keeps its velocity. Prescribed bodies keep theirs.
// Returns what was taken; 0 if the rows are not solved.
double removeByPlasticImpact(const Model& m, double h, const std::vector<char>& prescribed, StepWorkspace& ws,
                             State& s, double amount) {
  const int r = ws.rows;
  stateVelocities(s, ws.dq);  // ws.dq: scratch once the projection is done
  positionProblem(s, ws);  // b set again below
  ws.b.head(r).noalias() = ws.G.topRows(r) * ws.dq;
  for (const ConstraintBlock& blk : ws.blocks) {
    if (blk.kind != BlockKind::Bilateral)
      ws.b[blk.row] += std::max(0.0, blk.contact.cp.gap) / h;
    else if (blk.joint < 0)  // a prescribed motion: its rate is the command's
      ws.b.segment(blk.row, blk.size).setZero();
  }
  assembleDelassus(ws.mass_inverse, true, ws, 0, r);
  ws.P.head(r).setZero();
  const SolverReport rep =
      ws.solver.solve(ws.W.topLeftCorner(r, r), ws.b.head(r), ws.problem, solverOptions(m.settings), ws.P.head(r));
  if (!rep.converged || !ws.P.head(r).allFinite()) return 0;
  ws.dq.noalias() = ws.Y.leftCols(r) * ws.P.head(r);  // the impact's velocity change
  // Kinetic energy removed by alpha of it: -(alpha a + alpha^2 q / 2).
  double a = 0, q = 0;
  for (size_t i = 0; i < m.bodies.size(); ++i) {
    if (prescribed[i]) continue;
    const Body& b = m.bodies[i];
    const Vec3 dv = ws.dq.segment<3>(6 * i), dw = ws.dq.segment<3>(6 * i + 3);
    a += b.mass * dv.dot(s.bodies[i].v) + dw.dot(b.inertia * s.bodies[i].w);
    q += b.mass * dv.squaredNorm() + dw.dot(b.inertia * dw);
  }
  if (!(q > 0) || !(a < 0)) return 0;
  const double full = std::min(1.0, -a / q);
  const double most = -(full * a + 0.5 * full * full * q);
  const double alpha = amount < most ? (-a - std::sqrt(std::max(0.0, a * a - 2 * q * amount))) / q : full;
  for (size_t i = 0; i < m.bodies.size(); ++i) {
    if (prescribed[i]) continue;
    s.bodies[i].v += alpha * ws.dq.segment<3>(6 * i);
    s.bodies[i].w += alpha * ws.dq.segment<3>(6 * i + 3);
  }
  return std::min(amount, most);
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

double totalEnergyOf(const Model& m, const State& s) { return kineticEnergyOf(m, s) + potentialEnergyOf(m, s).total(); }

double StepStartEnergy::value(const Model& m) const {
  if (state) return totalEnergyOf(m, *state);
  return kineticEnergyOf(m, *velocities) + potential + input_work;  // as totalEnergyOf(start) + input_work
}

double takeBackProjectionEnergy(const Model& m, double h, StepWorkspace& ws, double potential_before,
                                const StepStartEnergy& start, State& s) {
  const double potential = potentialEnergyOf(m, s).total();
  const double projection_gain = potential - potential_before;
  if (!(projection_gain > 0)) return 0.0;
  const double step_gain = kineticEnergyOf(m, s) + potential - start.value(m);
  const double excess = std::min(projection_gain, step_gain);
  if (!(excess > 0)) return 0.0;
  const std::vector<char>& prescribed = ws.facts.prescribed_body;
  // Ideal joints alone: no solve (most of their steps take something back). The
  // projection's check gathers the bilateral rows first and the contacts after them
  // (gatherPositionRows), so the last block says whether there are contact rows.
  const bool contacts = !ws.blocks.empty() && ws.blocks.back().kind != BlockKind::Bilateral;
  const double first = contacts ? removeByPlasticImpact(m, h, prescribed, ws, s, excess)
                                : removeAgainstCorrection(m, prescribed, ws.unprojected_bodies, ws.projection_turn, s, excess);
  return first < excess ? first + removeKineticEnergy(m, prescribed, s, excess - first) : first;
}

}  // namespace nscd
