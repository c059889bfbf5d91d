// Label placement without overlaps (label_layout.hpp).
#include "label_layout.hpp"

#include <algorithm>
#include <cmath>

namespace nscd_node {
namespace {

constexpr double kCharWidth = 0.6;   // text heights per character (RViz's font)
constexpr double kBoxHeight = 1.3;   // text heights per line, with the spacing above and below

// The overlap area of a box and a disc, approximated by the box's overlap with the
// disc's inscribed square widened to its radius (exact enough to rank candidates).
double discOverlap(double x0, double x1, double y0, double y1, double cx, double cy, double r) {
  const double dx = std::max({x0 - cx, 0.0, cx - x1});
  const double dy = std::max({y0 - cy, 0.0, cy - y1});
  if (dx * dx + dy * dy >= r * r) return 0.0;
  const double w = std::min(x1, cx + r) - std::max(x0, cx - r);
  const double h = std::min(y1, cy + r) - std::max(y0, cy - r);
  return std::max(w, 0.0) * std::max(h, 0.0);
}

}  // namespace

LabelBox labelBox(const std::string& text, double height) {
  size_t longest = 0, line = 0, lines = 1;
  for (char c : text) {
    if (c == '\n') {
      ++lines;
      line = 0;
      continue;
    }
    // A UTF-8 continuation byte is part of the previous character.
    if ((static_cast<unsigned char>(c) & 0xC0) != 0x80) longest = std::max(longest, ++line);
  }
  return {0.5 * kCharWidth * height * static_cast<double>(longest),
          0.5 * kBoxHeight * height * static_cast<double>(lines)};
}

void LabelLayout::addRing(const nscd::Vec3& center, double radius) {
  rings_.push_back({center.x(), center.y(), radius});
}

double LabelLayout::overlap(const nscd::Vec3& c, const LabelBox& b) const {
  const double x0 = c.x() - b.half_width, x1 = c.x() + b.half_width;
  const double y0 = c.y() - b.half_height, y1 = c.y() + b.half_height;
  double area = 0;
  for (const Box& o : boxes_)
    area += std::max(0.0, std::min(x1, o.x1) - std::max(x0, o.x0)) *
            std::max(0.0, std::min(y1, o.y1) - std::max(y0, o.y0));
  for (const Ring& r : rings_) area += discOverlap(x0, x1, y0, y1, r.x, r.y, r.r);
  return area;
}

nscd::Vec3 LabelLayout::place(const std::string& text, const std::vector<nscd::Vec3>& candidates) {
  const LabelBox b = labelBox(text, height_);
  size_t best = 0;
  double least = INFINITY;
  for (size_t i = 0; i < candidates.size(); ++i) {
    const double o = overlap(candidates[i], b);
    if (o < least) {
      least = o;
      best = i;
    }
    if (o <= 0) break;
  }
  const nscd::Vec3 c = candidates.empty() ? nscd::Vec3::Zero() : candidates[best];
  boxes_.push_back({c.x() - b.half_width, c.x() + b.half_width, c.y() - b.half_height, c.y() + b.half_height});
  return c;
}

std::vector<nscd::Vec3> LabelLayout::aroundRing(const nscd::Vec3& center, double radius,
                                                const nscd::Vec3& e1, const nscd::Vec3& e2,
                                                const nscd::Vec3& preferred,
                                                const std::string& text) const {
  const LabelBox b = labelBox(text, height_);
  const double a0 = std::atan2(preferred.dot(e2), preferred.dot(e1));
  std::vector<nscd::Vec3> out;
  out.reserve(36);
  for (int level = 0; level < 3; ++level)
    for (int k = 0; k < 12; ++k) {
      // 0, +30, -30, +60, -60, ..., 180 degrees from the preferred side.
      const int step = (k + 1) / 2;
      const double a = a0 + (k % 2 ? 1 : -1) * step * M_PI / 6;
      const nscd::Vec3 d = std::cos(a) * e1 + std::sin(a) * e2;
      // The box's reach along d (in x-y): the label's centre that far beyond the ring.
      const double reach = std::abs(d.x()) * b.half_width + std::abs(d.y()) * b.half_height;
      out.push_back(center + (radius + 0.5 * height_ + reach + 1.5 * height_ * level) * d);
    }
  return out;
}

}  // namespace nscd_node
