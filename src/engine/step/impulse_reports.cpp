// Stage 4d: what the solved impulses leave behind. Exactly this step's active set
// becomes the next step's warm start (in the State); prescribed motions report
// the effort they needed; every contact point gets a report (forces = impulse /
// h, the gap at the end of the step to first order), summed per named contact
// and per clearance joint.
#include <algorithm>

#include "step_stages.hpp"

namespace nscd {

void storeImpulses(const Model& m, double h, State& s, const StepWorkspace& ws,
                   StepOutputs& out) {
  const double theta = m.settings.theta;
  std::fill(s.warm_valid.begin(), s.warm_valid.end(), 0);
  for (const ConstraintBlock& blk : ws.blocks) {
    if (blk.kind == BlockKind::Bilateral) {
      const int base = blk.joint >= 0 ? ws.facts.joint_row_base[blk.joint]
                                      : ws.facts.actuator_row_base[blk.actuator];
      for (int k = 0; k < blk.size; ++k) s.warm_bilateral[base + k] = ws.P[blk.row + k];
      // The effort a prescribed motion needs: the impulse along its driven row.
      if (blk.actuator >= 0) out.actuator_effort[blk.actuator] = ws.P[blk.row] / h;
      continue;
    }
    const ContactCandidate& c = blk.contact;
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    for (int k = 0; k < blk.size; ++k) p[k] = ws.P[blk.row + k];
    s.warm[c.slot] = p;
    s.warm_valid[c.slot] = 1;
    ContactReport rep;
    rep.source = c.source;
    rep.clearance = c.clearance;
    rep.feature = c.cp.feature;
    rep.body_a = blk.body_a;
    rep.body_b = blk.body_b;
    rep.point = c.cp.point_b;
    rep.normal = c.cp.normal;
    rep.fn = p[0] / h;
    rep.ft = (p[1] * blk.t1 + p[2] * blk.t2) / h;
    rep.sliding = blk.size == 3 && p[0] > 0 && p.tail<2>().norm() >= c.mu * p[0] * (1 - 1e-6);
    // Gap at the end of the step, to first order in the motion.
    // G's row is zero outside its bodies' columns: the sum over those, in
    // ascending columns from +0, is the full row's (Eigen sums a strided row in
    // order; the skipped terms are +-0).
    double un = 0;
    const int b0 = std::min(blk.body_a, blk.body_b), b1 = std::max(blk.body_a, blk.body_b);
    for (int body : {b0, b1}) {
      if (body == kGround || (body == b0 && b0 == b1)) continue;  // kGround < every body
      for (int k = 6 * body; k < 6 * body + 6; ++k)
        un += ws.G(blk.row, k) * (theta * ws.vnew[k] + (1 - theta) * ws.vk[k]);
    }
    rep.gap = c.cp.gap + h * un;
    out.reports.push_back(rep);
    if (c.clearance) {
      out.cj_fn[c.source] += rep.fn;
    } else {
      out.pair_fn[c.source] += rep.fn;
      out.pair_ft_vec[c.source] += rep.ft;
    }
  }
  for (size_t p = 0; p < out.pair_ft_vec.size(); ++p) out.pair_ft[p] = out.pair_ft_vec[p].norm();
}

}  // namespace nscd
