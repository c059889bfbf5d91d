// Bilateral rows of ideal joints and prescribed motions: the row helpers every
// joint kind shares, and one function per kind (revolute_joint.cpp,
// prismatic_joint.cpp, fixed_joint.cpp, prescribed_motion.cpp). Internal.
//
// Row convention: for a row with world direction d acting on the relative
// motion "B minus A" at points pb, pa, the Jacobian is
//   body B: [ d^T, (R_b^T (rb x d))^T ]   body A: -[ d^T, (R_a^T (ra x d))^T ]
// and for a pure rotational row with world direction d:
//   body B: [0, (R_b^T d)^T]              body A: -[0, (R_a^T d)^T].
#pragma once

#include "step/step_stages.hpp"

namespace nscd {

struct Frame3 {
  Vec3 e[3];
};
// e[0] = axis, e[1], e[2] completing a right-handed frame.
Frame3 frameAround(const Vec3& axis);

// A joint at the state: its bodies, anchors and axis in the world frame.
struct JointPlacement {
  const BodyState& a;
  const BodyState& b;
  Vec3 pa, pb;    // anchors
  Vec3 axis_a;    // joint axis, as body A carries it
  Frame3 fa;      // frameAround(axis_a)
  Vec3 dp;        // pb - pa
};
JointPlacement placeJoint(const Joint& j, const State& s);
// The same, body A the ground, its side taken from placeGroundSides's memo.
JointPlacement placeJointOnGround(const Joint& j, const State& s, const PlacementMemo& ground_side);

// Jacobian of one row, written into G: linear part (world) and the angular
// part given as a world vector for each body; converted to body frames here.
void putRow(Eigen::MatrixXd& G, int row, const State& s, int body_a, int body_b,
            const Vec3& lin_b, const Vec3& ang_b_world, const Vec3& lin_a,
            const Vec3& ang_a_world);
// Point-coincidence row along world direction d: error (pb - pa).d
void pointRow(Eigen::MatrixXd& G, int row, const State& s, int ia, int ib, const Vec3& pa,
              const Vec3& pb, const Vec3& d);
// Rotation row about world direction d.
void rotationRow(Eigen::MatrixXd& G, int row, const State& s, int ia, int ib, const Vec3& d);

// Each appends its rows to blk from row r on (r advanced), with their errors.
// Three point-coincidence rows (revolute and fixed joints).
void appendPointRows(const Joint& j, const State& s, const JointPlacement& p,
                     ConstraintBlock& blk, int& r, Eigen::MatrixXd& G);
// Three rows locking the relative orientation at the URDF zero (fixed, prismatic).
void appendOrientationLockRows(const Joint& j, const State& s, const JointPlacement& p,
                               ConstraintBlock& blk, int& r, Eigen::MatrixXd& G);
void appendRevoluteRows(const Joint& j, const State& s, const JointPlacement& p,
                        ConstraintBlock& blk, int& r, Eigen::MatrixXd& G);
// The revolute rows' errors alone (the same as appendRevoluteRows gives), G untouched.
void appendRevoluteErrors(const Joint& j, const JointPlacement& p, ConstraintBlock& blk, int& r);
void appendPrismaticRows(const Joint& j, const State& s, const JointPlacement& p,
                         ConstraintBlock& blk, int& r, Eigen::MatrixXd& G);
void appendFixedRows(const Joint& j, const State& s, const JointPlacement& p,
                     ConstraintBlock& blk, int& r, Eigen::MatrixXd& G);
// Prescribed actuator `ai`: its joint coordinate, or its body's displacement
// along the axis, follows the command at the commanded rate.
void appendPrescribedRows(const Model& m, const State& s, int ai, double rate,
                          ConstraintBlock& blk, int& r, Eigen::MatrixXd& G);

// Joint coordinates of the child relative to the parent, from the URDF zero.
double revoluteAngle(const Joint& j, const BodyState& a, const BodyState& b);
double revoluteRate(const Joint& j, const BodyState& a, const BodyState& b);
double prismaticPosition(const Joint& j, const BodyState& a, const BodyState& b);
double prismaticRate(const Joint& j, const BodyState& a, const BodyState& b);
// The coordinate of any joint kind (prismatic: m; else rad in (-pi, pi]) and its rate.
double jointCoordinate(const Joint& j, const BodyState& a, const BodyState& b);
double jointRate(const Joint& j, const BodyState& a, const BodyState& b);
// The coordinate, continuous: a revolute angle plus the whole turns that bring it
// within pi of `reference` (the joint's continuous angle a moment ago).
double jointCoordinateNear(const Joint& j, const BodyState& a, const BodyState& b,
                           double reference);

}  // namespace nscd
