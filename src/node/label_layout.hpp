// Where the 3D view's text labels go so that they do not pile up (ROS-free, tested
// alone): labels are placed one after the other, each at the first of its candidate
// places where its box overlaps no label placed before and no ring, else where it
// overlaps least. Boxes are measured in the world x-y plane (the C-60's top-down
// view), their size estimated from the text: RViz draws a character about 0.6 text
// heights wide.
#pragma once

#include <string>
#include <vector>

#include "nscd_sim/types.hpp"

namespace nscd_node {

// Half extents (m) of a one-line label's box at text height `height`.
struct LabelBox {
  double half_width = 0;
  double half_height = 0;
};
LabelBox labelBox(const std::string& text, double height);

class LabelLayout {
 public:
  explicit LabelLayout(double height) : height_(height) {}

  // A ring (a circle around `center`, radius `radius`, in the x-y plane) no label
  // should cover.
  void addRing(const nscd::Vec3& center, double radius);
  // The label's place among `candidates` (box centres, in order of preference); its
  // box is then taken.
  nscd::Vec3 place(const std::string& text, const std::vector<nscd::Vec3>& candidates);

  // Candidates around a ring: in the ring's plane (unit axes e1, e2), directions
  // starting at `preferred` (unit, in that plane) and turning away from it by 30°
  // steps on alternate sides, each at the distance that puts the box just outside
  // the ring (radius + half a text height), then the same further out.
  std::vector<nscd::Vec3> aroundRing(const nscd::Vec3& center, double radius, const nscd::Vec3& e1,
                                     const nscd::Vec3& e2, const nscd::Vec3& preferred,
                                     const std::string& text) const;

  // The overlap (m²) of a box with the placed boxes and the rings' discs.
  double overlap(const nscd::Vec3& center, const LabelBox& box) const;

 private:
  struct Box {
    double x0, x1, y0, y1;
  };
  struct Ring {
    double x, y, r;
  };
  double height_;
  std::vector<Box> boxes_;
  std::vector<Ring> rings_;
};

}  // namespace nscd_node
