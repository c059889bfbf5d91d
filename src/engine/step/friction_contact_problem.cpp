// Stage 4a: the friction-contact problem of the step's rows. Local free
// velocities b = G v_free; bilateral rows aim at their rheonomic targets, ideal
// joints at a workless theta-average velocity (Settings::joint_work); the
// Newton impact law shifts every active contact's normal by e U_N,k, a late
// contact's also by its gap over h; impulses
// start from the last step's (warm start, carried by the State).
#include <algorithm>
#include <utility>

#include "step_stages.hpp"

namespace nscd {

namespace {

// One term of G_i v_free and of G_i v_k (ck: from its first term on).
template <bool kFirst>
inline void addRowTerm(double g, double vfree, double vk, double& c, double& ck) {
  c += g * vfree;
  ck = kFirst ? g * vk : ck + g * vk;
}

// A known row's terms on one body (g: its piece of G, stride ld; v: the body's
// velocities): its axis's linear entry (axis < kLinearZero), then the angular ones.
template <bool kFirst>
inline void addKnownRowTerms(const double* g, Eigen::Index ld, const double* vfree, const double* vk, int axis,
                             double& c, double& ck) {
  if (axis != kLinearZero) {
    addRowTerm<kFirst>(g[axis * ld], vfree[axis], vk[axis], c, ck);
    addRowTerm<false>(g[3 * ld], vfree[3], vk[3], c, ck);
  } else {
    addRowTerm<kFirst>(g[3 * ld], vfree[3], vk[3], c, ck);
  }
  addRowTerm<false>(g[4 * ld], vfree[4], vk[4], c, ck);
  addRowTerm<false>(g[5 * ld], vfree[5], vk[5], c, ck);
}

}  // namespace

// b = G v_free of every row, and a bilateral row's target and an ideal joint's
// workless average, for a finite v_free (the direct equality step shares it).
void rowFreeVelocities(double joint_average, StepWorkspace& ws) {
  // Over each row's nonzero columns only (its block's bodies, in column
  // order): the sum Eigen's gemv forms, less its exact +-0 terms (G is zero outside
  // those columns, clearConstraintRows), which change no partial sum that is not
  // zero; a zero sum comes out +0 both ways (c * 1 + 0, as gemv adds it to the
  // zeroed b). A non-finite v_free (0 * inf) is the callers' case (the dense product).
  // A joint's G_i v_k (the workless average) over the same columns, from the first
  // product on: Eigen's dot of the whole row, left to right from its first product,
  // less the same +-0 terms; where it is zero its sign may differ, but it is then
  // added to a b_i that is nonzero or +0 (c * 1 + 0 - 0), which it leaves as it is
  // both ways. (v_k is finite where v_free is.)
  // A row whose linear parts are known (ConstraintBlock::linear_known) skips their
  // exact zeros too: finite (0 * a finite v), +-0 like the terms above.
  const double* G = ws.G.data();
  const Eigen::Index ldg = ws.G.outerStride();
  const double* vfree = ws.vfree.data();
  const double* vk = ws.vk.data();
  for (const ConstraintBlock& blk : ws.blocks) {
    int bodies[2] = {blk.body_a, blk.body_b == blk.body_a ? kGround : blk.body_b};
    if (bodies[1] != kGround && (bodies[0] == kGround || bodies[1] < bodies[0]))
      std::swap(bodies[0], bodies[1]);
    const bool bilateral = blk.kind == BlockKind::Bilateral;
    const bool average = bilateral && blk.joint >= 0 && joint_average > 0;
    if (blk.linear_known && average && bodies[0] != kGround) {  // a revolute joint's rows, as below
      for (int k = 0; k < blk.size; ++k) {
        const int i = blk.row + k;
        const int axis = blk.linear_axis[k];
        double c = 0, ck = 0;
        int j0 = 6 * bodies[0];
        addKnownRowTerms<true>(G + i + j0 * ldg, ldg, vfree + j0, vk + j0, axis, c, ck);
        if (bodies[1] != kGround) {
          j0 = 6 * bodies[1];
          addKnownRowTerms<false>(G + i + j0 * ldg, ldg, vfree + j0, vk + j0, axis, c, ck);
        }
        ws.b[i] = c * 1.0 + 0.0;
        ws.b[i] -= blk.target[k];
        ws.b[i] += joint_average * ck;
      }
      continue;
    }
    for (int k = 0; k < blk.size; ++k) {
      const int i = blk.row + k;
      // The row's columns that may be nonzero, in column order.
      int cols[12];
      int nc = 0;
      for (int body : bodies) {
        if (body == kGround) continue;
        const int j0 = 6 * body;
        if (!blk.linear_known) {
          for (int j = j0; j < j0 + 3; ++j) cols[nc++] = j;
        } else if (blk.linear_axis[k] != kLinearZero) {
          cols[nc++] = j0 + blk.linear_axis[k];
        }
        for (int j = j0 + 3; j < j0 + 6; ++j) cols[nc++] = j;
      }
      const double* gi = G + i;
      double c = 0;
      if (!average || nc == 0) {
        for (int t = 0; t < nc; ++t) c += gi[cols[t] * ldg] * vfree[cols[t]];
        ws.b[i] = c * 1.0 + 0.0;
        if (bilateral) ws.b[i] -= blk.target[k];
        continue;
      }
      double g = gi[cols[0] * ldg];
      c += g * vfree[cols[0]];
      double ck = g * vk[cols[0]];
      for (int t = 1; t < nc; ++t) {
        g = gi[cols[t] * ldg];
        c += g * vfree[cols[t]];
        ck += g * vk[cols[t]];
      }
      ws.b[i] = c * 1.0 + 0.0;
      ws.b[i] -= blk.target[k];
      ws.b[i] += joint_average * ck;
    }
  }
}

namespace {

// b = G v_free, the local free velocities of the rows, and a bilateral row's whole
// b (its target, an ideal joint's workless average) in the same pass. Returns
// false where it took the dense product (a non-finite v_free): the bilateral
// terms are then still to add (setBilateralBlock).
bool localFreeVelocities(double joint_average, StepWorkspace& ws) {
  if ((ws.vfree.array() * 0.0).sum() != 0) {  // an entry not finite (friction_contact_solver.cpp)
    ws.b.head(ws.rows).noalias() = ws.G.topRows(ws.rows) * ws.vfree;
    return false;
  }
  rowFreeVelocities(joint_average, ws);
  return true;
}

// A bilateral block: its rheonomic target and the workless average of an ideal
// joint (joint_average > 0) where localFreeVelocities did not add them, and warm
// its last step's impulses.
void setBilateralBlock(const State& s, const ConstraintBlock& blk, double joint_average,
                       bool b_done, bool warm, StepWorkspace& ws) {
  if (!b_done) {
    const auto G = ws.G.topRows(ws.rows);
    for (int k = 0; k < blk.size; ++k) ws.b[blk.row + k] -= blk.target[k];
    // Workless joints: theta G v_{k+1} + (1 - theta) G v_k = 0 (see JointWork).
    if (blk.joint >= 0 && joint_average > 0)
      for (int k = 0; k < blk.size; ++k)
        ws.b[blk.row + k] += joint_average * G.row(blk.row + k).dot(ws.vk);
  }
  const int base = blk.joint >= 0 ? ws.facts.joint_row_base[blk.joint]
                                  : ws.facts.actuator_row_base[blk.actuator];
  if (warm)
    for (int k = 0; k < blk.size; ++k) ws.P[blk.row + k] = s.warm_bilateral[base + k];
}

// A contact block: the impact law's shift of its normal row, warm its last
// step's impulses, and in planar mode its out-of-plane tangent row made void.
void setContactBlock(const Model& m, const State& s, const ConstraintBlock& blk, double h, bool warm,
                     StepWorkspace& ws) {
  const int r = ws.rows;
  const auto G = ws.G.topRows(r);
  // Newton impact law: U_N+ >= -e U_N- on every active contact, a separating one
  // too (design.md). Then v = -e v_k meets every normal condition, so the
  // frictionless problem (a convex QP in v) always has a solution. With the shift
  // on approaching contacts only, a body between two active contacts (a journal
  // touching both sides of a tight bearing, within the margin) moving into one of
  // them has none: the other's U_N+ >= 0 contradicts the first's U_N+ >= e |U_N-|.
  const double un_k = G.row(blk.row).dot(ws.vk);
  ws.b[blk.row] += blk.contact.e * un_k;
  // A late contact (not active at q_k, joined because the answer closes it) may
  // also close its gap g in the step: U_N+ >= -e U_N- - g/h. Held to U_N+ >=
  // -e U_N- like a contact that touches, it stopped its body g short, and a link
  // kicked across a tight bearing had no answer (stress cases 366, 721, 66).
  ws.b[blk.row] += blk.contact.late_slack / h;
  if (warm) {
    const int slot = blk.contact.slot;
    const bool valid = slot >= 0 && s.warm_valid[slot] != 0;
    for (int k = 0; k < blk.size; ++k) ws.P[blk.row + k] = valid ? s.warm[slot][k] : 0.0;
  }
  if (m.settings.planar == PlanarMode::XY && blk.size == 3) {
    // The out-of-plane tangent row is void: decouple it so P_T2 stays 0.
    const int t2 = blk.row + 2;
    ws.W.row(t2).head(r).setZero();
    ws.W.col(t2).head(r).setZero();
    ws.W(t2, t2) = std::max(ws.W(blk.row + 1, blk.row + 1), 1e-300);
    ws.b[t2] = 0;
    ws.P[t2] = 0;
  }
}

}  // namespace

void buildFrictionContactProblem(const Model& m, const State& s, double h, int kept,
                                 StepWorkspace& ws, StepStats& st) {
  const double theta = m.settings.theta;
  const double joint_average =
      m.settings.joint_work == JointWork::None ? (1 - theta) / theta : 0.0;
  const bool bilateral_b_done = localFreeVelocities(joint_average, ws);
  ws.problem.clear();
  st.active_contacts = 0;
  for (const ConstraintBlock& blk : ws.blocks) {
    ProblemBlock pb;
    pb.kind = blk.kind;
    pb.row = blk.row;
    pb.size = blk.size;
    pb.mu = blk.contact.mu;
    ws.problem.push_back(pb);
    // Rows below `kept` start from the current ws.P (a re-solve), the others warm.
    const bool warm = blk.row >= kept;
    if (blk.kind == BlockKind::Bilateral) {
      setBilateralBlock(s, blk, joint_average, bilateral_b_done, warm, ws);
      continue;
    }
    ++st.active_contacts;
    setContactBlock(m, s, blk, h, warm, ws);
  }
}

void removeRestitution(StepWorkspace& ws) {
  const auto G = ws.G.topRows(ws.rows);
  for (const ConstraintBlock& blk : ws.blocks) {
    if (blk.kind == BlockKind::Bilateral) continue;
    const double un_k = G.row(blk.row).dot(ws.vk);
    ws.b[blk.row] -= blk.contact.e * un_k;
  }
}

}  // namespace nscd
