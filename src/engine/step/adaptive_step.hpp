// Adaptive step control (Settings::step_control = adaptive), internal to the
// engine. A step of length h is taken from the same State along two paths: a
// coarse one of 2 substeps of h/2 and a fine one of 4 substeps of h/4 (why not 1
// and 2: kCoarseSubsteps, adaptive_step.cpp). Their difference is the local error
// estimate (for a first-order scheme the coarse path errs by 2 C (h/2)^2, the
// fine one by half that: the difference is the fine path's error). Where nothing
// nonsmooth happened in the step, their Richardson combination is kept
// (kRichardsonFactor), else the fine path's answer; a PI controller picks the
// next length. The fine path is taken first: where it has a nonsmooth event its
// answer is first order anyway, the coarse path is skipped and the error is
// estimated from the fine path's own substeps (embeddedEventError). So too where
// the step is at dt and that estimate is far within the tolerance
// (cappedWellWithinTolerance): the coarse path could not lengthen it. Where every
// contact is open at the step's start (a mechanism of ideal joints, a body in
// flight) and Settings::max_order > 2, the paths are
// taken without the projection and, while the estimate is above the tolerance,
// paths of 6, 8, ... substeps are added to an Aitken-Neville tableau (order k
// with k paths); the order and the next length are chosen for the least work
// per unit time (extrapolationStepLength), the answer projected once. Three files:
//   step_doubling.cpp         the error norm, the contact modes, the extrapolation
//   step_size_controller.cpp  the PI law, the order and length of smooth steps,
//                             rejections and the floor
//   adaptive_step.cpp         Simulator::stepAdaptive and planStep
#pragma once

#include <vector>

#include "step_workspace.hpp"

