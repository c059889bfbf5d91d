// <clearance>: a revolute joint turned into a 3D joint with radial and axial clearance.
#include <cmath>

#include "nscd_sim/clearance_geometry.hpp"
#include "number_text.hpp"
#include "scene_build.hpp"

namespace nscd {

namespace {

// initial_offset, world frame at the initial placement: its radial part must leave
// the journal inside the bore, its axial part inside the axial play.
void readInitialOffset(SceneBuild& sb, const XMLElement* e, const std::string& name, ClearanceJoint& cj) {
  cj.initial_offset = reqVec3(sb.c, e, "initial_offset");
  const Quat qb = cj.bearing_body == kGround ? Quat::Identity() : sb.m.bodies[cj.bearing_body].initial_pose.q;
  const Vec3 n = (qb * cj.bearing_axis).normalized();
  const double axial = cj.initial_offset.dot(n);
  const double radial = (cj.initial_offset - axial * n).norm();
  if (!(radial < cj.radial) || !(std::abs(axial) <= 0.5 * cj.axial))
    sb.c.fail(e->GetLineNum(), "initial_offset of clearance " + squote(name) + " leaves the journal outside its bearing: radial " +
                                   num(radial) + " m (must be < radial " + num(cj.radial) + "), axial " + num(axial) +
                                   " m (must be within +-axial/2 = " + num(0.5 * cj.axial) + ")");
  cj.has_initial_offset = true;
}

}  // namespace

// ---------------------------------------------------------------- clearance
void readClearance(SceneBuild& sb, const XMLElement* e) {
  checkElement(sb.c, e, "clearance");
  const std::string name = reqString(sb.c, e, "joint");
  const int mj = sb.modelJoint(e, name, "clearance");
  Joint& j = sb.m.joints[mj];
  if (j.type != JointType::Revolute)
    sb.c.fail(e->GetLineNum(), "clearance on " + sb.jointTypeName(mj) + " joint " + squote(name) +
                                 ": only revolute and continuous joints can have a clearance");
  if (j.clearance >= 0)
    sb.c.fail(e->GetLineNum(), "joint " + squote(name) + " is referenced by a second <clearance> (first at line " +
                                 std::to_string(sb.m.clearance_joints[j.clearance].src.line) + ")");
  ClearanceJoint cj;
  cj.name = name;
  cj.joint = mj;
  const std::string journal = has(e, "journal") ? reqString(sb.c, e, "journal") : "parent";
  if (journal != "parent" && journal != "child")
    sb.c.fail(e->GetLineNum(), "attribute 'journal' of <clearance> must be 'parent' or 'child', got " + squote(journal));
  cj.radius = reqNumber(sb.c, e, "radius");
  requireRange(sb.c, e, "radius", cj.radius, 0, true, kInf, false);
  cj.radial = reqNumber(sb.c, e, "radial");
  requireRange(sb.c, e, "radial", cj.radial, 0, true, kInf, false);
  cj.length = reqNumber(sb.c, e, "length");
  requireRange(sb.c, e, "length", cj.length, 0, true, kInf, false);
  cj.axial = reqNumber(sb.c, e, "axial");
  requireRange(sb.c, e, "axial", cj.axial, 0, true, kInf, false);
  cj.bumps = optInt(sb.c, e, "bumps", 3);
  if (cj.bumps < 0 || cj.bumps > kMaxBumps)
    sb.c.fail(e->GetLineNum(), "attribute 'bumps' of <clearance> must be in 0.." + std::to_string(kMaxBumps) +
                                 ", got " + std::to_string(cj.bumps));
  cj.bump_radius = optNumber(sb.c, e, "bump_radius", cj.radius / 8);
  requireRange(sb.c, e, "bump_radius", cj.bump_radius, 0, false, kInf, false);
  cj.bump_at = optNumber(sb.c, e, "bump_at", 1.5 * (cj.radius + cj.radial));
  requireRange(sb.c, e, "bump_at", cj.bump_at, 0, true, kInf, false);
  cj.mu = optNumber(sb.c, e, "mu", 0);
  requireRange(sb.c, e, "mu", cj.mu, 0, false, kInf, false);
  cj.e = optNumber(sb.c, e, "e", 0);
  requireRange(sb.c, e, "e", cj.e, 0, false, 1, false);
  const bool jp = journal == "parent";
  cj.journal_body = jp ? j.body_a : j.body_b;
  cj.bearing_body = jp ? j.body_b : j.body_a;
  cj.journal_center = jp ? j.anchor_a : j.anchor_b;
  cj.journal_axis = jp ? j.axis_a : j.axis_b;
  cj.bearing_center = jp ? j.anchor_b : j.anchor_a;
  cj.bearing_axis = jp ? j.axis_b : j.axis_a;
  cj.bearing_ref = anyOrthogonal(cj.bearing_axis);
  if (has(e, "initial_offset")) readInitialOffset(sb, e, name, cj);
  cj.src = SourceRef{sb.c.file, e->GetLineNum()};
  j.clearance = static_cast<int>(sb.m.clearance_joints.size());
  sb.m.clearance_joints.push_back(cj);
}

}  // namespace nscd
