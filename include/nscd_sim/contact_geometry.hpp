// Narrow phase: contact points between pairs of primitive shapes.
#pragma once

#include "nscd_sim/model.hpp"

namespace nscd {

// One contact point between shape A and shape B, all in world coordinates.
// normal is unit and points from B towards A: the gap grows when A moves along it.
// gap = (point_a - point_b) . normal (negative when penetrating).
struct ContactPoint {
  Vec3 point_a = Vec3::Zero();  // on the surface of A
  Vec3 point_b = Vec3::Zero();  // on the surface of B
  Vec3 normal = Vec3::UnitZ();
  double gap = 0;
  int feature = 0;  // stable id of the feature pair within this shape pair (warm starts)
};

constexpr int kMaxPointsPerPair = 8;

// True when collide() handles this pair of types (in either order).
bool shapePairSupported(ShapeType a, ShapeType b);

// Contact points of shape a (frame at world pose pa) and shape b (world pose pb)
// whose gap is below `margin`. Writes at most kMaxPointsPerPair points to out and
// returns how many. Allocates nothing.
int collide(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, double margin,
            ContactPoint* out);

}  // namespace nscd