namespace nscd {

// The buffers of an adaptive step, sized once when the simulator is made.
struct AdaptiveStepWorkspace {
  State start;          // the State the step starts from (restored for each path)
  State coarse;         // after the coarse path
  // The bodies at the start and after each substep of the last fine path
  // (kFineSubsteps + 1 entries): the embedded estimate of an event step.
  std::vector<std::vector<BodyState>> fine_substeps;
  // What the fine path reported (its last substep's outputs), kept while the
  // coarse path is taken after it.
  StepOutputs fine_report;
  // False when the last attempt's fine path had an event, or was capped at dt
  // far within the tolerance: the coarse path was not taken (coarse_out and
  // coarse are stale).
  bool coarse_taken = true;
  std::vector<double> start_command;  // the commands the planned step starts from (planStep)
  std::vector<double> end_command;    // the commands at the end of the planned step
  StepOutputs coarse_out, fine_out;  // the paths' forces (averaged) and stats
  std::vector<double> slot_mu;       // friction coefficient of each warm-start slot
  std::vector<double> rotation_length;  // per body (m): rotationLength
  // The extrapolation tableau of a smooth step (Settings::max_order > 2): row[k]
  // the bodies of T_{j,k} for the last level j taken; cur and tmp scratch.
  std::vector<std::vector<BodyState>> row;
  std::vector<BodyState> cur, tmp;
  StepOutputs level_out;  // the forces of the paths finer than the fine one (not kept)
  // What the last attempt was: tableau (a smooth step with every contact open,
  // the order chosen by extrapolationStepLength), the order of its answer (2:
  // the coarse and fine paths' combination), and errors[k] the error estimate of
  // T_{k,k-1} against T_{k,k} for k = 2 .. order (errors[2]: the paths' difference).
  bool tableau = false;
  int order = 2;
  std::vector<double> errors;
  // False while the paths of a smooth step are taken: their substeps skip the
  // projection (Simulator::advance), the step's answer is projected once.
  bool project_substeps = true;
  // The substep length of the last path taken (whose warm starts state_ holds).
  double kept_substep = 0;
  // True while the unprojected paths of a step that starts with every contact
  // open are taken: a substep with an event ends them (they are taken again).
  bool stop_at_event = false;
};

// Sizes the buffers for the model (`state`: the simulator's, for the sizes).
void initAdaptiveStep(const Model& m, const StepWorkspace& ws, const State& state,
                      AdaptiveStepWorkspace& a);

// ---- step_doubling.cpp
// The largest difference between two states' bodies, each component scaled by
// atol + rtol max(|a|, |b|): positions, velocities times velocity_weight, and the
// rotations as what they move a point at the body's rotation_length (m) by:
// angular velocities (world frame, times velocity_weight) times that length, and
// the angle between the orientations times it (scaled by atol + rtol length).
// Every component is a length or a speed, so atol is m and m/s for every body.
// Infinite if either state is not finite.
double scaledStateDifference(const State& a, const State& b, double atol, double rtol,
                             double velocity_weight, const std::vector<double>& rotation_length);
double scaledBodiesDifference(const std::vector<BodyState>& a, const std::vector<BodyState>& b, double atol,
                              double rtol, double velocity_weight, const std::vector<double>& rotation_length);
// A body's length for its rotations: the farthest point, from its centre of mass,
// of what it is attached by or touches (joint anchors, bearings with their length,
// contact shapes, spring ends), and at least its radius of gyration
// sqrt(trace I / 2 m); 1 m if none of these gives a positive length. A pendulum
// bob 1 m below its pivot gets 1 m; the C-60's parts 7-19 mm (a rad on a 7 mm
// part is 7 mm, not 1 m).
double rotationLength(const Model& m, int body);
// True if no contact changed mode between the two states' warm starts (the
// impulses of the step each ended): each slot open (inactive, or no normal
// impulse) in both, or closed in both and sticking in both, or sliding in both
// the same way (tangential impulses not opposed).
bool sameContactModes(const std::vector<double>& slot_mu, const State& a, const State& b);
// True if every contact slot is open in s (inactive, or no normal impulse).
bool contactsOpen(const std::vector<double>& slot_mu, const State& s);
// True if the step's stats show a nonsmooth event or a rescue: an unsolved
// problem, contacts closed by the answer, a halving, a plastic or frictionless fallback, scaled impulses.
bool stepHadEvent(const StepStats& st);
// The embedded error estimate of a path with an event (adaptive_step.cpp takes
// no coarse path then), from the bodies at the path's start and after each of
// its n >= 3 equal substeps of s = h / n (`substeps`, n + 1 entries): the
// velocity each body moved with over each substep (its displacement / s; the
// turn, world frame, times rotation_length / s), the path's velocity error as
// n / (2 (n - 2)) times the summed second differences of those, counted as the
// displacement it makes over the step (times h) and scaled by atol + rtol h
// |u|. For a first-order scheme in a smooth stretch that is the fine path's
// error, as the coarse-fine difference gives it (the path errs by n (s^2 / 2) a';
// its n - 2 second differences sum to (n - 2) s^2 a'). A velocity jump inside the
// path (an impact, a contact that sticks or lets go) counts about twice its size
// times h: the event is located in time. Displacements, not the velocities the
// substeps end with: the rows of ideal joints on the theta-average velocity
// leave an O(s) part of those flipping sign every substep (kCoarseSubsteps,
// adaptive_step.cpp), which the positions never move with; counted, it shrank
// the slider-crank's steps 3-fold. Infinite if a state is not finite.
// as_velocity: the velocity error itself over atol + rtol |u| (weight 1 where the
// above has h), as the paths' difference of a step without an event counts it:
// the estimate of a step without an event that may keep its fine path alone
// (cappedWellWithinTolerance).
double embeddedEventError(const std::vector<std::vector<BodyState>>& substeps, int n, double h, double atol,
                          double rtol, const std::vector<double>& rotation_length, bool as_velocity = false);
// The Richardson combination y_fine + (y_fine - y_coarse): the fine path's error
// of order h h/4 cancelled against the coarse one's h h/2, for a scheme of order
// 1. The theta-scheme is first order on mechanisms (measured: a four-bar's error
// at 0.5 s halves with h; docs/step_control.md); on a single body turning on one
// joint or a linear oscillator it is second order, and the combination is then
// still of order 2, with twice the fine path's error.
constexpr double kRichardsonFactor = 1.0;
// fine <- fine + f (fine - coarse) for every body: positions, velocities and world
// angular velocities linearly, orientations along the geodesic (the fine
// orientation turned on by f times the rotation from the coarse one to it).
void richardsonExtrapolate(const State& coarse, double f, State& fine);
void extrapolateBodies(const std::vector<BodyState>& coarse, double f, std::vector<BodyState>& fine);
// The substeps of level j (0-based) of the extrapolation: 2 (j + 1). Even
// counts only (kCoarseSubsteps, adaptive_step.cpp).
inline int levelSubsteps(int j) { return 2 * (j + 1); }
// Adds level j (its bodies y) to the Aitken-Neville tableau of a scheme whose
// error expands in powers of h (first order): T_{j,0} = y, T_{j,k+1} = T_{j,k} +
// (T_{j,k} - T_{j-1,k}) / (n_j / n_{j-k-1} - 1). After it a.row[k] = T_{j,k} for
// k <= j, and a.cur = T_{j,j}. Level 0 only sets a.row[0].
void addTableauLevel(int j, const std::vector<BodyState>& y, AdaptiveStepWorkspace& a);

// ---- step_size_controller.cpp
// The PI controller of the step length (Gustafsson 1991; Hairer-Wanner II, IV.2)
// for an error estimate of order 2 in h.
struct StepLengths {
  double h_min = 0;  // the floor
  double h_max = 0;  // dt
};
StepLengths stepLengths(const Settings& set);
// The length after a step of length h kept with error `error` (<= 1), given the
// error of the step kept before it (0: none) and whether this step was rejected
// first (then it may not grow).
double nextStepLength(const StepLengths& lim, double h, double error, double previous_error,
                      bool after_rejection);
// True if a step of length h is at the largest (dt) and its error estimate
// `error` is so far within the tolerance that the I controller (nextStepLength
// without memory) would ask for at least twice h: error <= (kSafety / 2)^2, about
// 0.2. The cap, not the estimate, then sets the length: such a step keeps its
// fine path's answer without taking the coarse path (Simulator::attemptAdaptiveStep).
bool cappedWellWithinTolerance(const StepLengths& lim, double h, double error);
// True if h is the largest step (dt), to planStep's rounding.
bool atLargestStep(const StepLengths& lim, double h);
// The length to try again after a step of length h rejected with error `error` (> 1).
double retryStepLength(const StepLengths& lim, double h, double error);
// Smooth steps with an extrapolation tableau (order and step control of
// extrapolation codes, Hairer-Norsett-Wanner I, II.9; Deuflhard 1983): from
// errors[k] (k = 2 .. order, the estimate of T_{k,k-1}, of local order k in h)
// the length H_k each order would take next, and the work per unit time of each,
// (the substeps of levels 0 .. k-1) / H_k. The next length is that of the
// cheapest order; if that is the highest order taken and a higher one is
// allowed (max_order) and the step was not rejected, the length the next order
// would need for the same work per time (H_k A_{k+1} / A_k): the next step then
// takes one level more if it needs it. at_most: a cap on the length in units of
// h, and no step up in order (1 right after a rejection, 0.9 for the retry of a
// rejected step; INFINITY: none).
double extrapolationStepLength(const StepLengths& lim, double h, const std::vector<double>& errors, int order,
                               int max_order, double at_most);

}  // namespace nscd
